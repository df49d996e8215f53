// landing_scenario run: one scenario, its outcome, video, snapshot and log.
#include <algorithm>
#include <atomic>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <iomanip>
#include <iostream>
#include <limits>
#include <map>
#include <mutex>
#include <nlohmann/json.hpp>
#include <opencv2/core.hpp>
#include <opencv2/imgcodecs.hpp>
#include <opencv2/imgproc.hpp>
#include <opencv2/videoio.hpp>
#include <optional>
#include <sstream>
#include <string>
#include <string_view>
#include <thread>
#include <vector>

#include "app_common.hpp"
#include "core/svg_plot.hpp"
#include "landing_scenario.hpp"
#include "system_option.hpp"
#include "touchdown/core/atomic_file.hpp"
#include "touchdown/core/statistics.hpp"
#include "touchdown/scenario/campaign.hpp"
#include "touchdown/scenario/contract.hpp"
#include "touchdown/scenario/dataset.hpp"
#include "touchdown/scenario/detector_bench.hpp"
#include "touchdown/scenario/marker_detector.hpp"
#include "touchdown/scenario/report.hpp"
#include "touchdown/scenario/run.hpp"
#include "touchdown/scenario/scenario.hpp"
#include "touchdown/search/dqn.hpp"
#include "touchdown/search/object_policy.hpp"
#include "video.hpp"

