// ArUco detection with an optional tracking ROI (marker_detector.hpp).
#include "scenario/marker_detector.hpp"

#include <algorithm>
#include <cmath>
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

}  // namespace touchdown::scenario::detail
