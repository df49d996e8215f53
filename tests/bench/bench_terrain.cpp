// Kernels of the terrain stage on a 1,024,000-point depth frame (simulated
// 1280x800 camera, f = 640 px, 1.5 m above rubble), one core.
//   build/tests/bench/bench_terrain --benchmark_repetitions=5 --benchmark_report_aggregates_only=true
#include <benchmark/benchmark.h>

#include <filesystem>
#include <sstream>

#include "touchdown/touchdown.hpp"

namespace td = touchdown;
namespace tt = touchdown::terrain;
namespace syn = touchdown::terrain::synthetic;

namespace {

struct Frame {
  td::PointCloud camera;  // organized, camera frame
  td::PointCloud world;   // finite points in the world frame
  Eigen::Isometry3d T_world_camera;
  std::string pcd_binary;
};

const Frame& frame() {
  static const Frame kFrame = [] {
    Frame fr;
    syn::Shape shape;
    shape.kind = syn::ShapeKind::Rubble;
    shape.prepare();
    const auto cam = syn::DepthCamera::centred(1280, 800, 640);
    fr.T_world_camera = syn::nadir_camera_pose(0, 0, 1.5);
    fr.camera = syn::render_depth_scan(shape, cam, fr.T_world_camera, 1);
    fr.world = fr.camera;
    tt::remove_non_finite(fr.world);
    tt::transform_cloud(fr.world, fr.T_world_camera);
    std::ostringstream os;
    td::write_pcd(fr.camera, os, td::PcdEncoding::Binary);
    fr.pcd_binary = os.str();
    return fr;
  }();
  return kFrame;
}

void BM_ReadPcdBinary(benchmark::State& state) {
  const auto& f = frame();
  for (auto _ : state) {
    std::istringstream in(f.pcd_binary);
    benchmark::DoNotOptimize(td::read_pcd(in, "mem"));
  }
  state.SetItemsProcessed(state.iterations() * static_cast<std::int64_t>(f.camera.size()));
}
BENCHMARK(BM_ReadPcdBinary)->Unit(benchmark::kMillisecond);

void BM_FlyingPixels(benchmark::State& state) {
  const auto& f = frame();
  for (auto _ : state) {
    state.PauseTiming();
    td::PointCloud c = f.camera;
    state.ResumeTiming();
    benchmark::DoNotOptimize(tt::remove_flying_pixels(c, 0.03));
  }
}
BENCHMARK(BM_FlyingPixels)->Unit(benchmark::kMillisecond);

void BM_VoxelDownsample(benchmark::State& state) {
  const auto& f = frame();
  for (auto _ : state) benchmark::DoNotOptimize(tt::voxel_downsample(f.world, 0.01));
  state.SetItemsProcessed(state.iterations() * static_cast<std::int64_t>(f.world.size()));
}
BENCHMARK(BM_VoxelDownsample)->Unit(benchmark::kMillisecond);

void BM_StatisticalOutliers(benchmark::State& state) {
  const auto down = tt::voxel_downsample(frame().world, 0.01);
  for (auto _ : state) {
    state.PauseTiming();
    td::PointCloud c = down;
    state.ResumeTiming();
    benchmark::DoNotOptimize(tt::remove_statistical_outliers(c, tt::OutlierOptions{}));
  }
  state.SetItemsProcessed(state.iterations() * static_cast<std::int64_t>(down.size()));
}
BENCHMARK(BM_StatisticalOutliers)->Unit(benchmark::kMillisecond);

void BM_HeightMapMedianAndFill(benchmark::State& state) {
  const auto down = tt::voxel_downsample(frame().world, 0.01);
  for (auto _ : state) {
    auto map = tt::build_height_map(down, tt::HeightMapOptions{});
    benchmark::DoNotOptimize(tt::fill_holes(map, 0.10));
  }
}
BENCHMARK(BM_HeightMapMedianAndFill)->Unit(benchmark::kMillisecond);

void BM_TriangulateSolid(benchmark::State& state) {
  auto map = tt::build_height_map(tt::voxel_downsample(frame().world, 0.01), tt::HeightMapOptions{});
  tt::fill_holes(map, 0.10);
  for (auto _ : state) benchmark::DoNotOptimize(tt::triangulate_solid(map, 0.1));
}
BENCHMARK(BM_TriangulateSolid)->Unit(benchmark::kMillisecond);

void BM_MeshTerrain(benchmark::State& state) {
  const auto& f = frame();
  tt::TerrainOptions o;
  o.T_world_camera = f.T_world_camera;
  for (auto _ : state) {
    state.PauseTiming();
    td::PointCloud c = f.camera;
    state.ResumeTiming();
    benchmark::DoNotOptimize(tt::mesh_terrain(std::move(c), o));
  }
}
BENCHMARK(BM_MeshTerrain)->Unit(benchmark::kMillisecond);

void BM_WriteStl(benchmark::State& state) {
  const auto& f = frame();
  tt::TerrainOptions o;
  o.T_world_camera = f.T_world_camera;
  const auto r = tt::mesh_terrain(f.camera, o);
  const auto path = std::filesystem::temp_directory_path() / "touchdown_bench.stl";
  for (auto _ : state) td::write_mesh(r.mesh, path);
  std::filesystem::remove(path);
  state.counters["triangles"] = static_cast<double>(r.mesh.triangles.size());
}
BENCHMARK(BM_WriteStl)->Unit(benchmark::kMillisecond);

}  // namespace

BENCHMARK_MAIN();
