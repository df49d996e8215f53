// led_pose: the drone's 6-DoF pose from its LEDs seen by a ground camera
// (or from an ArUco marker, the baseline), over a sequence of frames; and
// the synthetic camera (`render`) and the LED-vs-ArUco table (`benchmark`).
//
// This file: main, the command line and the shared pieces; the modes are in
// led_pose_render.cpp and led_pose_sequence.cpp (led_pose.hpp).
#include "led_pose.hpp"

#include <chrono>
#include <cmath>
#include <cstring>
#include <filesystem>
#include <functional>
#include <iomanip>
#include <iostream>
#include <map>
#include <nlohmann/json.hpp>
#include <optional>
#include <sstream>
#include <vector>

#include "app_common.hpp"
#include "touchdown/core/statistics.hpp"
#include "touchdown/core/units.hpp"
#include "touchdown/pose/camera.hpp"
#include "touchdown/pose/constellation.hpp"
#include "touchdown/pose/ground_truth.hpp"
#include "touchdown/pose/led_tracker.hpp"
#include "touchdown/pose/pose_json.hpp"
#include "touchdown/pose/sim/aruco_baseline.hpp"
#include "touchdown/pose/sim/pose_benchmark.hpp"
#include "touchdown/pose/sim/sequence.hpp"
#include "touchdown/pose/sim/synthetic.hpp"
#include "touchdown/pose/sim/trajectory.hpp"

namespace touchdown::app::led_pose_app {

namespace td = touchdown;
namespace fs = std::filesystem;

std::string size_text(const tp::CameraModel& c) { return std::to_string(c.width) + "x" + std::to_string(c.height); }

// The renderer's image limit, checked before anything is allocated, naming
// the camera file (`what`: "--camera FILE").
void check_render_size(const tp::CameraModel& c, const std::string& what) {
  const double pixels = static_cast<double>(c.width) * c.height;
  if (pixels <= static_cast<double>(tp::SyntheticCamera::kMaxPixels)) return;
  throw td::InvalidArgument(
      what + ": " + std::to_string(c.width) + " x " + std::to_string(c.height) + " = " +
      std::to_string(static_cast<long long>(pixels)) + " pixels needs ~" +
      td::app::gigabytes(pixels * tp::SyntheticCamera::kBytesPerPixel) + " a frame to render; the limit is " +
      std::to_string(tp::SyntheticCamera::kMaxPixels) + " pixels (4096 x 4096, ~" +
      td::app::gigabytes(static_cast<double>(tp::SyntheticCamera::kMaxPixels) * tp::SyntheticCamera::kBytesPerPixel) +
      ")");
}

// Library messages name option fields (`noise_sigma: must be in [0, 100]`);
// the user typed flags. Names the flag instead, for render's options and
// the ArUco baseline's.
std::string in_flag_terms(std::string message) {
  static const std::pair<const char*, const char*> kFlagNames[] = {
      {"make_trajectory: ", ""},
      {"increase min_distance or reduce margin_px", "increase --min-distance"},
      {"min_distance, max_distance: need 0 < min_distance <= max_distance",
       "--min-distance, --max-distance: need 0 < --min-distance <= --max-distance"},
      {"noise_sigma", "--noise"},
      {"distractor_count", "--distractors"},
      {"led_dropout_probability", "--dropout"},
      {"camera_tilt_deg", "--camera-tilt"},
      {"aruco_size", "--aruco-size"},
      {"aruco_id", "--aruco-id"},
      {"aruco_dictionary", "--aruco-dict"},
      {"frames must", "--frames must"},
      // The ArUco baseline's options (sequence mode).
      {"ArUco options: ", ""},
      {"marker_size", "--aruco-size"},
      {"marker_id", "--aruco-id"},
      {"dictionary: unknown", "--aruco-dict: unknown"},
  };
  for (const auto& [field, flag] : kFlagNames) {
    for (std::size_t at = message.find(field); at != std::string::npos;
         at = message.find(field, at + std::strlen(flag))) {
      message.replace(at, std::strlen(field), flag);
    }
  }
  return message;
}

tp::CameraModel camera_or_default(const std::string& f) { return f.empty() ? tp::CameraModel{} : tp::load_camera(f); }

tp::Constellation constellation_or_default(const std::string& f) {
  return f.empty() ? tp::default_constellation() : tp::load_constellation(f);
}

void refuse_unused(const CLI::Option* opt, const std::string& why) {
  if (opt->count()) throw td::InvalidArgument(opt->get_name() + ": " + why);
}

}  // namespace touchdown::app::led_pose_app

