// A consumer of the installed package: builds a terrain from a synthetic scan.
#include <iostream>
#include <string>
#include <touchdown/touchdown.hpp>

int main(int argc, char** argv) {
  namespace syn = touchdown::terrain::synthetic;
  if (argc > 1 && touchdown::version() != argv[1]) {
    std::cerr << "version mismatch: " << touchdown::version() << " vs " << argv[1] << "\n";
    return 1;
  }
  syn::Shape flat;
  flat.prepare();
  const auto cam = syn::DepthCamera::centred(160, 120, 100);
  touchdown::terrain::TerrainOptions options;
  options.T_world_camera = syn::nadir_camera_pose(0, 0, 1.0);
  const auto result =
      touchdown::terrain::mesh_terrain(syn::render_depth_scan(flat, cam, options.T_world_camera, 1), options);
  if (!result.ok() || !touchdown::check_closedness(result.mesh).watertight()) {
    std::cerr << "terrain failed: " << result.message << "\n";
    return 1;
  }
  std::cout << "touchdown " << touchdown::version() << ": " << result.message << "\n";
  return 0;
}
