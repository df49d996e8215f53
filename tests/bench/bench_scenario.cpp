// Scenario renderer benchmarks (issue 12; docs/benchmarks.md): one 640×480
// frame of the downward camera in clear weather over the concrete map with
// a few objects (target ≤ 2 ms), the same in heavy weather (fog, dust, rain,
// snow, falling leaves, wet glare, low light, motion blur), and building a
// renderer: cold (the map's ground, the cover layers and the scene's
// texture built from scratch), cached (a second renderer of the same scene
// shares the first one's texture) and a new scene on a built map (as in a
// campaign).
//
//   build/tests/bench/bench_scenario --benchmark_repetitions=5 --benchmark_report_aggregates_only=true
#include <benchmark/benchmark.h>

#include "scenario/render_cache.hpp"
#include "touchdown/scenario/camera.hpp"

namespace ts = touchdown::scenario;

namespace {

ts::Scenario scene(bool heavy) {
  ts::Scenario s;
  s.seed = 3;
  s.marker.size = 1.0;
  s.distractors.push_back({ts::DistractorKind::WrongId, 5, 1, 0.8, Eigen::Vector2d(-2.5, 3), 30});
  auto& box = s.static_objects.emplace_back();
  box.position = Eigen::Vector2d(3, 2.5), box.size = Eigen::Vector3d(1.2, 0.8, 1.0);
  auto& tree = s.static_objects.emplace_back();
  tree.kind = ts::StaticKind::Tree, tree.position = Eigen::Vector2d(-4, -3), tree.size = Eigen::Vector3d(3, 0.3, 5);
  auto& pole = s.static_objects.emplace_back();
  pole.kind = ts::StaticKind::Pole, pole.position = Eigen::Vector2d(2, -4), pole.size = Eigen::Vector3d(0.2, 0.2, 4);
  s.dynamic_objects.emplace_back();
  if (heavy) {
    ts::Weather& w = s.weather;
    w.fog = 0.03, w.dust = 0.3, w.rain = 1, w.snow = 0.5, w.leaves = 0.5;
    w.ground_wetness = 0.8, w.ground_leaves = 0.3, w.sun_elevation_deg = 70, w.ambient = 0.3;
  }
  return s;
}

ts::SceneState state(bool moving) {
  ts::SceneState st;
  st.T_world_body = Eigen::Translation3d(-0.5, 0.3, 10) * Eigen::Isometry3d::Identity();
  st.T_world_dynamic.push_back(Eigen::Translation3d(1.5, -1.5, 0) * Eigen::Isometry3d::Identity());
  if (moving) st.v_world = Eigen::Vector3d(4, 1, -0.5);
  return st;
}

void run(benchmark::State& bs, bool heavy) {
  ts::Renderer r(scene(heavy), ts::CameraOptions{});
  ts::SceneState st = state(heavy);
  ts::CameraFrame f;
  for (auto _ : bs) {
    r.render(st, f);
    ++st.frame_index;
    benchmark::DoNotOptimize(f.image.pixels.data());
  }
}

void BM_render_clear_ground(benchmark::State& bs) { run(bs, false); }
void BM_render_heavy_weather(benchmark::State& bs) { run(bs, true); }

void BM_renderer_construct_cold(benchmark::State& bs) {
  const ts::Scenario s = scene(true);
  for (auto _ : bs) {
    bs.PauseTiming();
    ts::detail::clear_render_caches();
    bs.ResumeTiming();
    ts::Renderer r(s, ts::CameraOptions{});
    benchmark::DoNotOptimize(&r);
  }
}

void BM_renderer_construct_cached(benchmark::State& bs) {
  const ts::Scenario s = scene(true);
  const ts::Renderer first(s, ts::CameraOptions{});
  for (auto _ : bs) {
    ts::Renderer r(s, ts::CameraOptions{});
    benchmark::DoNotOptimize(&r);
  }
}

/// As in a campaign: the map's ground and the cover layers are built, every
/// scenario is new (its own seed, so its own place and cover pattern).
void BM_renderer_construct_new_scene(benchmark::State& bs) {
  ts::Scenario s = scene(true);
  const ts::Renderer first(s, ts::CameraOptions{});
  for (auto _ : bs) {
    ++s.seed;
    ts::Renderer r(s, ts::CameraOptions{});
    benchmark::DoNotOptimize(&r);
  }
}

}  // namespace

BENCHMARK(BM_render_clear_ground)->Unit(benchmark::kMillisecond);
BENCHMARK(BM_render_heavy_weather)->Unit(benchmark::kMillisecond);
BENCHMARK(BM_renderer_construct_cold)->Unit(benchmark::kMillisecond);
BENCHMARK(BM_renderer_construct_cached)->Unit(benchmark::kMillisecond);
BENCHMARK(BM_renderer_construct_new_scene)->Unit(benchmark::kMillisecond);
BENCHMARK_MAIN();
