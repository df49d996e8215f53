// led_pose: the drone's 6-DoF pose from its LEDs seen by a ground camera
// (or from an ArUco marker, the baseline), over a sequence of frames; and
// the synthetic camera (`render`) and the LED-vs-ArUco table (`benchmark`).
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

// Largest id of any dictionary (ARUCO_ORIGINAL has 1024 markers); the
// dictionary's own size is checked when the options are validated.
constexpr int kMaxArucoId = 1023;

// The camera/constellation YAML given, else the one a rendered sequence carries.
fs::path config_path(const std::string& given, const fs::path& dir, const char* file, const char* option) {
  if (!given.empty()) return given;
  if (!dir.empty() && fs::exists(dir / file)) return dir / file;
  throw td::InvalidArgument(std::string(option) + " is required (no " + file + " in the sequence directory)");
}

// One JSON line by hand: fixed decimals (nlohmann would print the binary
// value of a rounded double in full), q with w >= 0.
std::string pose_json(const std::string& frame, const tp::PoseEstimate& e, double ms) {
  char buf[512];
  if (e.ok()) {
    const Eigen::Vector3d t = e.T_camera_body.translation();
    Eigen::Quaterniond q(e.T_camera_body.linear());
    if (q.w() < 0) q.coeffs() = -q.coeffs();
    std::snprintf(buf, sizeof(buf),
                  "{\"frame\": \"%s\", \"ok\": true, \"t\": [%.6f, %.6f, %.6f], \"q\": [%.7f, %.7f, %.7f, %.7f], "
                  "\"sigma\": [%.6f, %.6f], \"reproj_px\": %.3f, \"leds\": %d, \"blobs\": %d, \"ms\": %.3f, ",
                  frame.c_str(), t.x(), t.y(), t.z(), q.w(), q.x(), q.y(), q.z(), e.sigma_position_m,
                  e.sigma_rotation_rad, e.rms_px, e.points, e.blobs, ms);
    // The full 6×6 twist covariance, row-major (docs/formats.md).
    std::string out = buf;
    out += "\"covariance\": [";
    for (int r = 0; r < 6; ++r) {
      for (int c = 0; c < 6; ++c) {
        std::snprintf(buf, sizeof(buf), "%s%.6e", r + c ? ", " : "", e.covariance(r, c));
        out += buf;
      }
    }
    return out + "]}";
  } else if (e.status == tp::PoseStatus::Uncertain) {  // the figures that failed the gate
    std::snprintf(buf, sizeof(buf),
                  "{\"frame\": \"%s\", \"ok\": false, \"reason\": \"%s\", \"sigma\": [%.6f, %.6f], \"blobs\": %d, "
                  "\"ms\": %.3f}",
                  frame.c_str(), std::string(tp::to_string(e.status)).c_str(), e.sigma_position_m, e.sigma_rotation_rad,
                  e.blobs, ms);
  } else {
    std::snprintf(buf, sizeof(buf),
                  "{\"frame\": \"%s\", \"ok\": false, \"reason\": \"%s\", \"blobs\": %d, \"ms\": %.3f}", frame.c_str(),
                  std::string(tp::to_string(e.status)).c_str(), e.blobs, ms);
  }
  return buf;
}

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