namespace {

namespace td = touchdown;
namespace ts = touchdown::scenario;
namespace tsr = touchdown::search;
namespace fs = std::filesystem;
using Json = nlohmann::ordered_json;
using namespace touchdown::app;
using namespace touchdown::app::scenario_app;

/// The camera view with the system's detections, phase and state drawn on.
cv::Mat overlay(const ts::CameraFrame& frame, const ts::SystemOutput& out, const td::DroneState& s) {
  cv::Mat img(frame.height, frame.width, CV_8UC3);
  std::memcpy(img.data, frame.image.pixels.data(), frame.image.pixels.size());
  for (const auto& d : out.detections) {
    std::vector<cv::Point> quad;
    for (const auto& c : d.corners)
      quad.emplace_back(static_cast<int>(std::lround(c.x())), static_cast<int>(std::lround(c.y())));
    const cv::Scalar colour = d.accepted ? cv::Scalar(0, 255, 0) : cv::Scalar(0, 0, 255);
    cv::polylines(img, quad, true, colour, 2);
    cv::putText(img, "id " + std::to_string(d.id), quad[0] + cv::Point(4, -6), cv::FONT_HERSHEY_SIMPLEX, 0.5, colour,
                1);
  }
  const std::string line =
      "t " + format_fixed(s.t, 1) + " s  alt " + format_fixed(s.position.z(), 1) + " m  " + std::string(out.phase);
  cv::rectangle(img, cv::Rect(0, 0, frame.width, 24), cv::Scalar(0, 0, 0), cv::FILLED);
  cv::putText(img, line, cv::Point(6, 17), cv::FONT_HERSHEY_SIMPLEX, 0.55, cv::Scalar(255, 255, 255), 1);
  return img;
}

void banner(cv::Mat& img, const ts::ScenarioResult& r) {
  // A failed system has no verdict and no DTL: the banner says so in grey.
  const bool failed = r.status == ts::Violation::SystemFailed;
  const std::string text = failed          ? "SYSTEM FAILED (no verdict)"
                           : r.violation() ? "VIOLATION Type " + std::string(ts::to_string(r.status)) + "  DTL " +
                                                 format_fixed(r.dtl, 2) + " m"
                                           : "LANDED (no violation)  DTL " + format_fixed(r.dtl, 2) + " m";
  const cv::Scalar colour = failed          ? cv::Scalar(90, 90, 90)
                            : r.violation() ? cv::Scalar(0, 0, 200)
                                            : cv::Scalar(0, 140, 0);
  cv::rectangle(img, cv::Rect(0, img.rows - 40, img.cols, 40), colour, cv::FILLED);
  cv::putText(img, text, cv::Point(8, img.rows - 13), cv::FONT_HERSHEY_SIMPLEX, 0.7, cv::Scalar(255, 255, 255), 2);
}

using Video = td::app::VideoFile;

// ---- run: one scenario ----------------------------------------------------------------

/// The --detector option of run and campaign.
struct RunArgs {
  std::string scenario_path, system = "opencv-mls", video_path, log_path, snapshot_path, weights_path;
  std::string detector = "aruco";
  bool json = false;
  double snapshot_t = -1;
  ts::RunOptions options;
};

CLI::App* add_run_command(CLI::App& app, RunArgs& a) {
  auto* cmd = app.add_subcommand("run", "run a landing system in a scenario");
  cmd->add_option("SCENARIO", a.scenario_path, "scenario YAML or JSON (docs/formats.md)")->required();
  add_system_option(*cmd, a.system);
  add_detector_option(*cmd, a.detector);
  cmd->add_option("--video", a.video_path, "write the camera view with detections and the outcome (.mp4 or .avi)")
      ->check([](const std::string& p) {
        const auto ext = fs::path(p).extension();
        return ext == ".mp4" || ext == ".avi" ? std::string() : "must end in .mp4 or .avi, got '" + p + "'";
      });
  cmd->add_option("--log", a.log_path, "per-step CSV: trajectory, phase, eq. 5 marker areas, detections")
      ->check(output_extension(".csv"));
  auto* snapshot_opt =
      cmd->add_option("--snapshot", a.snapshot_path, "write the overlaid camera frame at --snapshot-t as PNG")
          ->check(output_extension(".png"));
  cmd->add_option("--snapshot-t", a.snapshot_t, "time of the snapshot [s] (default: the last frame)")
      ->check(number_in(0, 3600))
      ->needs(snapshot_opt);
  cmd->add_option("--weights", a.weights_path,
                  "drive the scenario's `external` dynamic objects with this DQN, as a landing_fuzz rlaga campaign "
                  "did (its results directory's dqn_weights.txt); without it they stay")
      ->check(td::app::existing_file());
  cmd->add_flag("--json", a.json, "one JSON object on stdout");
  ts::CameraOptions& camera = a.options.camera;
  cmd->add_option("--width", camera.width, "camera image width [px]")
      ->check(number_in(16, 4096))
      ->capture_default_str();
  cmd->add_option("--height", camera.height, "camera image height [px]")
      ->check(number_in(16, 4096))
      ->capture_default_str();
  cmd->add_option("--hfov", camera.hfov_deg, "horizontal field of view [deg]")
      ->check(number_in(10, 170, true, true))
      ->capture_default_str();
  cmd->add_option("--tilt", camera.tilt_deg, "camera tilt forward from nadir [deg]")
      ->check(number_in(0, 80))
      ->check(td::app::degrees_not_radians("--tilt"))
      ->capture_default_str();
  cmd->add_option("--camera-rate", camera.rate_hz, "frames per second")
      ->check(number_in(0, 50, true))
      ->capture_default_str();
  return cmd;
}

/// The overlaid frames of a run: every one to the video, the one nearest
/// --snapshot-t kept for the snapshot, the last one for the outcome banner.
struct RunImages {
  td::StagedOutputs staged;  // --video, --snapshot, --log: checked before the run
  fs::path snapshot_tmp, log_tmp;
  std::optional<Video> video;
  cv::Mat last, snapshot;
  double best_dt = 1e9;
};

/// A --snapshot-t within this of the end of the flight [s] is at the end:
/// half a physics step, as the flight ends on a step.
double end_tolerance(const RunArgs& a) { return 0.5 / a.options.flight.rate_hz; }

/// A --snapshot-t past the scenario's time limit can never be met: refused
/// before the run.
void check_snapshot_time(const RunArgs& a, const ts::Scenario& scenario) {
  if (a.snapshot_t > scenario.time_limit) {
    throw td::InvalidArgument("--snapshot-t " + td::detail::format_general(a.snapshot_t) +
                              ": after the time limit of " + a.scenario_path + " (" +
                              td::detail::format_general(scenario.time_limit) + " s)");
  }
}

/// Whether the snapshot shows the outcome banner: the outcome is known only
/// at the end of the flight, so a snapshot at the end (or by default, the
/// last frame) has it and a mid-flight one shows its time, altitude and
/// phase only. A time past the end is refused (known only after the run:
/// nothing has been written yet).
bool snapshot_shows_outcome(const RunArgs& a, const ts::ScenarioResult& r) {
  if (a.snapshot_t < 0) return true;
  if (a.snapshot_t > r.flight_s + end_tolerance(a)) {
    throw td::InvalidArgument("--snapshot-t " + td::detail::format_general(a.snapshot_t) +
                              ": after the end of the flight at " + format_fixed(r.flight_s, 2) +
                              " s (checked after the run; nothing was written)");
  }
  return a.snapshot_t >= r.flight_s - end_tolerance(a);
}

void write_images(const RunArgs& a, const ts::ScenarioResult& r, RunImages& images) {
  const bool snapshot_outcome = a.snapshot_path.empty() || snapshot_shows_outcome(a, r);
  // Only the frames after the outcome carry its banner: the held final ones.
  if (!images.last.empty()) banner(images.last, r);
  if (images.video) {
    // Hold the outcome on screen for a second.
    for (int i = 0; i < static_cast<int>(std::ceil(a.options.camera.rate_hz)); ++i) images.video->write(images.last);
    images.video->finish();
  }
  if (!a.snapshot_path.empty()) {
    const cv::Mat& img = snapshot_outcome || images.snapshot.empty() ? images.last : images.snapshot;
    std::vector<unsigned char> png;
    cv::imencode(".png", img, png);
    write_text(images.snapshot_tmp, std::string(png.begin(), png.end()), a.snapshot_path);
  }
}

int run_command(RunArgs& a) {
  const ts::Scenario scenario = ts::load_scenario(a.scenario_path);
  check_snapshot_time(a, scenario);
  ts::MlsOptions mls;
  mls.detector.kind = a.detector;
  auto sut = ts::make_landing_system(a.system, mls);
  if (!a.weights_path.empty()) {
    a.options.external = tsr::ObjectPolicy(std::make_shared<const tsr::QNetwork>(tsr::load_weights(a.weights_path)));
  }
  RunImages images;
  if (!a.video_path.empty()) {
    images.video.emplace(images.staged.add(a.video_path, "--video"), a.video_path, a.options.camera.rate_hz,
                         a.options.camera.width, a.options.camera.height);
  }
  images.snapshot_tmp = stage(images.staged, a.snapshot_path, "--snapshot");
  images.log_tmp = stage(images.staged, a.log_path, "--log");
  // Progress in camera frames of the time limit's worth (a landing ends it
  // early: the bar is then completed at the frames flown).
  ProgressBar bar("landing_scenario", "frames");
  const auto frames_max =
      static_cast<std::size_t>(std::max(1.0, std::ceil(scenario.time_limit * a.options.camera.rate_hz)));
  std::size_t frames = 0;
  a.options.on_frame = [&](const ts::CameraFrame& f, const ts::SystemOutput& out, const td::DroneState& s) {
    ++frames;
    bar.draw(std::min(frames, frames_max - 1), frames_max);
    if (!images.video && a.snapshot_path.empty()) return;
    images.last = overlay(f, out, s);
    if (images.video) images.video->write(images.last);
    if (!a.snapshot_path.empty() && a.snapshot_t >= 0 && std::abs(s.t - a.snapshot_t) < images.best_dt) {
      images.best_dt = std::abs(s.t - a.snapshot_t);
      images.snapshot = images.last.clone();
    }
  };
  ts::ScenarioResult r;
  try {
    r = ts::run_scenario(scenario, *sut, a.options);
  } catch (...) {
    bar.close();
    throw;
  }
  bar.draw(frames, frames);
  write_images(a, r, images);
  if (!a.log_path.empty())
    write_text(images.log_tmp, ts::trajectory_csv(r, 1.0 / a.options.flight.rate_hz), a.log_path);
  images.staged.commit();
  if (a.json) {
    std::cout << ts::result_json(r, a.scenario_path, sut->name()) << "\n";
  } else {
    std::cout << ts::run_summary(r, a.scenario_path, scenario.map, sut->name(), a.detector);
  }
  return kExitOk;
}

}  // namespace

namespace touchdown::app::scenario_app {

Subcommand add_run(CLI::App& app) { return make_subcommand<RunArgs>(app, add_run_command, run_command); }

}  // namespace touchdown::app::scenario_app
