#pragma once
/// \file
/// LED relative pose (issue 4, items 1–3): detections → correspondences →
/// EPnP → Gauss–Newton on SE(3), tracked from frame to frame.
///
/// - Initialisation (or after loss): the full correspondence search of
///   correspondence.hpp.
/// - Tracking: reproject the constellation from the predicted pose, assign
///   detections by minimum-cost matching (Hungarian algorithm), refine with
///   Gauss–Newton; re-initialise when the reprojection error exceeds a gate.
///   A fit too uncertain to report (PoseStatus::Uncertain, e.g. a distant
///   board) gives the frame no pose but keeps the track: the next frame is
///   matched against its prediction rather than searched from scratch.
/// - Outlier rejection as published: if the mean absolute deviation of the
///   detections' 3-D points exceeds the constellation's, drop points far from
///   the predicted constellation centre; then suppress duplicates within
///   k-means clusters (k = number of LEDs).
///
/// Allocation: none in steady-state tracking (tested). Thread-safety: one
/// tracker per camera stream.
#include <array>
#include <memory>
#include <span>
#include <string>
#include <vector>

#include "touchdown/pose/camera.hpp"
#include "touchdown/pose/constellation.hpp"
#include "touchdown/pose/correspondence.hpp"
#include "touchdown/pose/image.hpp"
#include "touchdown/pose/led_detector.hpp"
#include "touchdown/pose/pose_estimate.hpp"

namespace touchdown::pose {

struct TrackerOptions {
  DetectorOptions detector;
  CorrespondenceOptions correspondence;
  bool use_depth = true;            ///< use the depth image (gate, 3-D outlier test) when given
  double track_gate_px = 15.0;      ///< tracking: a blob farther than this from its predicted LED is not it [px]
  double reinit_rms_px = 3.0;       ///< tracking fit worse than this → full search [px]
  double mad_ratio = 2.0;           ///< outlier test: detections' MAD vs the constellation's
  double centre_gate = 1.5;         ///< keep 3-D points within this × constellation radius of the predicted centre
  double duplicate_fraction = 0.3;  ///< blobs closer than this × the smallest projected LED spacing are duplicates
  bool constant_velocity = true;    ///< predict with the last inter-frame motion
  bool validate(std::string* why) const;
};

class LedTracker {
 public:
  /// Throws InvalidArgument on an invalid camera, constellation or options.
  LedTracker(const CameraModel& camera, const Constellation& constellation, const TrackerOptions& options = {});
  ~LedTracker();
  LedTracker(LedTracker&&) noexcept;
  LedTracker& operator=(LedTracker&&) noexcept;

  /// One frame: detect, gate, match (or search), refine.
  const PoseEstimate& track(const BgrImageView& colour, const DepthImageView* depth = nullptr);
  /// The same from blobs detected elsewhere (uv_undistorted and color used).
  const PoseEstimate& track_blobs(std::span<const Blob> blobs);
  /// Forget the track: the next frame runs the full search.
  void reset();

  [[nodiscard]] const PoseEstimate& last() const;
  /// The blobs of the last frame after gating (indices used by led_to_blob()).
  [[nodiscard]] const std::vector<Blob>& blobs() const;
  [[nodiscard]] const std::array<int, kMaxLeds>& led_to_blob() const;

 private:
  struct Impl;
  std::unique_ptr<Impl> impl_;
};

}  // namespace touchdown::pose
