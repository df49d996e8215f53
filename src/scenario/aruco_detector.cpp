// ArUco detection with an optional tracking ROI, and the code reading of
// mm-mls (aruco_detector.hpp).
#include "scenario/aruco_detector.hpp"

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <opencv2/imgproc.hpp>
#include <string>

#include "touchdown/core/error.hpp"
#include "touchdown/pose/sim/aruco_dictionary.hpp"

namespace touchdown::scenario::detail {

cv::Mat as_mat(const GrayImageView& v) {
  return {v.height, v.width, CV_8UC1, const_cast<std::uint8_t*>(v.data), static_cast<std::size_t>(v.stride)};
}

cv::Ptr<cv::aruco::Dictionary> aruco_dictionary(std::string_view name) {
  const auto* dict = pose::find_aruco_dictionary(name);
  if (!dict) throw InvalidArgument("dictionary: unknown " + std::string(name));
  return cv::aruco::getPredefinedDictionary(dict->opencv_id);
}

ArucoDetector::ArucoDetector(bool roi, int full_frame_period)
    : parameters_(cv::aruco::DetectorParameters::create()),
      // The last box grown by its own size (at least 32 px) on every side:
      // at 10 Hz the marker moves far less than that between frames.
      region_(roi, full_frame_period, TrackingRegion::Shape{1.0, 32.0, 1, 16}) {}

void ArucoDetector::reset(std::string_view dictionary, int marker_id) {
  dictionary_ = aruco_dictionary(dictionary);
  target_id_ = marker_id;
  region_.reset();
}

void ArucoDetector::full(const cv::Mat& gray) {
  corners_.clear();
  ids_.clear();
  cv::aruco::detectMarkers(gray, dictionary_, corners_, ids_, parameters_);
  region_.searched_whole();
}

void ArucoDetector::detect(const DetectorFrame& frame, std::vector<MarkerDetection>& out) {
  if (!dictionary_) throw InvalidArgument("aruco detector: detect() before reset()");
  const cv::Mat gray = as_mat(frame.gray);
  [&] {
    const cv::Rect roi = region_.next(gray.cols, gray.rows);
    if (roi.empty()) return full(gray);
    corners_.clear();
    ids_.clear();
    cv::aruco::detectMarkers(gray(roi), dictionary_, corners_, ids_, parameters_);
    if (std::find(ids_.begin(), ids_.end(), target_id_) == ids_.end()) return full(gray);
    for (auto& quad : corners_) {
      for (auto& c : quad) c += cv::Point2f(static_cast<float>(roi.x), static_cast<float>(roi.y));
    }
  }();
  out.clear();
  for (std::size_t i = 0; i < ids_.size(); ++i) {
    MarkerDetection d;
    d.id = ids_[i];
    d.confidence = 1;
    d.has_corners = true;
    d.oriented = true;
    d.box_min = Eigen::Vector2d::Constant(1e300);
    d.box_max = Eigen::Vector2d::Constant(-1e300);
    for (std::size_t k = 0; k < 4; ++k) {
      d.corners[k] = Eigen::Vector2d(corners_[i][k].x, corners_[i][k].y);
      d.box_min = d.box_min.cwiseMin(d.corners[k]);
      d.box_max = d.box_max.cwiseMax(d.corners[k]);
    }
    out.push_back(d);
  }
}

void ArucoDetector::track(const MarkerDetection* accepted) {
  if (!accepted) return region_.track(nullptr, nullptr);
  Eigen::Vector2d lo = accepted->box_min, hi = accepted->box_max;
  if (accepted->has_corners) {  // the box of the corners, as cv::boundingRect gives for them
    std::vector<cv::Point2f> quad;
    for (const Eigen::Vector2d& c : accepted->corners)
      quad.emplace_back(static_cast<float>(c.x()), static_cast<float>(c.y()));
    const cv::Rect r = cv::boundingRect(quad);
    lo = Eigen::Vector2d(r.x, r.y);
    hi = Eigen::Vector2d(r.x + r.width, r.y + r.height);
  }
  region_.track(&lo, &hi);
}

// The marker's canonical image and its cells, as the ArUco detection
// tutorial describes the identification step (OpenCV docs, "Detection of
// ArUco Markers"): a perspective warp of the quadrilateral to a square of
// (n + 2) cells (the code and its black border), Otsu's threshold, and each
// cell's bit from the majority of its inner pixels (a margin of about 1/8
// of a cell left out, where the neighbours blur in).
int CodeReader::code_errors(const cv::Mat& gray, const std::array<Eigen::Vector2d, 4>& corners, int id, bool oriented) {
  constexpr int kCellPx = 8, kMarginPx = 1;
  const int n = dictionary_->markerSize;
  const int cells = n + 2;
  const auto side = static_cast<float>(cells * kCellPx);
  const cv::Point2f square[4] = {{0, 0}, {side, 0}, {side, side}, {0, side}};
  cv::Point2f quad[4];
  for (std::size_t k = 0; k < 4; ++k)
    quad[k] = cv::Point2f(static_cast<float>(corners[k].x()), static_cast<float>(corners[k].y()));
  const cv::Mat h = cv::getPerspectiveTransform(quad, square);
  cv::warpPerspective(gray, canonical_, h, cv::Size(cells * kCellPx, cells * kCellPx), cv::INTER_LINEAR);
  cv::threshold(canonical_, canonical_, 0, 255, cv::THRESH_BINARY | cv::THRESH_OTSU);
  bits_.create(n, n, CV_8UC1);
  const int inner = kCellPx - 2 * kMarginPx;
  for (int r = 0; r < n; ++r) {
    for (int c = 0; c < n; ++c) {
      const cv::Rect cell((c + 1) * kCellPx + kMarginPx, (r + 1) * kCellPx + kMarginPx, inner, inner);
      bits_.at<std::uint8_t>(r, c) = cv::countNonZero(canonical_(cell)) * 2 > inner * inner ? 1 : 0;
    }
  }
  // Oriented corners come in the order of the code's canonical rotation.
  return dictionary_->getDistanceToId(bits_, id, !oriented);
}

}  // namespace touchdown::scenario::detail
