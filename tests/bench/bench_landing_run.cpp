// One closed-loop landing run (issue 12; docs/benchmarks.md): world,
// rendered 640×480 camera at 10 Hz and opencv-mls, on one core (OpenCV's
// own threads off), for a flight of about 30 s: the drone starts 24 m from
// the marker, with a few objects, a walking person and light rain. Target:
// ≤ 2 s wall per 40 s of flight. Reports the split (render, system, physics) as
// counters.
//
//   build/tests/bench/bench_landing_run --benchmark_repetitions=5 --benchmark_report_aggregates_only=true
#include <benchmark/benchmark.h>

#include <opencv2/core.hpp>

#include "touchdown/scenario/run.hpp"

namespace ts = touchdown::scenario;

namespace {

ts::Scenario landing_run_scenario() {
  ts::Scenario s;
  s.seed = 5;
  s.marker.id = 3;
  s.marker.size = 1.0;
  s.drone.position = {-19, 15, 14};
  s.drone.gps_error = {1.5, -1.0};
  s.distractors.push_back({ts::DistractorKind::WrongId, 7, 1, 0.8, Eigen::Vector2d(-3, 3), 30});
  auto& box = s.static_objects.emplace_back();
  box.position = Eigen::Vector2d(-12, -3), box.size = Eigen::Vector3d(1.2, 0.8, 1.0);
  auto& tree = s.static_objects.emplace_back();
  tree.kind = ts::StaticKind::Tree, tree.position = Eigen::Vector2d(4, -6), tree.size = Eigen::Vector3d(3, 0.3, 6);
  s.dynamic_objects.emplace_back();
  s.weather.rain = 0.3;
  s.weather.ground_wetness = 0.3;
  return s;
}

void run(benchmark::State& bs, bool roi) {
  cv::setNumThreads(1);
  const ts::Scenario s = landing_run_scenario();
  ts::MlsOptions mls;
  mls.detector.roi = roi;
  auto sut = ts::make_landing_system("opencv-mls", mls);
  ts::Timing sum;
  double flight = 0;
  int runs = 0;
  for (auto _ : bs) {
    const ts::ScenarioResult r = ts::run_scenario(s, *sut);
    if (r.violation()) bs.SkipWithError(r.message.c_str());
    sum.render_s += r.timing.render_s, sum.system_s += r.timing.system_s, sum.physics_s += r.timing.physics_s;
    flight += r.ttl;
    ++runs;
  }
  bs.counters["flight_s"] = flight / runs;
  bs.counters["render_s"] = sum.render_s / runs;
  bs.counters["system_s"] = sum.system_s / runs;
  bs.counters["physics_s"] = sum.physics_s / runs;
}

void BM_landing_run(benchmark::State& bs) { run(bs, true); }
void BM_landing_run_whole_frame_detection(benchmark::State& bs) { run(bs, false); }

}  // namespace

BENCHMARK(BM_landing_run)->Unit(benchmark::kMillisecond)->Iterations(1);
BENCHMARK(BM_landing_run_whole_frame_detection)->Unit(benchmark::kMillisecond)->Iterations(1);
BENCHMARK_MAIN();