// The command line of the three modes: sequence (the default), render and
// benchmark. Some options are shared: the ArUco marker (sequence, render),
// the rendering choices (render, benchmark), depth and fusion (sequence,
// benchmark).
struct Args {
  // Sequence mode.
  std::string sequence_dir, camera_file, constellation_file, method = "led";
  tp::ArucoOptions aruco;
  // Given on the command line: checked against the sequence's own marker.
  CLI::Option *aruco_dict_opt = nullptr, *aruco_id_opt = nullptr, *aruco_size_opt = nullptr;
  bool no_depth = false, jsonl = false, fuse = false;
  std::string attitude_file;
  std::vector<double> max_sigma;  // --max-sigma POSITION_M,ROTATION_RAD (empty: the tracker's default)
  // render; benchmark shares the camera, constellation, geometry, tilt,
  // seed and profile.
  CLI::App* render = nullptr;
  std::string out_dir, r_camera, r_constellation;
  bool overwrite = false;
  tp::TrajectoryKind trajectory = tp::TrajectoryKind::Static;
  tp::CameraGeometry geometry = tp::CameraGeometry::Facing;
  double camera_tilt_deg = 20;
  int frames = 300;
  std::uint64_t seed = 1;
  double min_distance = 0.4, max_distance = 3.0;
  tp::RenderOptions ropt;
  tp::RenderProfile profile = tp::RenderProfile::Clean;
  CLI::Option* render_tilt = nullptr;
  // Set explicitly, these override the profile's values.
  CLI::Option *noise_opt = nullptr, *distractors_opt = nullptr, *dropout_opt = nullptr;
  // benchmark.
  CLI::App* bench = nullptr;
  bool json = false;
  int bench_frames = 300;
  CLI::Option *bench_geometry = nullptr, *bench_tilt = nullptr, *bench_profile = nullptr;
};

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

tp::CameraModel camera_or_default(const std::string& f) { return f.empty() ? tp::CameraModel{} : tp::load_camera(f); }

tp::Constellation constellation_or_default(const std::string& f) {
  return f.empty() ? tp::default_constellation() : tp::load_constellation(f);
}

// Options that would be silently ignored are errors (issue 11).
void refuse_unused(const CLI::Option* opt, const std::string& why) {
  if (opt->count()) throw td::InvalidArgument(opt->get_name() + ": " + why);
}

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

nlohmann::json benchmark_json(const Args& a, const tp::PoseBenchmarkResult& r) {
  nlohmann::json j;
  j["status"] = std::string(tp::to_string(r.status));
  j["frames_per_sequence"] = a.bench_frames;
  j["seed"] = a.seed;
  for (const auto& row : r.rows) {
    j["rows"].push_back({{"scenario", row.scenario},
                         {"profile", row.profile},
                         {"method", row.method},
                         {"sequence", row.sequence},
                         {"frames", row.frames},
                         {"success_rate", row.success_rate},
                         {"wrong_ok", row.wrong_ok},
                         {"wrong_ok_rate", row.wrong_ok_rate},
                         {"position_mean_m", row.position_mean_m},
                         {"position_std_m", row.position_std_m},
                         {"position_max_m", row.position_max_m},
                         {"orientation_mean_rad", row.orientation_mean_rad},
                         {"orientation_std_rad", row.orientation_std_rad},
                         {"ms_median", row.ms_median},
                         {"ms_p90", row.ms_p90}});
  }
  j["solvers_us_median"] = {{"epnp_gauss_newton", r.epnp_gn_us_median},
                            {"opencv_iterative", r.opencv_iterative_us_median},
                            {"opencv_sqpnp", r.opencv_sqpnp_us_median},
                            {"opencv_epnp", r.opencv_epnp_us_median},
                            {"samples", r.solver_samples}};
  return j;
}

