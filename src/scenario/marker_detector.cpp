// ArUco detection with an optional tracking ROI (marker_detector.hpp).
#include "scenario/marker_detector.hpp"

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <opencv2/imgproc.hpp>

namespace touchdown::scenario::detail {

MarkerDetector::MarkerDetector(cv::Ptr<cv::aruco::Dictionary> dictionary, bool roi, int full_frame_period)
    : dictionary_(std::move(dictionary)),
      parameters_(cv::aruco::DetectorParameters::create()),
      use_roi_(roi),
      full_frame_period_(std::max(1, full_frame_period)) {}

void MarkerDetector::full(const cv::Mat& gray, std::vector<std::vector<cv::Point2f>>& corners, std::vector<int>& ids) {
  corners.clear();
  ids.clear();
  cv::aruco::detectMarkers(gray, dictionary_, corners, ids, parameters_);
  since_full_ = 0;
}

void MarkerDetector::detect(const cv::Mat& gray, int target_id, std::vector<std::vector<cv::Point2f>>& corners,
                            std::vector<int>& ids) {
  ++since_full_;
  if (!use_roi_ || !tracking_ || since_full_ >= full_frame_period_) return full(gray, corners, ids);
  // The last box grown by its own size (at least 32 px) on every side:
  // at 10 Hz the marker moves far less than that between frames.
  const float side = std::max(last_box_.width, last_box_.height);
  const float grow = std::max(side, 32.0f);
  const float x0 = std::max(0.0f, std::floor(last_box_.x - grow));
  const float y0 = std::max(0.0f, std::floor(last_box_.y - grow));
  const float x1 = std::min(static_cast<float>(gray.cols), std::ceil(last_box_.br().x + grow));
  const float y1 = std::min(static_cast<float>(gray.rows), std::ceil(last_box_.br().y + grow));
  const cv::Rect roi(static_cast<int>(x0), static_cast<int>(y0), static_cast<int>(x1 - x0), static_cast<int>(y1 - y0));
  // A region most of the frame wide saves nothing.
  if (roi.width < 16 || roi.height < 16 || roi.area() * 2 > gray.cols * gray.rows) return full(gray, corners, ids);
  corners.clear();
  ids.clear();
  cv::aruco::detectMarkers(gray(roi), dictionary_, corners, ids, parameters_);
  if (std::find(ids.begin(), ids.end(), target_id) == ids.end()) return full(gray, corners, ids);
  for (auto& quad : corners) {
    for (auto& c : quad) c += cv::Point2f(static_cast<float>(roi.x), static_cast<float>(roi.y));
  }
}

void MarkerDetector::track(const std::vector<cv::Point2f>* target_corners) {
  tracking_ = target_corners != nullptr && target_corners->size() == 4;
  if (tracking_) last_box_ = cv::boundingRect(*target_corners);
}

// The marker's canonical image and its cells, as the ArUco detection
// tutorial describes the identification step (OpenCV docs, "Detection of
// ArUco Markers"): a perspective warp of the quadrilateral to a square of
// (n + 2) cells (the code and its black border), Otsu's threshold, and each
// cell's bit from the majority of its inner pixels (a margin of about 1/8
// of a cell left out, where the neighbours blur in).
int MarkerDetector::code_errors(const cv::Mat& gray, const std::vector<cv::Point2f>& corners, int id) {
  constexpr int kCellPx = 8, kMarginPx = 1;
  const int n = dictionary_->markerSize;
  const int cells = n + 2;
  const auto side = static_cast<float>(cells * kCellPx);
  const cv::Point2f square[4] = {{0, 0}, {side, 0}, {side, side}, {0, side}};
  const cv::Mat h = cv::getPerspectiveTransform(corners.data(), square);
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
  // The corners come in the order of the code's canonical rotation.
  return dictionary_->getDistanceToId(bits_, id, false);
}

}  // namespace touchdown::scenario::detail
