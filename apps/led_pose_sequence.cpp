// led_pose on a sequence of frames: the LED tracker or the ArUco baseline,
// its poses as JSON Lines or a summary against the ground truth.
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

// The camera/constellation YAML given, else the one a rendered sequence carries.
fs::path config_path(const std::string& given, const fs::path& dir, const char* file, const char* option) {
  if (!given.empty()) return given;
  if (!dir.empty() && fs::exists(dir / file)) return dir / file;
  throw td::InvalidArgument(std::string(option) + " is required (no " + file + " in the sequence directory)");
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

}  // namespace

namespace touchdown::app::led_pose_app {

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

}  // namespace touchdown::app::led_pose_app