void print_benchmark_table(const tp::PoseBenchmarkResult& r) {
  std::size_t scenario_width = 16;  // a custom scenario's name may be longer
  for (const auto& row : r.rows) scenario_width = std::max(scenario_width, row.scenario.size() + 2);
  std::cout << std::left << std::setw(static_cast<int>(scenario_width)) << "scenario"
            << "profile  sequence  method  frames  success  wrong-ok  pos mean [m]  pos std [m]  "
               "rot mean [rad]  rot std [rad]  ms/frame (median)\n";
  for (const auto& row : r.rows) {
    std::cout << std::left << std::setw(static_cast<int>(scenario_width)) << row.scenario << std::setw(9) << row.profile
              << std::setw(10) << row.sequence << std::setw(8) << row.method << std::right << std::setw(6) << row.frames
              << std::setw(9) << format_fixed(row.success_rate, 3) << std::setw(10) << row.wrong_ok << std::setw(14)
              << format_fixed(row.position_mean_m, 4) << std::setw(13) << format_fixed(row.position_std_m, 4)
              << std::setw(16) << format_fixed(row.orientation_mean_rad, 4) << std::setw(15)
              << format_fixed(row.orientation_std_rad, 4) << std::setw(19) << format_fixed(row.ms_median, 3) << "\n";
  }
  std::cout << "solvers on the tracked LEDs (median, " << r.solver_samples << " frames): EPnP+GN "
            << format_fixed(r.epnp_gn_us_median, 1) << " us, OpenCV ITERATIVE "
            << format_fixed(r.opencv_iterative_us_median, 1) << " us, SQPNP "
            << format_fixed(r.opencv_sqpnp_us_median, 1) << " us, EPNP " << format_fixed(r.opencv_epnp_us_median, 1)
            << " us\n";
}

int run_benchmark(const Args& a) {
  const auto r = tp::run_pose_benchmark(benchmark_options(a));
  if (!r.ok()) std::cerr << "led_pose: benchmark: " << r.message << "\n";
  if (a.json) {
    std::cout << benchmark_json(a, r).dump() << "\n";
  } else {
    print_benchmark_table(r);
  }
  return td::app::kExitOk;
}

// ---------------------------------------------------------------- sequence

// What tracks the sequence: the LED tracker or the ArUco baseline.
struct Estimator {
  std::optional<tp::LedTracker> tracker;
  std::optional<tp::ArucoPoseEstimator> marker;
};

// The ArUco marker to look for: the one the sequence was rendered with
// (sequence.yaml) unless the sequence does not record it. An option given
// on the command line that contradicts the recorded marker is refused: the
// poses would be wrong by the size ratio without a word (issue 31 item 12).
tp::ArucoOptions marker_of_sequence(const Args& a, const fs::path& dir, const tp::SequenceInfo& info) {
  std::string why;  // the options themselves first: "--aruco-id: 60 is not in dictionary 4X4_50"
  if (!a.aruco.validate(&why)) throw td::InvalidArgument(in_flag_terms(why));
  if (!info.aruco) return a.aruco;
  const std::string file = (dir / tp::kSequenceInfoFile).string();
  const auto refuse = [&](const CLI::Option* opt, const std::string& given, const std::string& recorded,
                          const char* key) {
    throw td::InvalidArgument(opt->get_name() + " " + given + " contradicts " + file +
                              ": the sequence was rendered with " + key + " " + recorded +
                              " (leave the option out to use it)");
  };
  const tp::ArucoOptions& rec = *info.aruco;
  if (a.aruco_dict_opt->count() &&
      tp::canonical_aruco_dictionary(a.aruco.dictionary) != tp::canonical_aruco_dictionary(rec.dictionary)) {
    refuse(a.aruco_dict_opt, a.aruco.dictionary, rec.dictionary, "aruco.dictionary");
  }
  if (a.aruco_id_opt->count() && a.aruco.marker_id != rec.marker_id) {
    refuse(a.aruco_id_opt, std::to_string(a.aruco.marker_id), std::to_string(rec.marker_id), "aruco.id");
  }
  if (a.aruco_size_opt->count() &&
      std::abs(a.aruco.marker_size - rec.marker_size) > 1e-9 * std::max(1.0, rec.marker_size)) {
    refuse(a.aruco_size_opt, td::detail::format_exact(a.aruco.marker_size), td::detail::format_exact(rec.marker_size),
           "aruco.size");
  }
  tp::ArucoOptions o = a.aruco;
  o.dictionary = rec.dictionary;
  o.marker_id = rec.marker_id;
  o.marker_size = rec.marker_size;
  return o;
}

