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
/// `rpy` (the key's earlier name, also degrees) is still read. The rotation
/// (`rpy_deg`/`rpy` or `matrix`) is required, in `body:` too; `xyz` defaults
/// to zero.
#include <Eigen/Geometry>
#include <filesystem>
#include <string>
#include <string_view>
#include <vector>

#include "touchdown/core/rotation.hpp"

namespace touchdown::terrain {

struct Extrinsics {
  /// Maps camera-frame points into the world frame (z up).
  Eigen::Isometry3d T_world_camera = Eigen::Isometry3d::Identity();
  /// Maps camera-frame points into the drone body frame (used by the body
  /// crop box); identity when the YAML has no `body:` section.
  Eigen::Isometry3d T_body_camera = Eigen::Isometry3d::Identity();
  /// Values that parse but look wrong, one line each ("cam.yaml:2: rpy_deg:
  /// [3.14159, 0, 1.5708] look like radians ..."): the library never
  /// prints; an app shows them as warnings on stderr.
  std::vector<std::string> warnings;
};

/// The rpy convention of every touchdown file (touchdown/core/rotation.hpp).
using touchdown::pose_from_xyz_rpy;
using touchdown::rotation_from_rpy;

/// Parses extrinsics YAML text; `source` names it in errors. Throws
/// touchdown::ParseError naming the key and the problem (a missing rotation
/// included). `rpy_deg` values that look like radians (every angle within
/// ±2π and one not a whole number of degrees) are read as degrees and
/// reported in `warnings`.
Extrinsics parse_extrinsics(std::string_view yaml_text, std::string_view source);
Extrinsics load_extrinsics(const std::filesystem::path& path);

/// YAML text for `e` (xyz + rpy_deg form), readable by parse_extrinsics.
std::string format_extrinsics(const Extrinsics& e, bool with_body);

}  // namespace touchdown::terrain
