// led_pose render and benchmark: a synthetic sequence on disk, and the
// LED-vs-ArUco table over rendered ones.
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
#include "led_pose.hpp"
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

namespace {

namespace td = touchdown;
namespace tp = touchdown::pose;
namespace fs = std::filesystem;
using td::app::format_fixed;
using td::app::number_in;
using namespace touchdown::app::led_pose_app;

// What rendering costs, measured on the 848x480 and 3840x2160 cameras
// (docs/cli.md): the PNGs of a frame take ~2.6 bytes a pixel on disk
// (noisy colour + depth), rendering and writing them ~90 ns a pixel, and
// the benchmark ~45 ns a pixel (rendering, LED tracking and ArUco).
constexpr double kPngBytesPerPixel = 2.6;
constexpr double kRenderSecondsPerPixel = 90e-9;
constexpr double kBenchmarkSecondsPerPixel = 45e-9;
// Largest requests (frames x pixels): ~26 GB of PNGs and ~15 min for
// render (24,567 frames at 848x480); ~75 min for the benchmark (40,946
// frames per sequence with the three default scenarios at 848x480).
constexpr double kMaxRenderPixels = 1e10;
constexpr double kMaxBenchmarkPixels = 1e11;

// ------------------------------------------------------------------ render

// Refused before anything is allocated, with what it would cost.
void check_render_request(const Args& a, const tp::CameraModel& camera) {
  check_render_size(camera, "--camera " + a.r_camera);
  if (const double pixels = static_cast<double>(a.frames) * camera.width * camera.height; pixels > kMaxRenderPixels) {
    throw td::InvalidArgument(
        "--frames " + std::to_string(a.frames) + " at " + size_text(camera) + ": " + td::app::large_count(pixels) +
        " pixels to render, ~" + td::app::gigabytes(pixels * kPngBytesPerPixel) + " of PNGs and ~" +
        td::app::duration_text(pixels * kRenderSecondsPerPixel) + "; the limit is " +
        td::app::large_count(kMaxRenderPixels) + " pixels (" +
        std::to_string(static_cast<long long>(kMaxRenderPixels / (static_cast<double>(camera.width) * camera.height))) +
        " frames at " + size_text(camera) + ")");
  }
}

// The profile's rendering options with the ones set on the command line.
tp::RenderOptions render_options(const Args& a) {
  tp::RenderOptions r = tp::apply_profile({}, a.profile);
  if (a.noise_opt->count()) r.noise_sigma = a.ropt.noise_sigma;
  if (a.distractors_opt->count()) r.distractor_count = a.ropt.distractor_count;
  if (a.dropout_opt->count()) r.led_dropout_probability = a.ropt.led_dropout_probability;
  r.aruco_dictionary = a.aruco.dictionary;
  r.aruco_id = a.aruco.marker_id;
  r.aruco_size = a.aruco.marker_size;
  std::string why;
  if (!r.validate(&why)) throw td::InvalidArgument(in_flag_terms(why));
  return r;
}

// OUT_DIR, checked before any work: its parent exists, and it is new or
// empty unless --overwrite (two sequences never mix).
void check_render_output(const Args& a) {
  fs::path target = fs::path(a.out_dir).lexically_normal();
  if (!target.has_filename()) target = target.parent_path();
  const fs::path parent = target.has_parent_path() ? target.parent_path() : fs::path(".");
  std::error_code ec;
  if (!fs::is_directory(parent, ec)) {
    throw td::IoError(a.out_dir + ": output directory '" + parent.string() + "' does not exist");
  }
  if (!fs::exists(target, ec)) return;
  if (!fs::is_directory(target, ec)) throw td::IoError(a.out_dir + ": exists and is not a directory");
  if (!a.overwrite && !fs::is_empty(target, ec)) {
    throw td::IoError(a.out_dir +
                      ": exists and is not empty; give --overwrite to replace the sequence in it (other files are "
                      "kept)");
  }
}

// --------------------------------------------------------------- benchmark

// The benchmark's options, refusing what it would ignore and a request over
// the size limit.
tp::PoseBenchmarkOptions benchmark_options(const Args& a) {
  if (a.r_constellation.empty()) {
    const std::string why =
        "applies only with --constellation (the default scenarios fix their own geometry, "
        "tilt and rendering)";
    refuse_unused(a.bench_geometry, why);
    refuse_unused(a.bench_tilt, why);
    refuse_unused(a.bench_profile, why);
  } else if (a.geometry != tp::CameraGeometry::Chase) {
    refuse_unused(a.bench_tilt, "applies only with --geometry chase");
  }
  tp::PoseBenchmarkOptions o;
  o.camera = camera_or_default(a.r_camera);
  check_render_size(o.camera, "--camera " + a.r_camera);
  if (a.r_constellation.empty()) {
    o.scenarios = tp::default_benchmark_scenarios();
  } else {
    o.scenarios.push_back({fs::path(a.r_constellation).stem().string() + " " + std::string(tp::to_string(a.geometry)),
                           tp::load_constellation(a.r_constellation), a.geometry, a.camera_tilt_deg, a.profile});
  }
  o.frames = a.bench_frames;
  const auto sequences = static_cast<double>(2 * o.scenarios.size());  // static and moving
  const double frame_pixels = static_cast<double>(o.camera.width) * o.camera.height;
  if (const double pixels = a.bench_frames * sequences * frame_pixels; pixels > kMaxBenchmarkPixels) {
    throw td::InvalidArgument("--frames " + std::to_string(a.bench_frames) + ": " +
                              std::to_string(2 * o.scenarios.size()) + " sequences of " + size_text(o.camera) +
                              " frames, " + td::app::large_count(pixels) + " pixels to render and track, ~" +
                              td::app::duration_text(pixels * kBenchmarkSecondsPerPixel) + "; the limit is " +
                              td::app::large_count(kMaxBenchmarkPixels) + " pixels (" +
                              std::to_string(static_cast<long long>(kMaxBenchmarkPixels / (sequences * frame_pixels))) +
                              " frames per sequence here)");
  }
  o.seed = a.seed;
  o.use_depth = !a.no_depth;
  o.tracker.fuse_frames = a.fuse;
  o.aruco = a.aruco;
  return o;
}

}  // namespace

