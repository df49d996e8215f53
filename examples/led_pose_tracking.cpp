// Track the drone's LEDs through a recorded sequence with the library API —
// what a ground-vehicle integrator copies. Here the "recording" is a
// synthetic one (moving camera, 0.4–3 m) written to a scratch directory
// (argument 1, which must not exist yet; default: under the temp dir) and
// removed at the end. For your own NNNNNN.png (+ NNNNNN.depth.png) frames,
// skip step 1 and list your directory instead.
#include <cstdio>
#include <filesystem>

#include "touchdown/pose/camera.hpp"
#include "touchdown/pose/constellation.hpp"
#include "touchdown/pose/led_tracker.hpp"
#include "touchdown/pose/sim/pose_benchmark.hpp"
#include "touchdown/pose/sim/sequence.hpp"
#include "touchdown/pose/sim/synthetic.hpp"

int main(int argc, char** argv) {
  namespace tp = touchdown::pose;
  namespace fs = std::filesystem;
  const fs::path dir = argc > 1 ? fs::path(argv[1]) : fs::temp_directory_path() / "touchdown_led_example";
  if (fs::exists(dir)) {
    std::fprintf(stderr, "%s exists: give a scratch directory that does not exist yet\n", dir.string().c_str());
    return 2;
  }
  const tp::CameraModel camera;                                // or tp::load_camera("camera.yaml")
  const tp::Constellation leds = tp::default_constellation();  // or tp::load_constellation("leds.yaml")

  // 1. A recording: 90 frames of a moving camera, with ground truth.
  const auto trajectory = tp::make_trajectory(tp::TrajectoryKind::Moving, 90, /*seed=*/7, camera, leds);
  tp::write_sequence(dir, camera, leds, trajectory, tp::RenderOptions{}, /*seed=*/7);
  const auto truth = tp::read_ground_truth(dir / "ground_truth.jsonl");

  // 2. One tracker per camera stream; images are reused between frames.
  tp::LedTracker tracker(camera, leds);
  touchdown::BgrImage colour;
  touchdown::DepthImage depth;
  int ok = 0, n = 0;
  double worst = 0;
  for (const auto& frame : tp::list_sequence(dir)) {
    tp::read_frame(frame, colour, &depth);
    const touchdown::DepthImageView d = depth.view();
    const tp::PoseEstimate& pose = tracker.track(colour.view(), depth.empty() ? nullptr : &d);
    const auto& gt = truth[static_cast<std::size_t>(n++)];
    if (!pose.ok()) {
      std::printf("%s: no pose (%s)\n", frame.name.c_str(), std::string(tp::to_string(pose.status)).c_str());
      continue;
    }
    ++ok;
    const auto [position_error, orientation_error] = tp::pose_error(pose.T_camera_body, gt.T_camera_body);
    worst = std::max(worst, position_error);
    if (n % 15 == 1) {
      const Eigen::Vector3d t = pose.T_camera_body.translation();
      std::printf("%s: t = (%.3f, %.3f, %.3f) m, %d LEDs, %.2f px, error %.1f mm / %.2f deg\n", frame.name.c_str(),
                  t.x(), t.y(), t.z(), pose.points, pose.rms_px, 1000 * position_error, orientation_error * 57.29578);
    }
  }
  std::printf("tracked %d of %d frames, worst position error %.1f mm\n", ok, n, 1000 * worst);
  fs::remove_all(dir);
  return ok >= n - 1 && worst < 0.05 ? 0 : 1;
}
