#pragma once
/// \file
/// The terrain stage end to end: a camera-frame depth cloud → filters →
/// height map → closed terrain mesh, with a report.
#include <Eigen/Geometry>
#include <array>
#include <optional>
#include <string>
#include <string_view>

#include "touchdown/core/enum_names.hpp"
#include "touchdown/core/mesh.hpp"
#include "touchdown/core/point_cloud.hpp"
#include "touchdown/terrain/filters.hpp"
#include "touchdown/terrain/height_map.hpp"

namespace touchdown::terrain {

struct TerrainOptions {
  /// Camera → world (z up); identity when the cloud is already in the world.
  Eigen::Isometry3d T_world_camera = Eigen::Isometry3d::Identity();
  /// Camera → body, for the body crop box.
  Eigen::Isometry3d T_body_camera = Eigen::Isometry3d::Identity();
  /// Jump-edge filter threshold at 1 m depth (metres, scaled by z²) for
  /// organized clouds; 0 = off. See remove_flying_pixels.
  double flying_pixel_threshold = 0.03;
  double crop_radius = 0.0;  ///< metres, 0 = off
  std::optional<Eigen::AlignedBox3d> crop_box_body;
  /// Voxel edge for downsampling; < 0 means half the height-map cell, 0 off.
  double voxel = -1.0;
  OutlierOptions outliers{};  ///< k = 0 turns removal off
  HeightMapOptions height_map{};
  double base_thickness = 0.10;  ///< solid below the lowest cell, metres
  /// Keep the filtered world-frame cloud in the result (to save or inspect it).
  bool keep_filtered_cloud = false;

  /// False (with the reason) when an option is out of range.
  [[nodiscard]] bool validate(std::string* why) const;
};

enum class TerrainStatus {
  Success,
  EmptyCloud,  ///< no finite point survived the filters
  TooSmall,    ///< fewer than 2×2 valid cells: no surface to triangulate
};

}  // namespace touchdown::terrain

template <>
struct touchdown::EnumNames<touchdown::terrain::TerrainStatus> {
  static constexpr std::array<std::string_view, 3> names{"success", "empty_cloud", "too_small"};
};

namespace touchdown::terrain {

inline std::string_view to_string(TerrainStatus status) { return enum_name(status); }

struct TerrainReport {
  std::size_t points_read = 0;
  std::size_t points_flying = 0;  ///< removed by the jump-edge filter
  std::size_t points_non_finite = 0;
  std::size_t points_cropped = 0;
  std::size_t points_after_voxel = 0;
  std::size_t points_outliers = 0;
  std::size_t points_used = 0;   ///< points that went into the height map
  std::size_t cells = 0;         ///< cells with a measured height
  std::size_t holes_filled = 0;  ///< cells filled by interpolation
  /// Enclosed regions the camera never observed (wider than max_hole):
  /// marked CellState::Unknown and filled by HeightMapOptions::unknown_fill.
  std::size_t unknown_regions = 0;
  std::size_t unknown_cells = 0;
  std::size_t triangles = 0;
  Bounds3 bounds;  ///< of the mesh's top surface
  double seconds = 0.0;
};

struct TerrainResult {
  TerrainStatus status = TerrainStatus::EmptyCloud;
  std::string message;
  HeightMap height_map;
  TriangleMesh mesh;
  PointCloud filtered_cloud;  ///< world frame; only with keep_filtered_cloud
  TerrainReport report;
  [[nodiscard]] bool ok() const { return status == TerrainStatus::Success; }
};

/// Runs the stage. `cloud_camera` is consumed (filtered in place). Throws
/// InvalidArgument for invalid options; data-dependent failures are statuses.
TerrainResult mesh_terrain(PointCloud cloud_camera, const TerrainOptions& options);

}  // namespace touchdown::terrain
