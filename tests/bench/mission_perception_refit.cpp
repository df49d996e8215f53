// Issue 56 item 5: the mission's perception model (σ = a + b r² per axis and
// a per-mission bias, PerceptionModelOptions) refitted to the render
// perception's own errors in a mission file's setting — with
// perception.camera_errors on, what a real camera's calibration, timing and
// shutter do to the pose. Flies N recorded render missions, takes every Ok
// pose measurement against the truth at its capture, and prints the per-band
// errors and the fitted keys (docs/benchmarks.md, "The perception model's
// fit"):
//   build/tests/bench/mission_perception_refit data/missions/circle_real_camera.yaml --runs 20 --wind 4
#include <algorithm>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <string>
#include <vector>

#include "touchdown/mission/mission.hpp"
#include "touchdown/mission/mission_io.hpp"

namespace tdm = touchdown::mission;

int main(int argc, char** argv) {
  if (argc < 2) {
    std::fprintf(stderr, "usage: mission_perception_refit MISSION.yaml [--runs N] [--wind VX]\n");
    return 2;
  }
  int runs = 20;
  double wind = 0;
  for (int i = 2; i + 1 < argc; i += 2) {
    const std::string k = argv[i];
    if (k == "--runs") runs = std::atoi(argv[i + 1]);
    if (k == "--wind") wind = std::atof(argv[i + 1]);
  }
  tdm::MissionFile file = tdm::load_mission(argv[1]);
  file.options.perception = "render";
  if (wind != 0) file.options.wind.mean = {wind, 0, 0};
  const Eigen::Vector3d camera = file.options.perception_options().camera.T_pad_camera.translation();
  // Bands of range from the camera [m].
  const std::vector<double> edges{0.3, 0.7, 1.0, 1.5, 2.0, 2.5, 3.0, 4.0};
  const std::size_t bands = edges.size() - 1;
  std::vector<double> sq(bands, 0), r2(bands, 0);
  std::vector<long> n(bands, 0);
  std::vector<double> bias_sq;
  for (int run = 0; run < runs; ++run) {
    const tdm::MissionResult r = tdm::run_mission(file.options, 1, static_cast<std::uint64_t>(run), true);
    if (r.poses.empty()) continue;
    // The mission's bias: its mean error; the noise about it by range.
    Eigen::Vector3d mean = Eigen::Vector3d::Zero();
    for (const auto& p : r.poses) mean += p.measured - p.truth;
    mean /= static_cast<double>(r.poses.size());
    bias_sq.push_back(mean.squaredNorm() / 3);
    for (const auto& p : r.poses) {
      const double range = (p.truth - camera).norm();
      const auto it = std::upper_bound(edges.begin(), edges.end(), range);
      if (it == edges.begin() || it == edges.end()) continue;
      const auto b = static_cast<std::size_t>(it - edges.begin() - 1);
      sq[b] += (p.measured - p.truth - mean).squaredNorm() / 3;
      r2[b] += range * range;
      ++n[b];
    }
    std::fprintf(stderr, "\rmission %d/%d", run + 1, runs);
  }
  std::fprintf(stderr, "\n");
  // σ = a + b r² through the bands' per-axis RMS, weighted by their frames.
  double sw = 0, sx = 0, sy = 0, sxx = 0, sxy = 0;
  std::printf("| range [m] | Ok frames | per-axis RMS about the mission's mean [m] |\n|---|---|---|\n");
  for (std::size_t b = 0; b < bands; ++b) {
    if (n[b] == 0) continue;
    const double rms = std::sqrt(sq[b] / static_cast<double>(n[b])), x = r2[b] / static_cast<double>(n[b]);
    const auto w = static_cast<double>(n[b]);
    sw += w, sx += w * x, sy += w * rms, sxx += w * x * x, sxy += w * x * rms;
    std::printf("| %.1f-%.1f | %ld | %.4f |\n", edges[b], edges[b + 1], n[b], rms);
  }
  const double det = sw * sxx - sx * sx;
  double b = det > 0 ? (sw * sxy - sx * sy) / det : 0;
  double a = (sy - b * sx) / sw;
  if (b < 0) b = 0, a = sy / sw;  // no growth with range: a constant σ
  if (a < 0) a = 0, b = sxy / sxx;
  double bias = 0;
  for (const double v : bias_sq) bias += v;
  bias = bias_sq.empty() ? 0 : std::sqrt(bias / static_cast<double>(bias_sq.size()));
  std::printf("\nperception: {sigma_a: %.4f, sigma_b: %.4f, bias_sigma: %.4f}   # %d render missions, %s\n", a, b, bias,
              runs, argv[1]);
  return 0;
}
