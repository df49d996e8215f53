// Robustness driver for the LED tracker on constellations it was not tuned
// to (issue 9, item 5): random constellations (5–8 LEDs, quasi-planar or
// 3-D, random colours), each facing a random direction with random emission
// cones, rendered by the synthetic camera in the facing geometry (static and
// moving) and tracked; counts frames with a pose, frames with ≥ 4 LEDs
// visible, and frames reported ok whose pose is more than 0.1 m or 0.1 rad
// wrong (printed with their figures).
//
//   build/tests/bench/pose_robustness [configs=20] [frames=90] [depth=1] [seed=1000] [max_sigma=default]
//
// Deterministic: the same arguments give the same counts.
#include <cstdio>
#include <cstdlib>
#include <exception>
#include <string>
#include <vector>

#include "touchdown/core/random.hpp"
#include "touchdown/pose/led_tracker.hpp"
#include "touchdown/pose/pose_benchmark.hpp"
#include "touchdown/pose/synthetic.hpp"
#include "touchdown/pose/trajectory.hpp"

namespace tp = touchdown::pose;

namespace {

// A board of n LEDs in the plane normal to a random facing f, 0.2 × 0.15 m,
// 0.1 m in front of the body origin, with 5 mm (quasi-planar) or 6 cm (3-D)
// of relief, LEDs at least 3 cm apart.
tp::Constellation random_constellation(touchdown::Rng& rng, bool& planar) {
  tp::Constellation k;
  const int n = 5 + static_cast<int>(rng.uniform(0, 4));
  planar = rng.uniform() < 0.5;
  const Eigen::Vector3d f = Eigen::Vector3d(rng.normal(), rng.normal(), rng.normal()).normalized();
  const Eigen::Vector3d u = f.unitOrthogonal(), v = f.cross(u);
  const tp::LedColor colours[4] = {tp::LedColor::Red, tp::LedColor::Green, tp::LedColor::Blue, tp::LedColor::White};
  for (int i = 0; i < n; ++i) {
    tp::Led led;
    for (int tries = 0; tries < 100; ++tries) {
      led.p_body = 0.1 * f + rng.uniform(-0.1, 0.1) * u + rng.uniform(-0.075, 0.075) * v +
                   rng.uniform(-1, 1) * (planar ? 0.0025 : 0.03) * f;
      bool apart = true;
      for (const auto& other : k.leds) apart = apart && (other.p_body - led.p_body).norm() > 0.03;
      if (apart) break;
    }
    led.color = colours[static_cast<int>(rng.uniform(0, 4))];
    led.normal = f;
    led.half_angle_deg = rng.uniform(50, 90);
    k.leds.push_back(led);
  }
  return k;
}

}  // namespace

int main(int argc, char** argv) {
  const int configs = argc > 1 ? std::atoi(argv[1]) : 20;
  const int frames = argc > 2 ? std::atoi(argv[2]) : 90;
  const bool use_depth = argc > 3 ? std::atoi(argv[3]) != 0 : true;
  const std::uint64_t seed = argc > 4 ? std::strtoull(argv[4], nullptr, 10) : 1000;
  tp::TrackerOptions options;
  options.use_depth = use_depth;
  if (argc > 5) {  // the uncertainty gate (position [m] and rotation [rad])
    options.correspondence.max_sigma_position_m = options.correspondence.max_sigma_rotation_rad = std::atof(argv[5]);
  }
  const tp::CameraModel camera;
  long total = 0, ok = 0, wrong = 0, visible4 = 0, ok_visible4 = 0;
  for (int c = 0; c < configs; ++c) {
    touchdown::Rng rng(seed + static_cast<std::uint64_t>(c), 0);
    bool planar = false;
    const tp::Constellation k = random_constellation(rng, planar);
    std::string why;
    if (!k.validate(&why)) {
      std::printf("config %2d: invalid constellation: %s\n", c, why.c_str());
      continue;
    }
    tp::RenderOptions render;
    render.render_marker = false;
    const tp::SyntheticCamera synth(camera, k, render);
    long config_ok = 0, config_total = 0, config_wrong = 0;
    for (const auto kind : {tp::TrajectoryKind::Static, tp::TrajectoryKind::Moving}) {
      std::vector<tp::TrajectorySample> trajectory;
      const std::uint64_t render_seed = seed + 7 + static_cast<std::uint64_t>(c);
      try {
        trajectory = tp::make_trajectory(kind, frames, render_seed, camera, k);
      } catch (const std::exception& e) {
        std::printf("config %2d: %s\n", c, e.what());
        continue;
      }
      tp::LedTracker tracker(camera, k, options);
      tp::RenderedFrame frame;
      for (std::size_t i = 0; i < trajectory.size(); ++i) {
        synth.render(trajectory[i].T_camera_body, tp::motion_blur_start(trajectory, i), render_seed, i, frame);
        const tp::DepthImageView depth = frame.depth.view();
        const tp::PoseEstimate& e = tracker.track(frame.colour.view(), use_depth ? &depth : nullptr);
        int visible = 0;
        for (const bool b : frame.led_visible) visible += b ? 1 : 0;
        ++config_total;
        ++total;
        visible4 += visible >= 4;
        if (!e.ok()) continue;
        ++config_ok;
        ++ok;
        ok_visible4 += visible >= 4;
        const auto [position, rotation] = tp::pose_error(e.T_camera_body, trajectory[i].T_camera_body);
        if (position > 0.1 || rotation > 0.1) {
          ++wrong;
          if (++config_wrong <= 3) {
            std::printf(
                "  WRONG config %d %s frame %zu: %.3f m %.3f rad, sigma %.3f m %.3f rad, rms %.2f px, %d LEDs, %d "
                "blobs, %d visible%s\n",
                c, kind == tp::TrajectoryKind::Static ? "static" : "moving", i, position, rotation, e.sigma_position_m,
                e.sigma_rotation_rad, e.rms_px, e.points, e.blobs, visible, e.reinitialised ? ", new search" : "");
          }
        }
      }
    }
    std::printf("config %2d: %zu LEDs %s: ok %ld / %ld, wrong-ok %ld\n", c, k.leds.size(),
                planar ? "quasi-planar" : "3-D         ", config_ok, config_total, config_wrong);
  }
  std::printf("total: %ld frames, %ld ok; of the %ld frames with >= 4 LEDs visible %.3f ok; wrong-ok %ld (%.3f %%)\n",
              total, ok, visible4, visible4 ? static_cast<double>(ok_visible4) / static_cast<double>(visible4) : 0.0,
              wrong, ok ? 100.0 * static_cast<double>(wrong) / static_cast<double>(ok) : 0.0);
  return 0;
}
