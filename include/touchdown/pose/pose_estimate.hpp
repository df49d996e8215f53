#pragma once
/// \file
/// The per-frame output shared by the LED tracker and the ArUco baseline.
#include <Eigen/Geometry>
#include <string_view>

#include "touchdown/pose/se3.hpp"

namespace touchdown::pose {

/// Why a frame has (or has no) pose. Everything but Ok is an expected
/// outcome, reported instead of a made-up pose.
enum class PoseStatus {
  Ok,
  TooFewBlobs,                 ///< fewer than 4 usable detections
  NoConsistentCorrespondence,  ///< no assignment of detections to LEDs explains the image
  ReprojectionTooLarge,        ///< the best pose's reprojection error exceeds the gate
  MarkerNotFound,              ///< ArUco baseline: the marker was not detected
  Degenerate,                  ///< the solver failed (points behind the camera, singular geometry)
};

/// A short human reason ("too few blobs", ...).
std::string_view to_string(PoseStatus status);

struct PoseEstimate {
  PoseStatus status = PoseStatus::TooFewBlobs;
  Eigen::Isometry3d T_camera_body = Eigen::Isometry3d::Identity();  ///< body frame in the camera frame
  double rms_px = 0;                                                ///< reprojection RMS of the points used [px]
  int points = 0;                                                   ///< LEDs (or marker corners) used in the final fit
  int blobs = 0;                                                    ///< blobs detected (after gating)
  bool reinitialised = false;              ///< the correspondences came from a full search this frame
  Matrix6d covariance = Matrix6d::Zero();  ///< left-perturbation twist (ρ, φ) covariance
  [[nodiscard]] bool ok() const { return status == PoseStatus::Ok; }
};

}  // namespace touchdown::pose
