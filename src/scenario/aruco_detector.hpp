#pragma once
// The ArUco marker detector (touchdown/scenario/marker_detector.hpp) and the
// code reading mm-mls does itself. Private to the scenario module.
//
// Detection: OpenCV's detectMarkers with its default parameters on the
// whole frame, or, while a target is being tracked, first on a region of
// interest around where it was last seen (the usual tracking shortcut of
// onboard marker trackers; docs/architecture.md). The whole frame is
// searched again whenever the region does not give the target and at least
// every `full_frame_period` frames, so the ROI never hides the target and
// distractors are still seen regularly.
#include <opencv2/aruco.hpp>
#include <opencv2/core.hpp>
#include <string_view>
#include <vector>

#include "scenario/tracking_region.hpp"
#include "touchdown/scenario/marker_detector.hpp"

namespace touchdown::scenario::detail {

/// cv::Mat header over a grey view (no copy).
cv::Mat as_mat(const GrayImageView& v);

/// The ArUco dictionary named `name` ("4X4_50", ...); throws
/// InvalidArgument for an unknown name.
cv::Ptr<cv::aruco::Dictionary> aruco_dictionary(std::string_view name);

class ArucoDetector final : public MarkerDetector {
 public:
  /// `roi` false: every frame is searched whole (OpenCV-MLS as published).
  ArucoDetector(bool roi, int full_frame_period);

  [[nodiscard]] std::string_view name() const override { return "aruco"; }
  void reset(std::string_view dictionary, int marker_id) override;
  void detect(const DetectorFrame& frame, std::vector<MarkerDetection>& out) override;
  void track(const MarkerDetection* accepted) override;

 private:
  void full(const cv::Mat& gray);

  cv::Ptr<cv::aruco::Dictionary> dictionary_;
  cv::Ptr<cv::aruco::DetectorParameters> parameters_;
  TrackingRegion region_;
  int target_id_ = 0;
  std::vector<std::vector<cv::Point2f>> corners_;
  std::vector<int> ids_;
};

/// Reads the code inside a quadrilateral: the number of cells of the code
/// read inside `corners` (ArUco corner order) that differ from the code of
/// `id` — 0 when the marker reads exactly as `id`, more for a look-alike
/// that a decoder's error correction turned into it (or a marker read
/// through noise). Reuses its buffers; one per thread.
class CodeReader {
 public:
  void reset(std::string_view dictionary) { dictionary_ = aruco_dictionary(dictionary); }
  /// `oriented`: the corners start at the code's top-left (else any of the
  /// four rotations is tried and the best taken).
  [[nodiscard]] int code_errors(const cv::Mat& gray, const std::array<Eigen::Vector2d, 4>& corners, int id,
                                bool oriented);

 private:
  cv::Ptr<cv::aruco::Dictionary> dictionary_;
  cv::Mat canonical_, bits_;
};

}  // namespace touchdown::scenario::detail
