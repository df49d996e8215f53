#pragma once
/// \file
/// Synthetic terrains with known geometry and a depth-camera simulator that
/// scans them into realistic noisy point clouds: the bundled sample data
/// (data/terrains/, made by `terrain_synth`) and the terrain oracle tests.
#include <Eigen/Geometry>
#include <array>
#include <cstdint>
#include <string>
#include <string_view>
#include <vector>

#include "touchdown/core/enum_names.hpp"
#include "touchdown/core/point_cloud.hpp"

namespace touchdown::terrain::synthetic {

enum class ShapeKind { Flat, Incline, Step, Plateau, Rubble, Post };

}  // namespace touchdown::terrain::synthetic

/// "flat", "incline", "step", "plateau", "rubble", "post" (from_string<ShapeKind>).
template <>
struct touchdown::EnumNames<touchdown::terrain::synthetic::ShapeKind> {
  static constexpr std::array<std::string_view, 6> names{"flat", "incline", "step", "plateau", "rubble", "post"};
};

namespace touchdown::terrain::synthetic {

inline std::string_view to_string(ShapeKind kind) { return enum_name(kind); }

/// An analytic terrain z = height(x, y) in the world frame (z up).
struct Shape {
  ShapeKind kind = ShapeKind::Flat;
  double base_z = 0.0;
  /// Direction (degrees from +x, counter-clockwise) along which an incline
  /// rises and across which a step goes up; also rotates a plateau.
  double azimuth_deg = 0.0;
  double slope_deg = 10.0;                 ///< incline
  double step_height = 0.10;               ///< step: higher side is +azimuth
  double edge_offset = 0.0;                ///< step: edge distance from the origin along azimuth
  double plateau_height = 0.15;            ///< plateau: a raised rectangle centred at the origin
  Eigen::Vector2d plateau_size{0.6, 0.4};  ///< plateau: along / across azimuth
  int rubble_count = 60;                   ///< rubble: rocks (ellipsoid caps) within ±rubble_extent
  double rubble_max_height = 0.08;
  double rubble_extent = 1.5;
  std::uint64_t rubble_seed = 1;
  Eigen::Vector2d post_xy{0.205, 0.205};  ///< post: a vertical cylinder on flat ground
  double post_radius = 0.04;
  double post_height = 0.25;

  /// Builds internal data (rubble rocks); call after changing parameters.
  void prepare();
  [[nodiscard]] double height(double x, double y) const;
  /// Horizontal distance from (x, y) to the nearest discontinuity or crease
  /// of the surface (+inf for flat and incline).
  [[nodiscard]] double distance_to_edge(double x, double y) const;

  struct Rock {
    Eigen::Vector2d centre;
    Eigen::Vector2d radii;
    double height;
  };
  std::vector<Rock> rocks;  ///< filled by prepare() for rubble
};

/// A stereo depth camera (defaults: Intel RealSense D435 at 848×480). The
/// depth error grows with distance squared, as in Intel's RMS model
/// (Grunnet-Jepsen et al., "Tuning depth cameras for best performance"):
/// σ_z = z² · subpixel / (f · baseline).
struct DepthCamera {
  int width = 848;
  int height = 480;
  double fx = 430.0, fy = 430.0, cx = 424.0, cy = 240.0;
  double min_range = 0.2, max_range = 10.0;
  double subpixel = 0.08;           ///< disparity noise, pixels
  double baseline = 0.050;          ///< metres
  double dropout_fraction = 0.01;   ///< pixels with no depth (NaN)
  double outlier_fraction = 0.002;  ///< pixels with a spurious depth between the camera and the surface
  bool flying_pixels = true;        ///< mix depths across depth discontinuities

  /// The same camera model at another resolution: `width` × `height` pixels,
  /// focal length `focal` (fx = fy), principal point at the image centre.
  [[nodiscard]] static DepthCamera centred(int width, int height, double focal) {
    DepthCamera c;
    c.width = width;
    c.height = height;
    c.fx = c.fy = focal;
    c.cx = width / 2.0;
    c.cy = height / 2.0;
    return c;
  }
};

/// Camera at `height_m` above (x, y) looking straight down, image x along
/// world +x rotated by `yaw_rad`.
Eigen::Isometry3d nadir_camera_pose(double x, double y, double height_m, double yaw_rad = 0.0);

/// Ray-casts every pixel against `shape` and returns the organized cloud in
/// the camera's optical frame (x right, y down, z forward), NaN where there
/// is no return. Deterministic for a given seed.
PointCloud render_depth_scan(const Shape& shape, const DepthCamera& camera, const Eigen::Isometry3d& T_world_camera,
                             std::uint64_t seed);

}  // namespace touchdown::terrain::synthetic
