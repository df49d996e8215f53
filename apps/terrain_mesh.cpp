// terrain_mesh: depth-camera point cloud → closed terrain mesh (issue 2).
#include <chrono>
#include <cmath>
#include <iomanip>
#include <iostream>
#include <nlohmann/json.hpp>
#include <optional>
#include <sstream>

#include "app_common.hpp"
#include "frames.hpp"
#include "touchdown/core/cloud_io.hpp"
#include "touchdown/core/mesh_io.hpp"
#include "touchdown/terrain/extrinsics.hpp"
#include "touchdown/terrain/terrain_mesher.hpp"

namespace {

std::string fmt_vec(const Eigen::Vector3d& v) {
  using touchdown::app::format_fixed;
  return "[" + format_fixed(v.x(), 3) + ", " + format_fixed(v.y(), 3) + ", " + format_fixed(v.z(), 3) + "]";
}

}  // namespace

int main(int argc, char** argv) {
  namespace td = touchdown;
  CLI::App app{"Mesh a depth-camera point cloud (PCD, PLY, XYZ/CSV) into a closed terrain solid (STL, PLY, OBJ).",
               "terrain_mesh"};
  std::string input, output, extrinsics_path, save_cloud;
  td::terrain::TerrainOptions opt;
  std::vector<double> crop_box;
  bool json = false, assume_world = false;
  using td::app::number_in;
  app.add_option("INPUT", input,
                 "point cloud: .pcd, .ply, .xyz, .csv, .txt (camera frame with --extrinsics, else world frame z up)")
      ->required();
  app.add_option("-o,--output", output, "terrain mesh to write: .stl (binary), .ply or .obj")->required();
  auto* extrinsics =
      app.add_option("--extrinsics", extrinsics_path,
                     "camera pose YAML (xyz [m] + rpy_deg [deg], or a 4x4 matrix) of a camera-frame INPUT; see "
                     "docs/formats.md")
          ->default_str("none");
  app.add_flag("--assume-world-frame", assume_world,
               "INPUT is in the world frame (z up) although it looks like a camera frame (organized, a PCD "
               "VIEWPOINT, or a depth-like shape: docs/formats.md)")
      ->excludes(extrinsics);
  app.add_option("--cell", opt.height_map.cell, "height-map cell edge [m]")
      ->check(number_in(0.001, 10))
      ->capture_default_str();
  app.add_option("--crop-radius", opt.crop_radius, "drop points closer than this to the camera [m], 0 = off")
      ->check(number_in(0, 100))
      ->capture_default_str();
  app.add_option("--crop-box", crop_box, "drop points inside this body-frame box [m]: xmin,ymin,zmin,xmax,ymax,zmax")
      ->delimiter(',')
      ->expected(6)
      ->check(number_in(-100, 100))
      ->default_str("off");
  td::app::add_enum_option(app, "--agg", opt.height_map.aggregate,
                           "per-cell height: " + td::enum_names_list<td::terrain::CellAggregate>());
  app.add_option("--max-hole", opt.height_map.max_hole, "widest gap filled by interpolation [m]")
      ->check(number_in(0, 100))
      ->capture_default_str();
  td::app::add_enum_option(app, "--unknown-fill", opt.height_map.unknown_fill,
                           "wider enclosed gaps (never observed) are marked unknown and filled as a block up to "
                           "their highest rim or as a pit");
  app.add_option("--voxel", opt.voxel, "voxel downsampling edge [m]; -1 (< 0) = half the cell, 0 = off")
      ->check(number_in(-1, 10))
      ->capture_default_str();
  app.add_option("--outlier-k", opt.outliers.k, "neighbours for statistical outlier removal, 0 = off")
      ->check(number_in(0, 100))
      ->capture_default_str();
  app.add_option("--outlier-std", opt.outliers.std_ratio, "outlier threshold: mean + this many std devs")
      ->check(number_in(0, 100, true))
      ->capture_default_str();
  app.add_option("--flying-threshold", opt.flying_pixel_threshold,
                 "jump-edge filter for organized clouds: depth jump [m] at 1 m range (scales with z^2), 0 = off")
      ->check(number_in(0, 10))
      ->capture_default_str();
  app.add_option("--base", opt.base_thickness, "solid thickness below the lowest cell [m]")
      ->check(number_in(0, 100, true))
      ->capture_default_str();
  app.add_option("--save-cloud", save_cloud, "also write the filtered world-frame cloud (.pcd binary, .ply, .xyz)")
      ->default_str("none");
  app.add_flag("--json", json, "print one JSON object on stdout");

  return td::app::run(app, argc, argv, [&]() -> int {
    const auto t0 = std::chrono::steady_clock::now();
    if (crop_box.size() == 6) {
      opt.crop_box_body = Eigen::AlignedBox3d(Eigen::Vector3d(crop_box[0], crop_box[1], crop_box[2]),
                                              Eigen::Vector3d(crop_box[3], crop_box[4], crop_box[5]));
    }
    std::string why;
    if (!opt.validate(&why)) throw td::InvalidArgument(why);
    // Check outputs before the work, so a bad path fails fast; a failed run
    // leaves none of them.
    td::mesh_format_from_path(output);
    if (!save_cloud.empty()) td::cloud_format_from_path(save_cloud);
    td::StagedOutputs outputs;
    const std::filesystem::path output_tmp = outputs.add(output, "--output");
    const std::filesystem::path save_cloud_tmp = td::app::stage(outputs, save_cloud, "--save-cloud");
    if (!extrinsics_path.empty()) {
      const auto ext = td::app::load_extrinsics_with_warnings(app.get_name(), extrinsics_path);
      opt.T_world_camera = ext.T_world_camera;
      opt.T_body_camera = ext.T_body_camera;
    }
    opt.keep_filtered_cloud = !save_cloud.empty();

    td::PointCloud cloud = td::read_cloud(input);
    if (cloud.empty()) throw td::ParseError(input + ": the point cloud is empty");
    if (extrinsics_path.empty() && !assume_world) td::app::require_world_frame(input, cloud);
    td::terrain::TerrainResult result = td::terrain::mesh_terrain(std::move(cloud), opt);
    if (!result.ok()) throw td::InvalidArgument(input + ": " + result.message);
    if (!save_cloud.empty()) td::write_cloud(result.filtered_cloud, save_cloud_tmp);
    td::write_mesh(result.mesh, output_tmp);
    std::vector<std::string> warnings;
    for (const std::string& w :
         {td::app::large_output_warning("--output", output, output_tmp,
                                        std::to_string(result.report.triangles) + " triangles at --cell " +
                                            td::detail::format_general(opt.height_map.cell) +
                                            " m; the size goes with 1 / cell^2"),
          save_cloud.empty() ? std::string()
                             : td::app::large_output_warning("--save-cloud", save_cloud, save_cloud_tmp, "")}) {
      if (!w.empty()) warnings.push_back(w);
    }
    outputs.commit();
    td::app::print_warnings(app.get_name(), warnings);
    const double seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();

    const auto& r = result.report;
    if (json) {
      nlohmann::json j;
      j["input"] = input;
      j["output"] = output;
      j["points_read"] = r.points_read;
      j["points_used"] = r.points_used;
      j["cells"] = r.cells;
      j["holes_filled"] = r.holes_filled;
      j["unknown_regions"] = r.unknown_regions;
      j["unknown_cells"] = r.unknown_cells;
      j["triangles"] = r.triangles;
      auto um = [](double v) { return std::round(v * 1e6) / 1e6 + 0.0; };  // micrometres are plenty
      j["bounds"] = {{"min", {um(r.bounds.min.x()), um(r.bounds.min.y()), um(r.bounds.min.z())}},
                     {"max", {um(r.bounds.max.x()), um(r.bounds.max.y()), um(r.bounds.max.z())}}};
      j["seconds"] = seconds;
      std::cout << j.dump() << "\n";
    } else {
      std::cout << "terrain_mesh: " << input << " -> " << output << "\n"
                << "  points:    " << r.points_read << " read, " << r.points_non_finite << " not finite, "
                << r.points_flying << " flying pixels, " << r.points_cropped << " cropped, " << r.points_after_voxel
                << " after voxel grid, " << r.points_outliers << " outliers, " << r.points_used << " used\n"
                << "  cells:     " << r.cells << " measured, " << r.holes_filled << " filled by interpolation, "
                << r.unknown_regions << " unobserved regions marked unknown (" << r.unknown_cells << " cells)\n"
                << "  mesh:      " << r.triangles << " triangles, closed solid, bounds " << fmt_vec(r.bounds.min)
                << " .. " << fmt_vec(r.bounds.max) << " m\n"
                << "  time:      " << std::fixed << std::setprecision(3) << seconds << " s\n";
    }
    return td::app::kExitOk;
  });
}
