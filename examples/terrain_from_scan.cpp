// Embedding the terrain stage: what a companion-computer integrator copies.
// A depth frame arrives in the camera frame together with the camera pose
// from the flight stack; we mesh it into a closed terrain solid.
//
//   example_terrain_from_scan [OUT.stl]
#include <iostream>
#include <touchdown/core/mesh.hpp>
#include <touchdown/core/mesh_io.hpp>
#include <touchdown/core/point_cloud.hpp>
#include <touchdown/terrain/synthetic.hpp>
#include <touchdown/terrain/terrain_mesher.hpp>

int main(int argc, char** argv) {
  namespace td = touchdown;
  namespace syn = td::terrain::synthetic;

  // Stand-in for a real frame: a simulated D435 over a 10 cm step.
  syn::Shape step;
  step.kind = syn::ShapeKind::Step;
  step.step_height = 0.10;
  step.prepare();
  const Eigen::Isometry3d T_world_camera = syn::nadir_camera_pose(0.0, 0.0, 1.2);
  td::PointCloud frame = syn::render_depth_scan(step, syn::DepthCamera{}, T_world_camera, /*seed=*/7);

  td::terrain::TerrainOptions options;  // defaults: 2 cm cells, median, 10 cm holes
  options.T_world_camera = T_world_camera;
  options.crop_radius = 0.3;  // the drone's own legs
  const td::terrain::TerrainResult result = td::terrain::mesh_terrain(std::move(frame), options);
  if (!result.ok()) {
    std::cerr << "no terrain: " << result.message << "\n";
    return 1;
  }
  const auto& hm = result.height_map;
  std::cout << result.message << "\n"
            << "height at (-0.3, 0): " << hm.height_at(-0.3, 0.0).value_or(NAN) << " m\n"
            << "height at (+0.3, 0): " << hm.height_at(0.3, 0.0).value_or(NAN) << " m\n"
            << "watertight: " << std::boolalpha << td::check_closedness(result.mesh).watertight() << "\n";
  if (argc > 1) td::write_mesh(result.mesh, argv[1]);
  return 0;
}
