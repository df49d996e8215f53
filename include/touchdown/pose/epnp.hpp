#pragma once
/// \file
/// Part of touchdown::pose.
/// EPnP (Lepetit, Moreno-Noguer & Fua, "EPnP: An Accurate O(n) Solution to
/// the PnP Problem", IJCV 2009), written here on Eigen with fixed-size
/// matrices: four control points for general constellations, three for
/// planar ones (sec. 3.4), the N = 1..4 null-space approximations (sec. 3.3)
/// and Gauss–Newton on the betas (sec. 3.5). `solve_pnp` chains EPnP with
/// the SE(3) Gauss–Newton refinement.
///
/// Allocation: none. Thread-safe: pure functions.
#include <Eigen/Core>
#include <Eigen/Geometry>
#include <array>
#include <span>
#include <string_view>

#include "touchdown/core/enum_names.hpp"
#include "touchdown/pose/camera.hpp"
#include "touchdown/pose/gauss_newton.hpp"

namespace touchdown::pose {

enum class EpnpStatus {
  Ok,
  TooFewPoints,  ///< fewer than 4 points, or not one pixel per point
  Degenerate,    ///< the points are (nearly) collinear, or their control points are singular
  NoSolution,    ///< no solution with the points in front of the camera (or the eigen-decomposition failed)
};

}  // namespace touchdown::pose

template <>
struct touchdown::EnumNames<touchdown::pose::EpnpStatus> {
  static constexpr std::array<std::string_view, 4> names{"ok", "too_few_points", "degenerate", "no_solution"};
};

namespace touchdown::pose {

inline std::string_view to_string(EpnpStatus status) { return enum_name(status); }

struct EpnpResult {
  EpnpStatus status = EpnpStatus::NoSolution;
  Eigen::Isometry3d T_camera_body = Eigen::Isometry3d::Identity();
  double rms_px = 0;    ///< reprojection RMS [px]
  bool planar = false;  ///< the three-control-point case was used
  [[nodiscard]] bool ok() const { return status == EpnpStatus::Ok; }
  /// The status's fixed text: solving never allocates.
  [[nodiscard]] std::string_view message() const { return to_string(status); }
};

/// Camera pose from ≥ 4 body-frame points and their undistorted pixels.
EpnpResult solve_epnp(const PinholeCamera& camera, std::span<const Eigen::Vector3d> p_body,
                      std::span<const Eigen::Vector2d> uv_px);

/// EPnP followed by Gauss–Newton on SE(3); status Degenerate if EPnP fails.
PoseRefinement solve_pnp(const PinholeCamera& camera, std::span<const Eigen::Vector3d> p_body,
                         std::span<const Eigen::Vector2d> uv_px, const GaussNewtonOptions& options = {});

}  // namespace touchdown::pose