namespace touchdown::app::led_pose_app {

int run_render(const Args& a) {
  check_render_output(a);
  if (a.geometry != tp::CameraGeometry::Chase) refuse_unused(a.render_tilt, "applies only with --geometry chase");
  const auto camera = camera_or_default(a.r_camera);
  check_render_request(a, camera);
  const auto k = constellation_or_default(a.r_constellation);
  const tp::RenderOptions r = render_options(a);
  tp::TrajectoryOptions to;
  to.min_distance = a.min_distance;
  to.max_distance = a.max_distance;
  to.geometry = a.geometry;
  to.camera_tilt_deg = a.camera_tilt_deg;
  std::vector<tp::TrajectorySample> samples;
  try {
    samples = tp::make_trajectory(a.trajectory, a.frames, a.seed, camera, k, to);
  } catch (const td::InvalidArgument& e) {
    throw td::InvalidArgument(in_flag_terms(e.what()));
  }
  td::app::ProgressBar bar("led_pose", "frames");
  const td::ProgressCallback progress = [&bar](const td::Progress& p) { bar.draw(p.done, p.total); };
  tp::write_sequence(a.out_dir, camera, k, samples, r, a.seed, progress);
  bar.close();
  std::cerr << "led_pose: wrote " << samples.size() << " frames to " << a.out_dir << "\n";
  return td::app::kExitOk;
}

}  // namespace touchdown::app::led_pose_app

namespace touchdown::app::led_pose_app {

int run_benchmark(const Args& a) {
  const auto r = tp::run_pose_benchmark(benchmark_options(a));
  if (!r.ok()) std::cerr << "led_pose: benchmark: " << r.message << "\n";
  std::cout << (a.json ? tp::benchmark_json(r, a.bench_frames, a.seed) + "\n" : tp::benchmark_table(r));
  return td::app::kExitOk;
}

}  // namespace touchdown::app::led_pose_app
