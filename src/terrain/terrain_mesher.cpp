#include "touchdown/terrain/terrain_mesher.hpp"

#include <chrono>
#include <cmath>

#include "touchdown/core/error.hpp"

namespace touchdown::terrain {

bool TerrainOptions::validate(std::string* why) const {
  auto fail = [&](const std::string& w) {
    if (why) *why = w;
    return false;
  };
  if (!(height_map.cell > 0) || !std::isfinite(height_map.cell))
    return fail("cell must be a positive number of metres");
  if (!(height_map.max_hole >= 0) || !std::isfinite(height_map.max_hole)) return fail("max-hole must be >= 0 metres");
  if (!(height_map.max_fill_slope > 0)) return fail("max fill slope must be positive");
  if (!(height_map.pit_depth > 0) || !std::isfinite(height_map.pit_depth)) return fail("pit-depth must be positive");
  if (!(flying_pixel_threshold >= 0) || !std::isfinite(flying_pixel_threshold)) {
    return fail("flying-pixel threshold must be >= 0 metres");
  }
  if (!(crop_radius >= 0) || !std::isfinite(crop_radius)) return fail("crop-radius must be >= 0 metres");
  if (crop_box_body && (crop_box_body->min().array() > crop_box_body->max().array()).any()) {
    return fail("crop-box min must not exceed max");
  }
  if (!std::isfinite(voxel)) return fail("voxel must be a number of metres (< 0 auto, 0 off)");
  if (outliers.k < 0) return fail("outlier k must be >= 0");
  if (!(outliers.std_ratio > 0) || !std::isfinite(outliers.std_ratio))
    return fail("outlier std ratio must be positive");
  if (!(base_thickness > 0) || !std::isfinite(base_thickness)) return fail("base thickness must be positive");
  return true;
}

TerrainResult mesh_terrain(PointCloud cloud, const TerrainOptions& o) {
  const auto t0 = std::chrono::steady_clock::now();
  std::string why;
  if (!o.validate(&why)) throw InvalidArgument("terrain options: " + why);
  TerrainResult result;
  TerrainReport& r = result.report;
  auto finish = [&](TerrainStatus status, std::string message) {
    result.status = status;
    result.message = std::move(message);
    r.seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
    return std::move(result);
  };

  r.points_read = cloud.size();
  r.points_flying = remove_flying_pixels(cloud, o.flying_pixel_threshold);
  r.points_non_finite = remove_non_finite(cloud) - r.points_flying;
  CropOptions crop;
  crop.radius = o.crop_radius;
  crop.box_body = o.crop_box_body;
  crop.T_body_camera = o.T_body_camera;
  r.points_cropped = crop_near_camera(cloud, crop);
  if (cloud.empty()) {
    return finish(TerrainStatus::EmptyCloud, "no points left: " + std::to_string(r.points_read) + " read, " +
                                                 std::to_string(r.points_non_finite) + " not finite, " +
                                                 std::to_string(r.points_flying) + " flying pixels, " +
                                                 std::to_string(r.points_cropped) + " cropped");
  }
  transform_cloud(cloud, o.T_world_camera);
  const double voxel = o.voxel < 0 ? 0.5 * o.height_map.cell : o.voxel;
  if (voxel > 0) {
    PointCloud down = voxel_downsample(cloud, voxel);
    cloud = std::move(down);
  }
  r.points_after_voxel = cloud.size();
  r.points_outliers = remove_statistical_outliers(cloud, o.outliers);
  r.points_used = cloud.size();

  result.height_map = build_height_map(cloud, o.height_map);
  if (o.keep_filtered_cloud) {
    result.filtered_cloud = std::move(cloud);
  }
  cloud = PointCloud{};  // release before meshing
  const HoleReport holes = fill_holes(result.height_map, o.height_map.max_hole, o.height_map.max_fill_slope);
  const UnknownReport unknown = fill_unknown(result.height_map, o.height_map.unknown_fill, o.height_map.pit_depth);
  r.cells = result.height_map.count(CellState::Measured);
  r.holes_filled = holes.filled_cells;
  r.unknown_regions = unknown.regions;
  r.unknown_cells = unknown.cells;

  result.mesh = triangulate_solid(result.height_map, o.base_thickness);
  r.triangles = result.mesh.triangles.size();
  if (result.mesh.empty()) {
    return finish(TerrainStatus::TooSmall, "the points cover " + std::to_string(r.cells) + " cell(s) of " +
                                               std::to_string(o.height_map.cell) +
                                               " m but a surface needs at least a 2 x 2 block of cells");
  }
  // Bounds of the top surface: x/y of all vertices, z of the top ones.
  r.bounds = Bounds3{};
  const std::size_t ntop = result.mesh.vertices.size() / 2;
  for (std::size_t k = 0; k < ntop; ++k) r.bounds.extend(result.mesh.vertices[k].cast<double>());
  std::string msg =
      "terrain mesh of " + std::to_string(r.triangles) + " triangles from " + std::to_string(r.points_used) + " points";
  if (r.unknown_regions > 0) {
    msg += "; " + std::to_string(r.unknown_regions) + " unobserved region(s) wider than " +
           std::to_string(o.height_map.max_hole) + " m marked unknown (" + std::to_string(r.unknown_cells) +
           " cells, filled as " + (o.height_map.unknown_fill == UnknownFill::Block ? "blocks" : "pits") + ")";
  }
  return finish(TerrainStatus::Success, std::move(msg));
}

}  // namespace touchdown::terrain