void set_up_estimator(Estimator& est, const Args& a, const tp::CameraModel& camera, const tp::Constellation& k,
                      const tp::SequenceInfo& info) {
  if (a.method == "led") {
    tp::TrackerOptions to;
    to.use_depth = !a.no_depth;
    to.fuse_frames = a.fuse;
    if (a.max_sigma.size() == 2) {
      to.correspondence.max_sigma_position_m = to.correspondence.attitude_max_sigma_position_m =
          to.complete_max_sigma_position_m = a.max_sigma[0];
      to.correspondence.max_sigma_rotation_rad = to.correspondence.attitude_max_sigma_rotation_rad =
          to.complete_max_sigma_rotation_rad = a.max_sigma[1];
    }
    est.tracker.emplace(camera, k, to);
  } else {
    if (!a.max_sigma.empty()) throw td::InvalidArgument("--max-sigma: only the LED method reports a sigma limit");
    try {
      est.marker.emplace(camera, k.T_body_marker, marker_of_sequence(a, a.sequence_dir, info));
    } catch (const td::InvalidArgument& e) {
      throw td::InvalidArgument(in_flag_terms(e.what()));
    }
  }
}

// The sequence's frames as they are tracked, and what is said about them.
struct SequenceRun {
  touchdown::BgrImage colour;
  touchdown::DepthImage depth;
  bool depth_scale_checked = false;
  std::string out;  // printed at the end: a bad frame leaves no partial output
  int ok = 0;
  std::vector<double> ms, rms, pos_err, rot_err;
  std::vector<std::string> wrong_ok;   // frames reported ok but off the truth by more than kWrongOk*
  std::map<std::string, int> no_pose;  // why the others have none: status -> frames
  int grey = 0;                        // frames without colour (B = G = R everywhere)
};

// True when every pixel (every 7th, for speed) has B = G = R: a grey frame,
// in which LEDs found by their colour cannot be.
bool is_grey(const touchdown::BgrImage& image) {
  for (std::size_t i = 0; i + 2 < image.pixels.size(); i += 3 * 7) {
    if (image.pixels[i] != image.pixels[i + 1] || image.pixels[i] != image.pixels[i + 2]) return false;
  }
  return !image.pixels.empty();
}

// A pose reported ok but farther than this from the ground truth is wrong
// (the benchmark's wrong-ok threshold).
constexpr double kWrongOkPositionM = 0.1;
constexpr double kWrongOkRotationRad = 0.1;

// Reads frame `f` into run.colour (and run.depth), refusing an image of
// another size than the camera's or depth in another unit.
void read_checked_frame(const tp::SequenceFrame& f, bool want_depth, const tp::CameraModel& camera,
                        const fs::path& camera_path, SequenceRun& run) {
  tp::read_frame(f, run.colour, want_depth ? &run.depth : nullptr);
  if (is_grey(run.colour)) ++run.grey;
  if (run.colour.width != camera.width || run.colour.height != camera.height) {
    throw td::ParseError(f.colour.string() + ": image is " + std::to_string(run.colour.width) + "x" +
                         std::to_string(run.colour.height) + " but the camera is " + std::to_string(camera.width) +
                         "x" + std::to_string(camera.height));
  }
  // The first depth frame with enough measurements tells whether the
  // camera's depth_scale fits its unit: a wrong one would make the
  // depth gate drop every LED without a word.
  if (want_depth && !run.depth_scale_checked) {
    const auto check = tp::check_depth_scale(run.depth.view(), camera.depth_scale);
    run.depth_scale_checked = check.conclusive;
    if (!check.plausible) {
      throw td::ParseError(camera_path.string() + ": " + check.message + " (seen in " + f.depth->filename().string() +
                           ")");
    }
  }
}

