#pragma once
/// \file
/// Part of touchdown::pose.
/// The per-frame output shared by the LED tracker and the ArUco baseline.
#include <Eigen/Geometry>
#include <array>
#include <string_view>
#include <utility>

#include "touchdown/core/enum_names.hpp"
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
  /// Two different poses explain the image equally well (the mirrored tilt
  /// of a quasi-planar board, a symmetric constellation) and neither depth
  /// nor the tracked motion tells them apart: no pose rather than a guess.
  Ambiguous,
  /// The pose is determined too poorly to use: its 1-σ position or rotation
  /// exceeds the tracker's limits (a small or distant constellation).
  Uncertain,
};

}  // namespace touchdown::pose

/// Short human reasons ("too few blobs", ...), also the JSON status names.
template <>
struct touchdown::EnumNames<touchdown::pose::PoseStatus> {
  static constexpr std::array<std::string_view, 8> names{"ok",
                                                         "too few blobs",
                                                         "no consistent correspondence",
                                                         "reprojection error too large",
                                                         "marker not found",
                                                         "degenerate geometry",
                                                         "ambiguous",
                                                         "too uncertain"};
};

namespace touchdown::pose {

inline std::string_view to_string(PoseStatus status) { return enum_name(status); }

/// The 1-σ figures of a left-perturbation twist covariance (ρ, φ) at
/// T_camera_body: the root of the trace of the covariance of the
/// translation t (δt = ρ − [t]× φ) [m] and of the rotation [rad].
std::pair<double, double> pose_sigmas(const Matrix6d& covariance, const Eigen::Isometry3d& T_camera_body);

struct PoseEstimate {
  PoseStatus status = PoseStatus::TooFewBlobs;
  Eigen::Isometry3d T_camera_body = Eigen::Isometry3d::Identity();  ///< body frame in the camera frame
  double rms_px = 0;                                                ///< reprojection RMS of the points used [px]
  int points = 0;                                                   ///< LEDs (or marker corners) used in the final fit
  int blobs = 0;                                                    ///< blobs detected (after gating)
  bool reinitialised = false;              ///< the correspondences came from a full search this frame
  Matrix6d covariance = Matrix6d::Zero();  ///< left-perturbation twist (ρ, φ) covariance
  /// 1-σ uncertainty of the pose from the covariance, for a consumer to
  /// weigh it: the root of the trace of the position's (t of
  /// T_camera_body) covariance [m] and of the rotation's [rad]. The
  /// residual-based noise estimate is floored at the assumed detection
  /// noise, so an exact fit does not claim exactness.
  double sigma_position_m = 0;
  double sigma_rotation_rad = 0;
  [[nodiscard]] bool ok() const { return status == PoseStatus::Ok; }
  /// The status's fixed text: producing a pose never allocates.
  [[nodiscard]] std::string_view message() const { return to_string(status); }
};

}  // namespace touchdown::pose
