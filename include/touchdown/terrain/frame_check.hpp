#pragma once
/// \file
/// Is a point cloud in a world frame (z up) or still in a depth camera's
/// optical frame (x right, y down, z forward)? Meshing a camera-frame cloud
/// as if z were up turns the terrain upside down (a post becomes a pit), so
/// the apps refuse a cloud that looks like a camera frame unless they are
/// given its pose (`--extrinsics`) or told it is world-frame
/// (`--assume-world-frame`): frames are never guessed. The rule is
/// documented in docs/formats.md ("Which frame a cloud is in").
#include <array>
#include <cstddef>
#include <limits>
#include <string>
#include <string_view>

#include "touchdown/core/enum_names.hpp"
#include "touchdown/core/point_cloud.hpp"

namespace touchdown::terrain {

struct FrameCheckOptions {
  /// A dominant plane tilted more than this from horizontal [deg] is the
  /// ground seen by a forward-looking camera (in its optical frame the
  /// ground faces -y).
  double max_tilt_deg = 45.0;
  /// A near-horizontal dominant plane lying more than this × the cloud's
  /// horizontal extent above the origin, with (almost) every point at z > 0,
  /// is the ground seen by a downward-looking camera (z is depth).
  double max_height_ratio = 0.25;
  double min_positive_fraction = 0.99;
  /// Fewer finite points than this: too few to judge (no evidence).
  std::size_t min_points = 50;

  [[nodiscard]] bool validate(std::string* why) const;
};

enum class FrameRule {
  None,         ///< nothing says camera frame
  Organized,    ///< the cloud keeps a pixel grid (PCD HEIGHT > 1)
  Viewpoint,    ///< the PCD VIEWPOINT is not the identity
  TiltedPlane,  ///< the dominant plane is steeper than max_tilt_deg
  DepthLike,    ///< every point at z > 0, dominant plane far above the origin
};

}  // namespace touchdown::terrain

template <>
struct touchdown::EnumNames<touchdown::terrain::FrameRule> {
  static constexpr std::array<std::string_view, 5> names{"none", "organized", "viewpoint", "tilted_plane",
                                                         "depth_like"};
};

namespace touchdown::terrain {

inline std::string_view to_string(FrameRule rule) { return enum_name(rule); }

struct FrameEvidence {
  static constexpr double kNaN = std::numeric_limits<double>::quiet_NaN();
  FrameRule rule = FrameRule::None;
  /// Why the cloud looks like a camera frame, one clause for a message
  /// ("it is organized (640 x 480 pixels) ..."); empty for FrameRule::None.
  std::string reason;
  /// The plane fit behind the geometric rules (NaN when it did not run:
  /// organized cloud, viewpoint, too few points).
  double plane_tilt_deg = kNaN;     ///< angle of its normal from the z axis
  double plane_fraction = kNaN;     ///< share of the points on it
  double plane_height = kNaN;       ///< its z at x = y = 0 [m]
  double extent = kNaN;             ///< horizontal extent of the cloud (1st-99th percentile) [m]
  double positive_fraction = kNaN;  ///< share of the points with z > 0

  [[nodiscard]] bool camera_frame() const { return rule != FrameRule::None; }
};

/// Checks, in order: organized → camera frame; a PCD VIEWPOINT that is not
/// the identity → camera frame; then a robust plane fit (RANSAC, then least
/// squares on its inliers) to at most 20 000 of the finite points: a plane
/// tilted more than `max_tilt_deg`, or every point at z > 0 with the plane
/// more than `max_height_ratio` × the extent above the origin → camera
/// frame. Deterministic (its time: docs/benchmarks.md, "Terrain stage").
/// Throws InvalidArgument for invalid options.
FrameEvidence camera_frame_evidence(const PointCloud& cloud, const FrameCheckOptions& options = {});

}  // namespace touchdown::terrain