// Counts a frame's estimate, and its error when the ground truth has the frame.
void record_estimate(const tp::SequenceFrame& f, const tp::PoseEstimate& e, double elapsed,
                     const std::map<std::string, const tp::GroundTruthSample*>& truth, bool jsonl, SequenceRun& run) {
  run.ms.push_back(elapsed);
  if (!e.ok()) ++run.no_pose[std::string(tp::to_string(e.status))];
  if (e.ok()) {
    ++run.ok;
    run.rms.push_back(e.rms_px);
    if (const auto it = truth.find(f.name); it != truth.end()) {
      const auto [p, r] = tp::pose_error(e.T_camera_body, it->second->T_camera_body);
      run.pos_err.push_back(p);
      run.rot_err.push_back(r);
      if (p > kWrongOkPositionM || r > kWrongOkRotationRad) run.wrong_ok.push_back(f.name);
    }
  }
  if (jsonl) run.out += pose_json(f.name, e, elapsed) + "\n";
}

double mean(const std::vector<double>& v) {
  double s = 0;
  for (double x : v) s += x;
  return v.empty() ? 0.0 : s / static_cast<double>(v.size());
}

void print_sequence_summary(const Args& a, std::size_t frames, const SequenceRun& run) {
  std::cout << "led_pose: " << a.method << " on " << frames << " frames of " << a.sequence_dir << "\n"
            << "  pose found      " << run.ok << " / " << frames << " ("
            << format_fixed(100.0 * run.ok / static_cast<double>(std::max<std::size_t>(1, frames)), 1) << "%)\n";
  if (!run.no_pose.empty()) {
    // Why the others have none (issue 58 item 5: a run of grey frames said
    // only "0 / 10").
    std::vector<std::pair<std::string, int>> why(run.no_pose.begin(), run.no_pose.end());
    std::stable_sort(why.begin(), why.end(), [](const auto& x, const auto& y) { return x.second > y.second; });
    std::cout << "  no pose         ";
    for (std::size_t i = 0; i < why.size(); ++i) std::cout << (i ? ", " : "") << why[i].second << " " << why[i].first;
    std::cout << "\n";
  }
  if (run.grey > 0 && a.method == "led") {
    std::cout << "  note            " << td::app::count_noun(run.grey, "frame")
              << " without colour (grey): the LED method finds the LEDs by their colour\n";
  }
  std::cout << "  reprojection    median "
            << (run.rms.empty() ? std::string("n/a") : format_fixed(td::upper_median(run.rms), 3) + " px") << "\n"
            << "  time per frame  median " << format_fixed(td::upper_median(run.ms), 3) << " ms\n";
  if (!run.pos_err.empty()) {
    std::cout << "  vs ground truth mean position error " << format_fixed(mean(run.pos_err), 4) << " m, orientation "
              << format_fixed(mean(run.rot_err), 4) << " rad (" << run.pos_err.size() << " frames)\n"
              << "                  max  position error "
              << format_fixed(*std::max_element(run.pos_err.begin(), run.pos_err.end()), 4) << " m, orientation "
              << format_fixed(*std::max_element(run.rot_err.begin(), run.rot_err.end()), 4) << " rad\n"
              << "  wrong but ok    " << td::app::count_noun(static_cast<long long>(run.wrong_ok.size()), "frame")
              << " (> " << td::detail::format_general(kWrongOkPositionM) << " m or "
              << td::detail::format_general(kWrongOkRotationRad) << " rad)";
    // The first few, so that the user can look at them.
    constexpr std::size_t kListed = 8;
    for (std::size_t i = 0; i < std::min(kListed, run.wrong_ok.size()); ++i) {
      std::cout << (i == 0 ? ": " : ", ") << run.wrong_ok[i];
    }
    if (run.wrong_ok.size() > kListed) std::cout << ", ...";
    std::cout << "\n";
  }
}

