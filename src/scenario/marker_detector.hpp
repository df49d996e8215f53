#pragma once
// ArUco detection for the reference landing systems (landing_system.cpp):
// OpenCV's detectMarkers with its default parameters on the whole frame,
// or, while a target is being tracked, first on a region of interest
// around where it was last seen (the usual tracking shortcut of onboard
// marker trackers; docs/architecture.md). The whole frame is searched
// again whenever the region does not give the target and at least every
// `full_frame_period` frames, so the ROI never hides the target and
// distractors are still seen regularly. Private to the scenario module.
#include <opencv2/aruco.hpp>
#include <opencv2/core.hpp>
#include <vector>

namespace touchdown::scenario::detail {

class MarkerDetector {
 public:
  /// `roi` false: every frame is searched whole (OpenCV-MLS as published).
  MarkerDetector(cv::Ptr<cv::aruco::Dictionary> dictionary, bool roi, int full_frame_period = 10);

  /// Detects markers in `gray`; `target_id` is the id whose last position
  /// steers the ROI. Corners are in full-image pixels.
  void detect(const cv::Mat& gray, int target_id, std::vector<std::vector<cv::Point2f>>& corners,
              std::vector<int>& ids);
  /// Tells the detector where the target was accepted in this frame (its
  /// four corners), or that it was not (`nullptr`).
  void track(const std::vector<cv::Point2f>* target_corners);
  /// Cells of the code read inside `corners` (a detection's, in ArUco
  /// corner order) that differ from the code of `id`: 0 when the marker
  /// reads exactly as `id`, more for a look-alike that the decoder's error
  /// correction turned into it (or a marker read through noise).
  [[nodiscard]] int code_errors(const cv::Mat& gray, const std::vector<cv::Point2f>& corners, int id);

 private:
  void full(const cv::Mat& gray, std::vector<std::vector<cv::Point2f>>& corners, std::vector<int>& ids);

  cv::Ptr<cv::aruco::Dictionary> dictionary_;
  cv::Ptr<cv::aruco::DetectorParameters> parameters_;
  bool use_roi_;
  int full_frame_period_;
  bool tracking_ = false;
  cv::Rect2f last_box_;
  int since_full_ = 0;
  cv::Mat canonical_, bits_;
};

}  // namespace touchdown::scenario::detail