namespace {

namespace td = touchdown;
namespace tp = touchdown::pose;
namespace fs = std::filesystem;
using td::app::format_fixed;
using td::app::number_in;
using namespace touchdown::app::led_pose_app;

// Largest id of any dictionary (ARUCO_ORIGINAL has 1024 markers); the
// dictionary's own size is checked when the options are validated.
constexpr int kMaxArucoId = 1023;

void add_sequence_options(CLI::App& app, Args& a) {
  app.add_option("SEQUENCE_DIR", a.sequence_dir, "directory of NNNNNN.png frames (+ NNNNNN.depth.png)");
  app.add_option("--camera", a.camera_file,
                 "camera file: touchdown camera YAML, OpenCV calibration YAML or ROS camera_info YAML "
                 "(default: SEQUENCE_DIR/camera.yaml)");
  app.add_option("--constellation", a.constellation_file,
                 "LED constellation YAML (default: SEQUENCE_DIR/constellation.yaml)");
  app.add_option("--method", a.method, "led or aruco")->check(CLI::IsMember({"led", "aruco"}))->capture_default_str();
  a.aruco_dict_opt = app.add_option("--aruco-dict", a.aruco.dictionary,
                                    "ArUco dictionary (4X4_50, 6X6_250, APRILTAG_36h11, ...; default: the one "
                                    "SEQUENCE_DIR/sequence.yaml records, else 4X4_50)");
  a.aruco_id_opt = app.add_option("--aruco-id", a.aruco.marker_id,
                                  "ArUco marker id on the airframe, below the dictionary's size (default: "
                                  "SEQUENCE_DIR/sequence.yaml's, else 3)")
                       ->check(number_in(0, kMaxArucoId));
  a.aruco_size_opt = app.add_option("--aruco-size", a.aruco.marker_size,
                                    "ArUco marker edge [m] (default: SEQUENCE_DIR/sequence.yaml's, else 0.1)")
                         ->check(number_in(0, 10, true));
  app.add_flag("--no-depth", a.no_depth, "ignore depth images (2-D gating only)");
  app.add_flag("--fuse", a.fuse,
               "report poses fused over the track's frames (a Kalman filter) instead of each frame's own; "
               "not for a flight stack that filters the poses itself");
  app.add_flag("--jsonl", a.jsonl, "one JSON object per frame on stdout");
  app.add_option("--attitude", a.attitude_file,
                 "attitude JSON Lines, one line per frame: the gravity direction measured in the camera and the body "
                 "frame (docs/formats.md); the LED tracker uses it as a prior");
  app.add_option("--max-sigma", a.max_sigma,
                 "POSITION_M,ROTATION_RAD: report a pose whose 1-sigma exceeds either as 'too uncertain' "
                 "(default: 0.03,0.03 for a fit that does not explain its whole frame, none for a tracked fit "
                 "that does; docs/benchmarks.md)")
      ->delimiter(',')
      ->expected(2)
      ->allow_extra_args(false)  // `--max-sigma 0.05,0.05 SEQ` leaves SEQ to the positional
      ->check(number_in(0, 10, true));
}

void add_render_command(CLI::App& app, Args& a) {
  auto* render = app.add_subcommand("render", "write a synthetic sequence (colour + depth PNGs, ground_truth.jsonl)");
  a.render = render;
  render->add_option("OUT_DIR", a.out_dir, "directory to create (its parent must exist)")->required();
  render->add_flag("--overwrite", a.overwrite,
                   "OUT_DIR may hold a sequence: replace it (its frames, ground truth, camera and constellation "
                   "files; other files are kept)");
  render->add_option(
      "--camera", a.r_camera,
      "camera file, as for SEQUENCE_DIR, up to 4096x4096 pixels (default: a D435 colour stream at 848x480)");
  render->add_option("--constellation", a.r_constellation,
                     "constellation YAML (default: the built-in F450 six-LED set)");
  td::app::add_enum_option(*render, "--trajectory", a.trajectory,
                           "camera path: " + td::enum_names_list<tp::TrajectoryKind>());
  td::app::add_enum_option(*render, "--geometry", a.geometry,
                           "facing: the camera faces the constellation's facing side (from below for downward "
                           "LEDs); chase: the paper's ground-vehicle camera, tilted up, with the drone behind and "
                           "above it");
  a.render_tilt =
      render->add_option("--camera-tilt", a.camera_tilt_deg, "chase: camera tilt above the horizontal [deg]")
          ->check(number_in(0, 80))
          ->check(td::app::degrees_not_radians("--camera-tilt"))
          ->capture_default_str();
  render
      ->add_option("--frames", a.frames,
                   "number of frames (frames x camera pixels <= 1e10: 24,567 frames at 848x480, ~26 GB of PNGs)")
      ->check(number_in(1, tp::kMaxTrajectoryFrames))
      ->capture_default_str();
  td::app::add_seed_option(*render, "--seed", a.seed, "random seed");
  render->add_option("--min-distance", a.min_distance, "closest camera-constellation (LED centroid) distance [m]")
      ->check(number_in(0, tp::kMaxTrajectoryDistance, true))
      ->capture_default_str();
  render->add_option("--max-distance", a.max_distance, "farthest camera-constellation distance [m]")
      ->check(number_in(0, tp::kMaxTrajectoryDistance, true))
      ->capture_default_str();
  td::app::add_enum_option(*render, "--profile", a.profile,
                           "clean, or harsh: white-clipping LED cores with hue halos, exposure steps, LED-coloured "
                           "lamps, airframe reflections, motion-blur streaks, rolling drop-outs");
  // Set explicitly, these override the profile's values.
  a.noise_opt = render->add_option("--noise", a.ropt.noise_sigma, "sensor noise [DN] (default: the profile's)")
                    ->check(number_in(0, 100));
  a.distractors_opt =
      render->add_option("--distractors", a.ropt.distractor_count, "bright lamps in view (default: the profile's)")
          ->check(number_in(0, 100));
  a.dropout_opt = render
                      ->add_option("--dropout", a.ropt.led_dropout_probability,
                                   "per-LED per-frame dropout probability (default: the profile's)")
                      ->check(number_in(0, 1));
  render->add_option("--aruco-dict", a.aruco.dictionary, "ArUco dictionary of the rendered marker")
      ->capture_default_str();
  render->add_option("--aruco-id", a.aruco.marker_id, "ArUco id (below the dictionary's size)")
      ->check(number_in(0, kMaxArucoId))
      ->capture_default_str();
  render->add_option("--aruco-size", a.aruco.marker_size, "ArUco marker edge [m]")
      ->check(number_in(0, 10, true))
      ->capture_default_str();
}

void add_benchmark_command(CLI::App& app, Args& a) {
  auto* bench = app.add_subcommand("benchmark", "render static and moving sequences and compare LED and ArUco");
  a.bench = bench;
  bench
      ->add_option("--frames", a.bench_frames,
                   "frames per sequence (frames x sequences x camera pixels <= 1e11: 40,946 frames with the "
                   "default scenarios at 848x480, ~75 min)")
      ->check(number_in(1, tp::kMaxTrajectoryFrames))
      ->capture_default_str();
  td::app::add_seed_option(*bench, "--seed", a.seed, "random seed");
  bench->add_option(
      "--camera", a.r_camera,
      "camera file, as for SEQUENCE_DIR, up to 4096x4096 pixels (default: a D435 colour stream at 848x480)");
  bench->add_option("--constellation", a.r_constellation,
                    "constellation YAML: one scenario in --geometry (default: two built-in scenarios, the F450's "
                    "downward LEDs from below and the paper's front board in the chase geometry)");
  a.bench_geometry = td::app::add_enum_option(*bench, "--geometry", a.geometry,
                                              "with --constellation: " + td::enum_names_list<tp::CameraGeometry>());
  a.bench_tilt = bench
                     ->add_option("--camera-tilt", a.camera_tilt_deg,
                                  "with --constellation and --geometry chase: camera tilt above the horizontal [deg]")
                     ->check(number_in(0, 80))
                     ->check(td::app::degrees_not_radians("--camera-tilt"))
                     ->capture_default_str();
  a.bench_profile = td::app::add_enum_option(
      *bench, "--profile", a.profile, "with --constellation: rendering, " + td::enum_names_list<tp::RenderProfile>());
  bench->add_flag("--no-depth", a.no_depth, "LED method without depth");
  bench->add_flag("--fuse", a.fuse, "LED method: poses fused over the track's frames");
  bench->add_flag("--json", a.json, "print one JSON object on stdout");
}

}  // namespace

int main(int argc, char** argv) {
  CLI::App app{
      "Estimate the drone's pose from its LEDs (or an ArUco marker) in a sequence of camera frames.\n"
      "Subcommands: render (synthetic sequence), benchmark (LED vs ArUco table).",
      "led_pose"};
  app.require_subcommand(0, 1);
  Args a;
  add_sequence_options(app, a);
  add_render_command(app, a);
  add_benchmark_command(app, a);

  return td::app::run(app, argc, argv, [&]() -> int {
    if (*a.render) return run_render(a);
    if (*a.bench) return run_benchmark(a);
    return run_sequence(a);
  });
}