// The attitude file's prior for every frame of the sequence, in its order;
// a frame the file lacks is an error naming it.
std::vector<tp::AttitudePrior> attitude_per_frame(const fs::path& file, const std::vector<tp::SequenceFrame>& frames) {
  const std::vector<tp::AttitudeSample> samples = tp::read_attitude(file);
  std::map<std::string, const tp::AttitudeSample*> by_frame;
  for (const auto& s : samples) by_frame[s.frame] = &s;
  std::vector<tp::AttitudePrior> out;
  out.reserve(frames.size());
  for (const auto& f : frames) {
    const auto it = by_frame.find(f.name);
    if (it == by_frame.end()) {
      throw td::ParseError(file.string() + ": no line for frame \"" + f.name + "\" of the sequence (" +
                           std::to_string(samples.size()) + " lines for " + std::to_string(frames.size()) + " frames)");
    }
    tp::AttitudePrior p;
    p.g_camera = it->second->g_camera;
    p.g_body = it->second->g_body;
    p.sigma_rad = td::deg_to_rad(it->second->sigma_deg);
    out.push_back(p);
  }
  return out;
}

int run_sequence(const Args& a) {
  if (a.sequence_dir.empty()) throw td::InvalidArgument("SEQUENCE_DIR is required (or a subcommand; see --help)");
  const fs::path dir(a.sequence_dir);
  const auto frames_list = tp::list_sequence(dir);
  const fs::path camera_path = config_path(a.camera_file, dir, "camera.yaml", "--camera");
  const auto camera = tp::load_camera(camera_path);
  const auto k =
      tp::load_constellation(config_path(a.constellation_file, dir, "constellation.yaml", "--constellation"));
  Estimator est;
  set_up_estimator(est, a, camera, k, tp::read_sequence_info(dir));
  // Ground truth, when the sequence carries it (a rendered one does).
  std::vector<tp::GroundTruthSample> truth;
  if (fs::exists(dir / "ground_truth.jsonl")) truth = tp::read_ground_truth(dir / "ground_truth.jsonl");
  std::map<std::string, const tp::GroundTruthSample*> truth_of;  // by frame name
  for (const auto& g : truth) truth_of.emplace(g.frame, &g);
  // The attitude prior, one per frame, all checked before any frame runs.
  std::vector<tp::AttitudePrior> priors;
  if (!a.attitude_file.empty()) {
    if (a.method != "led") throw td::InvalidArgument("--attitude: only the LED method uses an attitude prior");
    priors = attitude_per_frame(a.attitude_file, frames_list);
  }
  SequenceRun run;
  // A progress bar on a terminal once the run has taken over a second
  // (lines off one, for work over a minute).
  td::app::ProgressBar bar("led_pose", "frames");
  const bool on_terminal = td::app::ProgressBar::on_terminal();
  const auto start = std::chrono::steady_clock::now();
  for (std::size_t i = 0; i < frames_list.size(); ++i) {
    const tp::SequenceFrame& f = frames_list[i];
    if (!on_terminal || std::chrono::steady_clock::now() - start > std::chrono::seconds(1)) {
      bar.draw(i, frames_list.size());
    }
    const bool want_depth = a.method == "led" && !a.no_depth && f.depth;
    read_checked_frame(f, want_depth, camera, camera_path, run);
    const touchdown::DepthImageView dv = run.depth.view();
    const auto t0 = std::chrono::steady_clock::now();
    const tp::PoseEstimate e = !est.tracker ? est.marker->estimate(run.colour.view())
                               : priors.empty()
                                   ? est.tracker->track(run.colour.view(), want_depth ? &dv : nullptr)
                                   : est.tracker->track(run.colour.view(), want_depth ? &dv : nullptr, priors[i]);
    const double elapsed = std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - t0).count();
    record_estimate(f, e, elapsed, truth_of, a.jsonl, run);
  }
  bar.close();
  if (a.jsonl) {
    std::cout << run.out;
    return td::app::kExitOk;
  }
  print_sequence_summary(a, frames_list.size(), run);
  return td::app::kExitOk;
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
