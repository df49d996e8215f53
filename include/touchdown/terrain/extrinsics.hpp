#pragma once
/// \file
/// Camera extrinsics: where the depth camera sits in the world (and,
/// optionally, on the drone body). YAML format in docs/formats.md:
///
///     xyz: [0.0, 0.0, 1.5]       # metres
///     rpy_deg: [180.0, 0.0, 90.0]  # [roll, pitch, yaw] degrees, R = Rz(yaw) * Ry(pitch) * Rx(roll)
///     body:                      # optional: camera pose in the drone body frame
///       xyz: [0.06, 0.0, -0.04]
///       rpy_deg: [180.0, 0.0, 0.0]
///
/// or `matrix:` with 16 numbers (row-major 4×4, or four rows of four).
/// `rpy` (the key's earlier name, also degrees) is still read.
#include <Eigen/Geometry>
#include <filesystem>
#include <string_view>

#include "touchdown/core/rotation.hpp"

namespace touchdown::terrain {

struct Extrinsics {
  /// Maps camera-frame points into the world frame (z up).
  Eigen::Isometry3d T_world_camera = Eigen::Isometry3d::Identity();
  /// Maps camera-frame points into the drone body frame (used by the body
  /// crop box); identity when the YAML has no `body:` section.
  Eigen::Isometry3d T_body_camera = Eigen::Isometry3d::Identity();
};

/// The rpy convention of every touchdown file (touchdown/core/rotation.hpp).
using touchdown::pose_from_xyz_rpy;
using touchdown::rotation_from_rpy;

/// Parses extrinsics YAML text; `source` names it in errors. Throws
/// touchdown::ParseError naming the key and the problem.
Extrinsics parse_extrinsics(std::string_view yaml_text, std::string_view source);
Extrinsics load_extrinsics(const std::filesystem::path& path);

/// YAML text for `e` (xyz + rpy_deg form), readable by parse_extrinsics.
std::string format_extrinsics(const Extrinsics& e, bool with_body);

}  // namespace touchdown::terrain
