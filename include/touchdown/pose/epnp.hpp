#pragma once
/// \file
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
#include <span>

#include "touchdown/pose/camera.hpp"
#include "touchdown/pose/gauss_newton.hpp"

namespace touchdown::pose {

struct EpnpResult {
  bool ok = false;  ///< false for fewer than 4 points, collinear points or no solution in front
  Eigen::Isometry3d T_camera_body = Eigen::Isometry3d::Identity();
  double rms_px = 0;    ///< reprojection RMS [px]
  bool planar = false;  ///< the three-control-point case was used
};

/// Camera pose from ≥ 4 body-frame points and their undistorted pixels.
EpnpResult solve_epnp(const PinholeCamera& camera, std::span<const Eigen::Vector3d> p_body,
                      std::span<const Eigen::Vector2d> uv_px);

/// EPnP followed by Gauss–Newton on SE(3); status Degenerate if EPnP fails.
PoseRefinement solve_pnp(const PinholeCamera& camera, std::span<const Eigen::Vector3d> p_body,
                         std::span<const Eigen::Vector2d> uv_px, const GaussNewtonOptions& options = {});

}  // namespace touchdown::pose
