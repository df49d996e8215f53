// landing_scenario: runs a landing system under test in a marker-landing
// scenario (docs/formats.md, "Landing scenarios") and reports the outcome
// with the RLaGA paper's violation types; or writes a random valid scenario.
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
#include "system_option.hpp"
#include "touchdown/core/atomic_file.hpp"
#include "touchdown/core/statistics.hpp"
#include "touchdown/scenario/campaign.hpp"
#include "touchdown/scenario/contract.hpp"
#include "touchdown/scenario/dataset.hpp"
#include "touchdown/scenario/detector_bench.hpp"
#include "touchdown/scenario/marker_detector.hpp"
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

Json vec_json(const Eigen::Ref<const Eigen::VectorXd>& v) {
  Json a = Json::array();
  for (Eigen::Index i = 0; i < v.size(); ++i) a.push_back(round3(v(i)));
  return a;
}

Json result_json(const std::string& scenario_path, std::string_view system, const ts::ScenarioResult& r) {
  Json j;
  j["scenario"] = scenario_path;
  j["system"] = system;
  j["violation"] = r.violation();
  j["type"] = ts::to_string(r.status);
  j["message"] = r.message;
  j["landed"] = r.landed;
  j["dtl"] = round3(r.dtl);
  j["ttl"] = round3(r.ttl);
  j["final_position"] = vec_json(r.final_position);
  if (r.collided) {
    j["collision"] = {
        {"t", round3(r.collision.t)}, {"object", r.collision.what}, {"point", vec_json(r.collision.point)}};
  }
  j["descent"] = {{"started", r.descent_started}};
  if (r.descent_started) {
    j["descent"]["t"] = round3(r.descent_time);
    j["descent"]["target"] = vec_json(r.descent_target);
  }
  j["false_detection"] = r.false_detection;
  const auto truth_json = [](const ts::DetectionTruth& d) {
    return Json{{"t", round3(d.t)},
                {"object", d.object},
                {"label", ts::to_string(d.label)},
                {"id", d.id},
                {"ground", vec_json(d.ground)}};
  };
  j["trigger"] = r.has_trigger ? truth_json(r.trigger) : Json(nullptr);
  j["last_accepted"] = r.has_last_accepted ? truth_json(r.last_accepted) : Json(nullptr);
  Json occluders = Json::array();
  for (const auto& o : r.occluders) {
    occluders.push_back({{"object", o.object},
                         {"first_t", round3(o.first_t)},
                         {"last_t", round3(o.last_t)},
                         {"frames", o.frames},
                         {"frames_descending", o.frames_descending}});
  }
  j["occluders"] = std::move(occluders);
  const ts::Observability& ob = r.observability;
  j["observability"] = ob.measured ? Json{{"sighting_time", round3(ob.sighting_time)},
                                          {"observable_s", round3(ob.observable_s)},
                                          {"longest_s", round3(ob.longest_s)},
                                          {"probe_observable_s", round3(ob.probe_observable_s)},
                                          {"probe_longest_s", round3(ob.probe_longest_s)},
                                          {"probe_failure", ts::to_string(ob.probe_failure)},
                                          {"probe_contrast", round3(ob.probe_contrast)},
                                          {"long_enough", ob.observable_long_enough()}}
                                   : Json(nullptr);
  Json frames = Json::array();
  for (const auto& f : r.frames) {
    frames.push_back({{"t", round3(f.t)},
                      {"marker_area_visible_px", f.marker_area_visible_px},
                      {"marker_area_truth_px", round3(f.marker_area_truth_px)},
                      {"detections", f.detections},
                      {"accepted", f.accepted},
                      {"false_accepted", f.false_accepted},
                      {"sight", ts::to_string(f.view.sight)},
                      {"contrast", round3(f.view.contrast)}});
  }
  j["frames"] = std::move(frames);
  j["timing"] = {{"render_s", round3(r.timing.render_s)},
                 {"system_s", round3(r.timing.system_s)},
                 {"physics_s", round3(r.timing.physics_s)},
                 {"oracle_s", round3(r.timing.oracle_s)},
                 {"total_s", round3(r.timing.total_s)}};
  return j;
}

std::string log_csv(const ts::ScenarioResult& r, double dt) {
  std::ostringstream os;
  os << "t,x,y,z,vx,vy,vz,yaw_deg,phase,marker_area_visible_px,marker_area_truth_px,detections,accepted,false_"
        "accepted\n";
  std::size_t f = 0;
  for (const auto& s : r.trajectory) {
    os << format_fixed(s.t, 3) << ',' << format_fixed(s.position.x(), 4) << ',' << format_fixed(s.position.y(), 4)
       << ',' << format_fixed(s.position.z(), 4) << ',' << format_fixed(s.velocity.x(), 4) << ','
       << format_fixed(s.velocity.y(), 4) << ',' << format_fixed(s.velocity.z(), 4) << ',' << format_fixed(s.yaw_deg, 3)
       << ',' << s.phase;
    // A frame is taken at the start of the step that ends at s.t.
    if (f < r.frames.size() && std::abs(r.frames[f].t + dt - s.t) < 0.5 * dt) {
      const auto& fr = r.frames[f++];
      os << ',' << fr.marker_area_visible_px << ',' << format_fixed(fr.marker_area_truth_px, 1) << ',' << fr.detections
         << ',' << fr.accepted << ',' << fr.false_accepted;
    } else {
      os << ",,,,,";
    }
    os << '\n';
  }
  return os.str();
}

/// The camera view with the system's detections, phase and state drawn on.
cv::Mat overlay(const ts::CameraFrame& frame, const ts::SystemOutput& out, const ts::DroneState& s) {
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
  const std::string text =
      r.violation() ? "VIOLATION Type " + std::string(ts::to_string(r.status)) : "LANDED (no violation)";
  const cv::Scalar colour = r.violation() ? cv::Scalar(0, 0, 200) : cv::Scalar(0, 140, 0);
  cv::rectangle(img, cv::Rect(0, img.rows - 40, img.cols, 40), colour, cv::FILLED);
  cv::putText(img, text + "  DTL " + format_fixed(r.dtl, 2) + " m", cv::Point(8, img.rows - 13),
              cv::FONT_HERSHEY_SIMPLEX, 0.7, cv::Scalar(255, 255, 255), 2);
}

using Video = td::app::VideoFile;

std::string percent(int n, int of) { return format_fixed(of > 0 ? 100.0 * n / of : 0.0, 1) + " %"; }

std::string campaign_csv(const ts::CampaignResult& c, const std::vector<std::string>& names) {
  std::ostringstream os;
  os << "scenario,map,violation,type,landed,dtl,ttl,false_detection,flight_s,frames,wall_s,render_s,system_s,"
        "message\n";
  for (std::size_t i = 0; i < c.entries.size(); ++i) {
    const ts::ScenarioOutcome& e = c.entries[i].outcome;
    std::string msg = e.message;
    for (char& ch : msg)
      if (ch == '"') ch = '\'';
    os << names[i] << ',' << ts::to_string(c.entries[i].map) << ',' << (e.violation() ? 1 : 0) << ','
       << ts::to_string(e.status) << ',' << (e.landed ? 1 : 0) << ',' << format_fixed(e.dtl, 3) << ','
       << format_fixed(e.ttl, 2) << ',' << (e.false_detection ? 1 : 0) << ',' << format_fixed(e.flight_s, 2) << ','
       << e.frame_count << ',' << format_fixed(e.timing.total_s, 3) << ',' << format_fixed(e.timing.render_s, 3) << ','
       << format_fixed(e.timing.system_s, 3) << ",\"" << msg << "\"\n";
  }
  return os.str();
}

Json campaign_json(const ts::CampaignResult& c, const std::string& source, const ts::CampaignOptions& o) {
  const auto& s = c.summary;
  Json j;
  j["scenarios"] = source;
  j["system"] = o.system.name();
  j["detection_roi"] = o.mls.detector.roi;
  j["threads"] = td::resolve_threads(o.threads);
  j["count"] = s.scenarios;
  j["violations"] = s.violations;
  j["violation_rate"] = round3(s.violation_rate());
  j["type_i"] = s.type_i;
  j["type_ii"] = s.type_ii;
  j["type_iii"] = s.type_iii;
  j["off_marker"] = s.off_marker;
  j["unfair_type_ii"] = s.unfair_type_ii;
  j["system_failed"] = s.system_failed;
  j["flight_s"] = round3(s.flight_s);
  j["wall_s"] = round3(s.wall_s);
  j["timing"] = {{"render_s", round3(s.timing.render_s)},
                 {"system_s", round3(s.timing.system_s)},
                 {"physics_s", round3(s.timing.physics_s)},
                 {"oracle_s", round3(s.timing.oracle_s)},
                 {"total_s", round3(s.timing.total_s)}};
  return j;
}

void print_campaign(const ts::CampaignResult& c, const std::string& source, const ts::CampaignOptions& o) {
  const auto& s = c.summary;
  std::vector<double> dtl, ttl;
  for (const auto& e : c.entries) {
    if (!e.outcome.landed) continue;
    dtl.push_back(e.outcome.dtl);
    ttl.push_back(e.outcome.ttl);
  }
  const double other =
      s.timing.total_s - s.timing.render_s - s.timing.system_s - s.timing.physics_s - s.timing.oracle_s;
  const auto share = [&](double v) {
    return format_fixed(s.timing.total_s > 0 ? 100 * v / s.timing.total_s : 0.0, 0) + " %";
  };
  std::cout << "campaign   " << s.scenarios << " scenarios: " << source << "\n"
            << "system     " << o.system.name()
            << (o.mls.detector.kind != "aruco" && o.system != "learned-mls" ? " (" + o.mls.detector.kind + " detector)"
                                                                            : "")
            << (o.mls.detector.roi ? "" : " (whole-frame detection)") << "\n"
            << "violations " << s.violations << "/" << s.scenarios << " (" << percent(s.violations, s.scenarios)
            << "): type I " << s.type_i << " (" << percent(s.type_i, s.scenarios) << "), type II " << s.type_ii << " ("
            << percent(s.type_ii, s.scenarios) << "; " << s.unfair_type_ii << " unfair), type III " << s.type_iii
            << " (" << percent(s.type_iii, s.scenarios) << "), off-marker " << s.off_marker << "\n";
  if (s.system_failed > 0) {
    const auto first = std::find_if(c.entries.begin(), c.entries.end(), [](const ts::CampaignEntry& e) {
      return e.outcome.status == ts::Violation::SystemFailed;
    });
    std::cout << "failed     " << s.system_failed << " runs: the system under test failed (first, scenario "
              << (first - c.entries.begin()) << ": " << first->outcome.failure << ")\n";
  }
  std::cout << "landed     " << dtl.size() << ": median DTL " << format_fixed(td::median(dtl), 2) << " m, median TTL "
            << format_fixed(td::median(ttl), 1) << " s\n"
            << "time       " << format_fixed(s.wall_s, 1) << " s wall on " << td::resolve_threads(o.threads)
            << " threads for " << format_fixed(s.flight_s, 0) << " s of flight ("
            << format_fixed(s.wall_s > 0 ? s.flight_s / s.wall_s : 0.0, 0) << "x real time); per scenario "
            << format_fixed(s.scenarios > 0 ? s.timing.total_s / s.scenarios : 0.0, 2) << " s: render "
            << share(s.timing.render_s) << ", system " << share(s.timing.system_s) << ", physics "
            << share(s.timing.physics_s) << ", oracle " << share(s.timing.oracle_s) << ", other " << share(other)
            << "\n";
}

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

void print_run(const RunArgs& a, const ts::Scenario& scenario, std::string_view system, const ts::ScenarioResult& r) {
  std::cout << "scenario   " << a.scenario_path << " (" << ts::to_string(scenario.map) << ")\n"
            << "system     " << system
            << (a.detector != "aruco" && system != "learned-mls" ? " (" + a.detector + " detector)" : "") << "\n"
            << "outcome    " << (r.violation() ? "VIOLATION" : "ok") << ": " << r.message << "\n"
            << "DTL        " << format_fixed(r.dtl, 2) << " m   TTL " << format_fixed(r.ttl, 1) << " s\n"
            << "frames     " << r.frames.size() << "   steps " << r.trajectory.size() << "\n";
  const ts::Observability& o = r.observability;
  if (o.measured) {
    std::cout << "target     observable " << format_fixed(o.observable_s, 1) << " s (longest "
              << format_fixed(o.longest_s, 1) << " s) in its camera, " << format_fixed(o.probe_observable_s, 1)
              << " s (longest " << format_fixed(o.probe_longest_s, 1) << " s) from the probe above it\n";
  }
  std::cout << "time       " << format_fixed(r.timing.total_s, 3) << " s (render " << format_fixed(r.timing.render_s, 3)
            << ", system " << format_fixed(r.timing.system_s, 3) << ", physics " << format_fixed(r.timing.physics_s, 3)
            << ", oracle " << format_fixed(r.timing.oracle_s, 3) << ")\n";
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
  a.options.on_frame = [&](const ts::CameraFrame& f, const ts::SystemOutput& out, const ts::DroneState& s) {
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
  if (!a.log_path.empty()) write_text(images.log_tmp, log_csv(r, 1.0 / a.options.flight.rate_hz), a.log_path);
  images.staged.commit();
  if (a.json) {
    std::cout << result_json(a.scenario_path, sut->name(), r).dump() << "\n";
  } else {
    print_run(a, scenario, sut->name(), r);
  }
  return kExitOk;
}

// ---- random: write a random scenario ----------------------------------------------------

/// "DICT:ID" → dictionary and id (checked by DatasetOptions::validate).
void parse_marker(const std::string& text, const std::string& option, std::string* dictionary, int* id) {
  const auto colon = text.find(':');
  std::size_t used = 0;
  try {
    if (colon == std::string::npos) throw std::invalid_argument("");
    *id = std::stoi(text.substr(colon + 1), &used);
  } catch (const std::exception&) {
    used = 0;
  }
  if (colon == std::string::npos || used == 0 || colon + 1 + used != text.size())
    throw td::InvalidArgument(option + " " + text + ": expected DICTIONARY:ID, e.g. 4X4_50:0");
  *dictionary = text.substr(0, colon);
}

// The --map name that leaves the map to the random draw.
const std::string kAnyMap = "any";

struct RandomArgs {
  std::uint64_t seed = 1;
  std::string out_path;
  std::optional<ts::MapKind> map;  // empty: any
};

CLI::App* add_random_command(CLI::App& app, RandomArgs& a) {
  auto* cmd = app.add_subcommand("random", "write a random valid scenario drawn from the bounds table");
  add_seed_option(*cmd, "--seed", a.seed, "random seed");
  add_enum_option(*cmd, "--map", a.map, kAnyMap, td::enum_names_list<ts::MapKind>() + " or " + kAnyMap);
  cmd->add_option("-o,--output", a.out_path, "scenario file to write (.yaml or .json)")
      ->required()
      ->check([](const std::string& p) {
        const auto ext = fs::path(p).extension();
        return ext == ".yaml" || ext == ".yml" || ext == ".json" ? std::string()
                                                                 : "must end in .yaml, .yml or .json, got '" + p + "'";
      });
  return cmd;
}

int random_command(const RandomArgs& a) {
  td::StagedOutputs staged;
  const fs::path tmp = staged.add(a.out_path, "--output");
  const ts::Scenario s = a.map ? ts::random_scenario(a.seed, *a.map) : ts::random_scenario(a.seed);
  const bool as_json = fs::path(a.out_path).extension() == ".json";
  write_text(tmp, as_json ? ts::to_json(s) : ts::to_yaml(s), a.out_path);
  staged.commit();
  std::cerr << "landing_scenario: wrote " << a.out_path << " (" << ts::to_string(s.map) << ", "
            << s.static_objects.size() << " static, "
            << count_noun(static_cast<long long>(s.dynamic_objects.size()), "moving object") << ", "
            << count_noun(static_cast<long long>(s.distractors.size()), "distractor") << ")\n";
  return kExitOk;
}

// ---- campaign: many scenarios ----------------------------------------------------------

struct CampaignArgs {
  std::vector<std::string> files;
  std::uint64_t first_seed = 1;
  int count = 100;
  std::optional<ts::MapKind> map;  // empty: any
  std::string csv_path, weights_path, marker;
  std::string system = "opencv-mls";
  bool json = false, whole_frame = false;
  ts::CampaignOptions campaign;
};

CLI::App* add_campaign_command(CLI::App& app, CampaignArgs& a) {
  auto* cmd = app.add_subcommand(
      "campaign",
      "run many scenarios (random ones by seed, or the given files) in parallel; violation rate and type mix");
  a.campaign.threads = std::max(1, static_cast<int>(std::thread::hardware_concurrency()));
  auto* files_opt = cmd->add_option("SCENARIO", a.files, "scenario files (default: random ones)");
  add_seed_option(*cmd, "--seed", a.first_seed, "seed of the first random scenario")->excludes(files_opt);
  cmd->add_option("--count", a.count, "random scenarios")
      ->check(CLI::Range(1, 100000))
      ->capture_default_str()
      ->excludes(files_opt);
  add_enum_option(*cmd, "--map", a.map, kAnyMap,
                  "map of the random scenarios: " + td::enum_names_list<ts::MapKind>() + " or " + kAnyMap)
      ->excludes(files_opt);
  add_system_option(*cmd, a.system);
  add_detector_option(*cmd, a.campaign.mls.detector.kind);
  cmd->add_option("--marker", a.marker,
                  "the target of the random scenarios, DICTIONARY:ID (default: drawn; a learned detector needs "
                  "its model's marker)")
      ->excludes(files_opt);
  cmd->add_option("--threads", a.campaign.threads, "worker threads (0 = every core)")
      ->check(CLI::NonNegativeNumber)
      ->capture_default_str();
  cmd->add_flag("--whole-frame-detection", a.whole_frame,
                "detect in the whole frame every time (no tracking ROI), as the published baseline");
  cmd->add_option("--weights", a.weights_path,
                  "drive every scenario's `external` dynamic objects with this DQN, as the landing_fuzz rlaga "
                  "campaign that wrote the files did (its dqn_weights.txt); without it they stay")
      ->check(td::app::existing_file());
  cmd->add_option("--csv", a.csv_path, "one row per scenario")->check(output_extension(".csv"));
  cmd->add_flag("--json", a.json, "the summary as one JSON object on stdout");
  return cmd;
}

int campaign_command(CampaignArgs& a) {
  td::StagedOutputs staged;
  const fs::path csv_tmp = stage(staged, a.csv_path, "--csv");
  std::vector<ts::Scenario> scenarios;
  std::vector<std::string> names;
  std::string source;
  if (!a.files.empty()) {
    for (const auto& f : a.files) {
      scenarios.push_back(ts::load_scenario(f));
      names.push_back(f);
    }
    source = count_noun(static_cast<long long>(a.files.size()), "file");
  } else {
    if (a.first_seed > std::numeric_limits<std::uint64_t>::max() - static_cast<std::uint64_t>(a.count - 1)) {
      throw td::InvalidArgument("--seed " + std::to_string(a.first_seed) + " with --count " + std::to_string(a.count) +
                                ": the seeds would pass 18446744073709551615 (2^64 - 1)");
    }
    scenarios = ts::random_scenarios(a.first_seed, a.count, a.map);
    if (!a.marker.empty()) {
      std::string dictionary;
      int id = 0;
      parse_marker(a.marker, "--marker", &dictionary, &id);
      for (ts::Scenario& s : scenarios) ts::set_target(s, dictionary, id);
    }
    for (int i = 0; i < a.count; ++i)
      names.push_back("seed " + std::to_string(a.first_seed + static_cast<std::uint64_t>(i)));
    source = "random, seeds " + std::to_string(a.first_seed) + ".." +
             std::to_string(a.first_seed + static_cast<std::uint64_t>(a.count) - 1) + ", map " +
             (a.map ? std::string(ts::to_string(*a.map)) : kAnyMap);
  }
  a.campaign.mls.detector.roi = !a.whole_frame;
  a.campaign.system = a.system;
  if (!a.weights_path.empty()) {
    // One network, shared read-only; one ObjectPolicy per run (it keeps the
    // run's held action), as the search's LocalEvaluator does.
    auto network = std::make_shared<const tsr::QNetwork>(tsr::load_weights(a.weights_path));
    a.campaign.external_for = [network](std::size_t) {
      return std::function<void(const ts::World&, std::vector<ts::ObjectAction>&)>(tsr::ObjectPolicy(network));
    };
  }
  // The campaign's threads are the parallelism: OpenCV's own would
  // oversubscribe the cores.
  cv::setNumThreads(1);
  // A bar with the time left (lines off a terminal), from the scenarios
  // finished (the library calls this one scenario at a time).
  ProgressBar bar("landing_scenario", "scenarios");
  bar.draw(0, scenarios.size());
  a.campaign.progress = [&bar](const td::Progress& p) { bar.draw(p.done, p.total); };
  ts::CampaignResult c;
  try {
    c = ts::run_campaign(scenarios, a.campaign);
  } catch (...) {
    bar.close();
    throw;
  }
  if (!a.csv_path.empty()) write_text(csv_tmp, campaign_csv(c, names), a.csv_path);
  staged.commit();
  if (a.json) {
    std::cout << campaign_json(c, source, a.campaign).dump() << "\n";
  } else {
    print_campaign(c, source, a.campaign);
  }
  return kExitOk;
}

// ---- dataset: detector training and test frames -----------------------------------------

struct DatasetArgs {
  std::string out;
  int count = 1000;
  std::string marker = "4X4_50:0";
  int threads = 1;
  ts::DatasetOptions options;
};

CLI::App* add_dataset_command(CLI::App& app, DatasetArgs& a) {
  auto* cmd = app.add_subcommand(
      "dataset",
      "render labelled frames for training and testing marker detectors (docs/formats.md, Detector dataset)");
  a.threads = std::max(1, static_cast<int>(std::thread::hardware_concurrency()));
  cmd->add_option("--out", a.out, "directory to create (must not exist): images/ and labels.jsonl")->required();
  cmd->add_option("--count", a.count, "frames")->check(CLI::Range(1, 10000000))->capture_default_str();
  add_seed_option(*cmd, "--seed", a.options.seed, "dataset seed (frame i is drawn from (seed, i))");
  cmd->add_option("--marker", a.marker, "the target marker, DICTIONARY:ID")->capture_default_str();
  cmd->add_option("--max-tilt", a.options.max_tilt_deg, "largest camera tilt drawn [deg]")
      ->check(td::app::degrees_not_radians("--max-tilt"))
      ->capture_default_str();
  cmd->add_option("--threads", a.threads, "worker threads (0 = every core)")
      ->check(CLI::NonNegativeNumber)
      ->capture_default_str();
  return cmd;
}

Json quad_json(const ts::QuadLabel& q) {
  Json j;
  j["in_view"] = q.in_view();
  Json corners = Json::array();
  if (q.in_front) {
    for (const Eigen::Vector2d& c : q.corners) corners.push_back({round3(c.x()), round3(c.y())});
  }
  j["corners"] = corners;
  j["box"] = {round3(q.box_min.x()), round3(q.box_min.y()), round3(q.box_max.x()), round3(q.box_max.y())};
  j["inside_fraction"] = round3(q.inside_fraction);
  j["visible_fraction"] = round3(q.visible_fraction);
  return j;
}

Json dataset_frame_json(const ts::DatasetFrame& f, const std::string& image) {
  Json j;
  j["image"] = image;
  j["index"] = f.index;
  j["split"] = td::enum_name(f.split);
  j["scenario_seed"] = f.scenario_seed;
  j["map"] = ts::to_string(f.scenario.map);
  j["weather"] = f.weather;
  const ts::Weather& w = f.scenario.weather;
  j["conditions"] = {{"fog", round3(w.fog)},
                     {"rain", round3(w.rain)},
                     {"snow", round3(w.snow)},
                     {"dust", round3(w.dust)},
                     {"leaves", round3(w.leaves)},
                     {"ground_wetness", round3(w.ground_wetness)},
                     {"ground_snow", round3(w.ground_snow)},
                     {"ground_leaves", round3(w.ground_leaves)},
                     {"ambient", round3(w.ambient)},
                     {"sun_elevation_deg", round3(w.sun_elevation_deg)}};
  j["phase"] = f.phase;
  const Eigen::Vector3d c = f.T_world_camera.translation();
  j["camera"] = {{"position", {round3(c.x()), round3(c.y()), round3(c.z())}},
                 {"tilt_deg", round3(f.camera.tilt_deg)},
                 {"hfov_deg", f.camera.hfov_deg},
                 {"width", f.camera.width},
                 {"height", f.camera.height}};
  j["distance"] = round3(f.distance);
  Json t = quad_json(f.target);
  t["sight"] = ts::to_string(f.view.sight);
  t["side_px"] = round3(f.view.side_px);
  t["contrast"] = round3(f.view.contrast);
  j["target"] = t;
  Json d = Json::array();
  for (const ts::DistractorLabel& x : f.distractors) {
    Json q = quad_json(x.quad);
    q["kind"] = ts::to_string(x.kind);
    d.push_back(q);
  }
  j["distractors"] = d;
  j["occluder"] = f.occluder;
  return j;
}

int dataset_command(DatasetArgs& a) {
  parse_marker(a.marker, "--marker", &a.options.dictionary, &a.options.marker_id);
  std::string why;
  if (!a.options.validate(&why)) throw td::InvalidArgument("--marker/--max-tilt: " + why);
  const fs::path out(a.out);
  if (fs::exists(out)) throw td::IoError("--out " + a.out + ": exists (a dataset goes into a new directory)");
  require_parent_directory(a.out, "--out");
  // Written beside it, renamed when complete: a failed or interrupted run
  // leaves no dataset.
  td::StagedDirectory staged(fs::absolute(out));
  const fs::path tmp = staged.path();
  fs::create_directories(tmp / "images");
  cv::setNumThreads(1);
  std::vector<std::string> lines(static_cast<std::size_t>(a.count));
  std::array<int, 3> splits{};
  std::vector<ts::DatasetSplit> split_of(static_cast<std::size_t>(a.count));
  ProgressBar bar("landing_scenario", "frames");
  td::BatchOptions batch;
  batch.threads = a.threads;
  batch.progress = [&bar](const td::Progress& p) { bar.draw(p.done, p.total); };
  td::run_batch(static_cast<std::size_t>(a.count), batch, [&](std::size_t i, std::size_t) {
    const ts::DatasetFrame f = ts::render_dataset_frame(a.options, static_cast<int>(i));
    char name[32];
    std::snprintf(name, sizeof name, "images/%06zu.png", i);
    const cv::Mat bgr(f.frame.height, f.frame.width, CV_8UC3, const_cast<std::uint8_t*>(f.frame.image.pixels.data()));
    cv::Mat gray;
    cv::cvtColor(bgr, gray, cv::COLOR_BGR2GRAY);
    if (!cv::imwrite((tmp / name).string(), gray, {cv::IMWRITE_PNG_COMPRESSION, 1}))
      throw td::IoError("--out " + a.out + ": cannot write " + name);
    lines[i] = dataset_frame_json(f, name).dump();
    split_of[i] = f.split;
  });
  bar.close();
  for (const ts::DatasetSplit s : split_of) ++splits[static_cast<std::size_t>(s)];
  std::string text;
  for (const std::string& l : lines) text += l + "\n";
  write_text(tmp / "labels.jsonl", text, a.out + "/labels.jsonl");
  Json meta;
  meta["format"] = "touchdown-dataset/1";
  meta["seed"] = a.options.seed;
  meta["count"] = a.count;
  meta["marker"] = {{"dictionary", a.options.dictionary}, {"id", a.options.marker_id}};
  meta["camera"] = {{"width", a.options.camera.width},
                    {"height", a.options.camera.height},
                    {"hfov_deg", a.options.camera.hfov_deg},
                    {"max_tilt_deg", a.options.max_tilt_deg}};
  meta["splits"] = {{"train", splits[0]}, {"validation", splits[1]}, {"test", splits[2]}};
  meta["images"] = "8-bit grey PNG, the systems' BGR frame converted as cv::cvtColor(COLOR_BGR2GRAY)";
  write_text(tmp / "dataset.json", meta.dump(2) + "\n", a.out + "/dataset.json");
  staged.commit();
  std::cout << "dataset " << a.out << ": " << a.count << " frames (train " << splits[0] << ", validation " << splits[1]
            << ", test " << splits[2] << "), marker " << a.options.dictionary << " id " << a.options.marker_id
            << ", seed " << a.options.seed << "\n";
  return kExitOk;
}

// ---- detect: a detector on image files -----------------------------------------------------

struct DetectArgs {
  std::vector<std::string> images;
  std::string marker = "4X4_50:0";
  bool json = false;
  ts::DetectorOptions detector;
};

CLI::App* add_detect_command(CLI::App& app, DetectArgs& a) {
  auto* cmd = app.add_subcommand("detect", "run a marker detector on image files (any size; PNG, JPEG, ...)");
  cmd->add_option("IMAGE", a.images, "image files")->required()->check(td::app::existing_file());
  cmd->add_option("--detector", a.detector.kind, "the marker detector")
      ->check(one_of_names(ts::marker_detector_names()))
      ->capture_default_str();
  cmd->add_option("--model", a.detector.model,
                  "the learned detector's ONNX model (default: data/models/, TOUCHDOWN_MODEL)");
  cmd->add_option("--marker", a.marker, "the marker looked for, DICTIONARY:ID (aruco reports every id of it)")
      ->capture_default_str();
  cmd->add_option("--min-confidence", a.detector.min_confidence, "learned: report detections from this confidence")
      ->check(number_in(0, 1))
      ->capture_default_str();
  cmd->add_flag("--json", a.json, "one JSON object per image on stdout (JSON Lines)");
  return cmd;
}

int detect_command(DetectArgs& a) {
  std::string dictionary;
  int id = 0;
  parse_marker(a.marker, "--marker", &dictionary, &id);
  a.detector.roi = false;  // separate images: nothing to track
  cv::setNumThreads(1);
  auto detector = ts::make_marker_detector(a.detector);
  detector->reset(dictionary, id);
  // Every image is read before any is reported: a bad file is one error, no partial output.
  std::vector<cv::Mat> bgr;
  for (const std::string& path : a.images) {
    cv::Mat im = cv::imread(path, cv::IMREAD_COLOR);
    if (im.empty()) throw td::IoError(path + ": not an image OpenCV can read");
    bgr.push_back(im);
  }
  std::vector<ts::MarkerDetection> found;
  for (std::size_t i = 0; i < bgr.size(); ++i) {
    cv::Mat gray;
    cv::cvtColor(bgr[i], gray, cv::COLOR_BGR2GRAY);
    const ts::DetectorFrame frame{{bgr[i].data, bgr[i].cols, bgr[i].rows, static_cast<std::ptrdiff_t>(bgr[i].step)},
                                  {gray.data, gray.cols, gray.rows, static_cast<std::ptrdiff_t>(gray.step)}};
    const auto t0 = std::chrono::steady_clock::now();
    detector->detect(frame, found);
    const double ms = std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - t0).count();
    if (a.json) {
      Json j;
      j["image"] = a.images[i];
      j["width"] = bgr[i].cols;
      j["height"] = bgr[i].rows;
      j["detector"] = detector->name();
      j["ms"] = round3(ms);
      Json list = Json::array();
      for (const ts::MarkerDetection& d : found) {
        Json x;
        x["id"] = d.id;
        x["confidence"] = round3(d.confidence);
        x["box"] = {round3(d.box_min.x()), round3(d.box_min.y()), round3(d.box_max.x()), round3(d.box_max.y())};
        if (d.has_corners) {
          Json c = Json::array();
          for (const Eigen::Vector2d& p : d.corners) c.push_back({round3(p.x()), round3(p.y())});
          x["corners"] = c;
          x["oriented"] = d.oriented;
        }
        list.push_back(x);
      }
      j["detections"] = list;
      std::cout << j.dump() << "\n";
      continue;
    }
    std::cout << a.images[i] << " (" << bgr[i].cols << "x" << bgr[i].rows << ", " << detector->name() << ", "
              << format_fixed(ms, 1) << " ms): " << count_noun(static_cast<long long>(found.size()), "detection")
              << "\n";
    for (const ts::MarkerDetection& d : found) {
      std::cout << "  id " << d.id << "  confidence " << format_fixed(d.confidence, 2) << "  box ["
                << format_fixed(d.box_min.x(), 1) << ", " << format_fixed(d.box_min.y(), 1) << "] - ["
                << format_fixed(d.box_max.x(), 1) << ", " << format_fixed(d.box_max.y(), 1) << "]";
      if (d.has_corners) {
        std::cout << "  corners";
        for (const Eigen::Vector2d& p : d.corners)
          std::cout << " (" << format_fixed(p.x(), 1) << ", " << format_fixed(p.y(), 1) << ")";
      }
      std::cout << "\n";
    }
  }
  return kExitOk;
}

// ---- detect-bench: detectors on a labelled dataset --------------------------------------

struct BenchArgs {
  std::string dataset, split = "all", plot_path, detectors = "aruco,learned";
  double threshold = 0.7;
  int limit = 0;
  bool json = false;
  std::string model;
};

CLI::App* add_bench_command(CLI::App& app, BenchArgs& a) {
  auto* cmd = app.add_subcommand(
      "detect-bench", "precision, recall, AP@0.5 and time of marker detectors on a dataset (landing_scenario dataset)");
  cmd->add_option("DATASET", a.dataset, "a dataset directory (dataset.json, labels.jsonl, images/)")
      ->required()
      ->check(td::app::existing_directory());
  cmd->add_option("--detectors", a.detectors, "comma-separated: aruco, learned")->capture_default_str();
  cmd->add_option("--model", a.model, "the learned detector's model (default: data/models/, TOUCHDOWN_MODEL)");
  cmd->add_option("--split", a.split, "frames of this split only: train, validation, test or all")
      ->check(CLI::IsMember({"all", "train", "validation", "test"}))
      ->capture_default_str();
  cmd->add_option("--threshold", a.threshold,
                  "confidence from which a detection counts (recall, precision, false "
                  "positives; AP uses every confidence)")
      ->check(number_in(0, 1))
      ->capture_default_str();
  cmd->add_option("--limit", a.limit, "the first N frames only (0: all)")->check(CLI::Range(0, 10000000));
  cmd->add_option("--plot", a.plot_path, "recall against distance, a panel per weather kind, a line per detector (SVG)")
      ->check(output_extension(".svg"));
  cmd->add_flag("--json", a.json, "the figures as one JSON object");
  return cmd;
}

/// Recall against the distance band, one panel per weather kind (small
/// multiples: 20 lines in one frame could not be read), one line per
/// detector; a band's point needs at least 10 targets.
std::string bench_plot(const std::vector<std::string>& names, const std::vector<std::vector<ts::BenchFrame>>& runs,
                       const std::vector<ts::BenchLabel>& labels, double threshold, const std::string& title) {
  const std::vector<std::string>& bands = ts::distance_bands();
  std::vector<std::string> weathers;
  for (const auto& l : labels) {
    if (std::find(weathers.begin(), weathers.end(), l.weather) == weathers.end()) weathers.push_back(l.weather);
  }
  std::sort(weathers.begin(), weathers.end());
  const auto& colours = td::detail::palette::kSeries;
  const int columns = 5, rows = std::max(1, static_cast<int>((weathers.size() + columns - 1) / columns));
  const double panel_w = 150, panel_h = 130, gap_x = 42, gap_y = 58, left = 62, top = 70;
  td::detail::SvgWriter svg(static_cast<int>(left + columns * (panel_w + gap_x) + 10),
                            static_cast<int>(top + rows * (panel_h + gap_y) + 10));
  svg.title(title);
  // The legend above the panels: one swatch per detector.
  for (std::size_t d = 0; d < names.size(); ++d) {
    const double lx = left + 170.0 * static_cast<double>(d);
    const std::string style = std::string(" fill='none' stroke='") + colours[d % colours.size()] +
                              "' stroke-width='2'" + (d == 0 ? "" : " stroke-dasharray='6 3'");
    svg.line(lx, 42, lx + 24, 42, style);
    svg.text(lx + 30, 46, names[d]);
  }
  for (std::size_t w = 0; w < weathers.size(); ++w) {
    const int col = static_cast<int>(w) % columns, row = static_cast<int>(w) / columns;
    td::detail::PlotAxis x;
    x.lo = -0.4;
    x.hi = static_cast<double>(bands.size()) - 0.6;
    x.grid = false;
    td::detail::PlotAxis y = td::detail::fit_axis(0, 1, 4, col == 0 ? "recall at " + format_fixed(threshold, 2) : "");
    const double px0 = left + col * (panel_w + gap_x), py0 = top + row * (panel_h + gap_y);
    const td::detail::PlotFrame f{px0, py0, px0 + panel_w, py0 + panel_h, x, y};
    svg.axes(f);
    svg.text(px0 + panel_w / 2, py0 - 6, weathers[w], " text-anchor='middle' font-weight='bold'");
    for (std::size_t b = 0; b < bands.size(); ++b) {
      std::string band = bands[b];  // "3-6 m" -> "3-6": the unit goes to the axis title
      if (band.size() > 2 && band.ends_with(" m")) band.resize(band.size() - 2);
      svg.text(f.px(static_cast<double>(b)), f.bottom + 14, band, " text-anchor='middle' font-size='10'");
    }
    if (row == rows - 1 || w + columns >= weathers.size())
      svg.text(px0 + panel_w / 2, f.bottom + 30, "camera to marker [m]", " text-anchor='middle' font-size='10'");
    for (std::size_t d = 0; d < names.size(); ++d) {
      std::vector<double> xs, ys;
      for (std::size_t b = 0; b < bands.size(); ++b) {
        int pos = 0, hit = 0;
        for (std::size_t i = 0; i < labels.size(); ++i) {
          if (labels[i].weather != weathers[w] || ts::distance_band(labels[i].distance) != bands[b]) continue;
          if (runs[d][i].role != ts::TargetRole::Positive) continue;
          ++pos;
          for (const ts::Scored& sc : runs[d][i].detections) hit += sc.hit && sc.confidence >= threshold ? 1 : 0;
        }
        if (pos >= 10) {
          xs.push_back(static_cast<double>(b));
          ys.push_back(static_cast<double>(hit) / pos);
        }
      }
      if (xs.empty()) continue;
      const std::string colour = colours[d % colours.size()];
      svg.polyline(f.to_pixels(xs, ys), " fill='none' stroke='" + colour + "' stroke-width='1.8'" +
                                            (d == 0 ? "" : " stroke-dasharray='6 3'"));
      for (const Eigen::Vector2d& p : f.to_pixels(xs, ys)) svg.circle(p.x(), p.y(), 2.5, " fill='" + colour + "'");
    }
  }
  return svg.finish();
}

/// The benchmark's figures (JSON) and its table (text): per group of frames
/// — all, by weather, distance band, visible fraction, phase, the oracle's
/// sight, and clear weather with the target observable — each
/// detector's recall, precision and AP@0.5; then false positives on frames
/// without the target and the time per frame.
Json bench_report(const BenchArgs& a, const std::vector<std::string>& names,
                  const std::vector<std::vector<ts::BenchFrame>>& runs, const std::vector<ts::BenchLabel>& labels,
                  const std::string& dictionary, int id, std::string* text) {
  // Groups of frames: all, by weather, distance band, visible fraction, phase.
  struct Group {
    std::string name;
    std::vector<std::size_t> frames;
  };
  std::vector<Group> groups{{"all", {}}};
  std::map<std::string, std::vector<std::size_t>> by_weather, by_distance, by_visible, by_phase, by_sight;
  // The systems' working range: clear weather, the oracle reads the target.
  Group working{"clear, observable", {}};
  for (std::size_t i = 0; i < labels.size(); ++i) {
    groups[0].frames.push_back(i);
    if (!labels[i].sight.empty()) by_sight["sight " + labels[i].sight].push_back(i);
    if (labels[i].weather == "clear" && labels[i].sight == "observable") working.frames.push_back(i);
    by_weather["weather " + labels[i].weather].push_back(i);
    by_phase["phase " + labels[i].phase].push_back(i);
    by_distance["distance " + ts::distance_band(labels[i].distance)].push_back(i);
    if (runs[0][i].role == ts::TargetRole::Positive)
      by_visible["visible " + ts::visible_band(labels[i].visible_fraction)].push_back(i);
  }
  // Weather and phase by name; distance and visibility from near to far, whole to least.
  for (auto& [k, v] : by_weather) groups.push_back({k, v});
  for (const std::string& band : ts::distance_bands()) {
    const std::string k = "distance " + band;
    if (by_distance.count(k)) groups.push_back({k, by_distance[k]});
  }
  for (const std::string& band : ts::visible_bands()) {
    const std::string k = "visible " + band;
    if (by_visible.count(k)) groups.push_back({k, by_visible[k]});
  }
  for (auto& [k, v] : by_phase) groups.push_back({k, v});
  for (auto& [k, v] : by_sight) groups.push_back({k, v});
  if (!working.frames.empty()) groups.push_back(working);
  Json out;
  out["dataset"] = a.dataset;
  out["frames"] = labels.size();
  out["threshold"] = a.threshold;
  out["marker"] = {{"dictionary", dictionary}, {"id", id}};
  std::ostringstream table;
  table << std::left << std::setw(26) << "group" << std::right << std::setw(7) << "frames" << std::setw(8) << "targets";
  for (const std::string& n : names)
    table << std::setw(16) << (n + " recall") << std::setw(11) << "precision" << std::setw(9) << "AP@0.5";
  table << "\n";
  for (const Group& g : groups) {
    table << std::left << std::setw(26) << g.name << std::right << std::setw(7) << g.frames.size();
    Json jg;
    for (std::size_t d = 0; d < names.size(); ++d) {
      std::vector<const ts::BenchFrame*> fr;
      for (std::size_t i : g.frames) fr.push_back(&runs[d][i]);
      const ts::BenchFigures b = ts::bench_figures(fr, a.threshold);
      if (d == 0) table << std::setw(8) << b.positives;
      table << std::setw(16) << (b.positives ? format_fixed(b.recall(), 3) : "-") << std::setw(11)
            << format_fixed(b.precision(), 3) << std::setw(9)
            << (std::isnan(b.ap50) ? std::string("-") : format_fixed(b.ap50, 3));
      jg[names[d]] = {{"frames", b.frames},
                      {"targets", b.positives},
                      {"hits", b.hits},
                      {"false_positives", b.false_positives},
                      {"recall", round3(b.recall())},
                      {"precision", round3(b.precision())},
                      {"ap50", std::isnan(b.ap50) ? Json(nullptr) : Json(round3(b.ap50))}};
    }
    table << "\n";
    out["groups"][g.name] = jg;
  }
  // False positives on frames without the target, and time per frame.
  std::ostringstream tail;
  for (std::size_t d = 0; d < names.size(); ++d) {
    int none = 0, none_distract = 0, fp = 0, fp_distract = 0;
    std::vector<double> ms;
    for (std::size_t i = 0; i < labels.size(); ++i) {
      ms.push_back(runs[d][i].ms);
      if (runs[d][i].role != ts::TargetRole::None) continue;
      int n = 0;
      for (const ts::Scored& sc : runs[d][i].detections) n += sc.confidence >= a.threshold ? 1 : 0;
      ++none, fp += n;
      if (labels[i].distractors_in_view > 0) ++none_distract, fp_distract += n;
    }
    const double per_k = none ? 1000.0 * fp / none : 0.0;
    const double per_k_d = none_distract ? 1000.0 * fp_distract / none_distract : 0.0;
    const double med = td::median(ms);
    tail << names[d] << ": " << format_fixed(per_k, 1) << " false positives per 1000 frames without the target ("
         << none << " frames; " << format_fixed(per_k_d, 1) << " on the " << none_distract
         << " with distractors in view), " << format_fixed(med, 2) << " ms per frame (median, one core)\n";
    out["detectors"][names[d]] = {{"false_positives_per_1000", round3(per_k)},
                                  {"frames_without_target", none},
                                  {"false_positives_per_1000_with_distractors", round3(per_k_d)},
                                  {"frames_with_distractors", none_distract},
                                  {"ms_median", round3(med)}};
  }
  *text = "dataset " + a.dataset + " (" + std::to_string(labels.size()) + " frames, split " + a.split + "), marker " +
          dictionary + " id " + std::to_string(id) + ", threshold " + format_fixed(a.threshold, 2) + "\n" +
          table.str() + tail.str();
  return out;
}

int bench_command(BenchArgs& a) {
  td::StagedOutputs staged;
  const fs::path plot_tmp = stage(staged, a.plot_path, "--plot");
  const fs::path dir(a.dataset);
  const fs::path meta_path = dir / "dataset.json";
  Json meta;
  try {
    std::ifstream in(meta_path);
    if (!in) throw td::IoError(meta_path.string() + ": cannot read (not a landing_scenario dataset)");
    meta = Json::parse(in);
  } catch (const Json::exception&) {
    throw td::ParseError(meta_path.string() + ": not JSON");
  }
  std::string dictionary;
  int id = 0;
  try {
    dictionary = meta.at("marker").at("dictionary").get<std::string>();
    id = meta.at("marker").at("id").get<int>();
  } catch (const Json::exception&) {
    throw td::ParseError(meta_path.string() + ": marker.dictionary, marker.id: missing");
  }
  std::vector<ts::BenchLabel> labels = ts::read_bench_labels(dir / "labels.jsonl");
  if (a.split != "all") std::erase_if(labels, [&](const ts::BenchLabel& l) { return l.split != a.split; });
  if (a.limit > 0 && labels.size() > static_cast<std::size_t>(a.limit))
    labels.resize(static_cast<std::size_t>(a.limit));
  if (labels.empty()) throw td::InvalidArgument(a.dataset + ": no frames of split " + a.split);
  std::vector<std::string> names;
  std::stringstream list(a.detectors);
  for (std::string n; std::getline(list, n, ',');) {
    if (n != "aruco" && n != "learned") throw td::InvalidArgument("--detectors: unknown '" + n + "' (aruco, learned)");
    names.push_back(n);
  }
  if (names.empty()) throw td::InvalidArgument("--detectors: none given");
  cv::setNumThreads(1);  // one core per detector, as a companion computer's worker
  std::vector<std::unique_ptr<ts::MarkerDetector>> detectors;
  for (const std::string& n : names) {
    ts::DetectorOptions o;
    o.kind = n;
    o.roi = false;
    o.min_confidence = 0.05;
    if (!a.model.empty()) o.model = a.model;
    detectors.push_back(ts::make_marker_detector(o));
    detectors.back()->reset(dictionary, id);
  }
  std::vector<std::vector<ts::BenchFrame>> runs(names.size());
  ProgressBar bar("landing_scenario", "images");
  std::vector<ts::MarkerDetection> found;
  for (std::size_t i = 0; i < labels.size(); ++i) {
    const fs::path image = dir / labels[i].image;
    const cv::Mat gray = cv::imread(image.string(), cv::IMREAD_GRAYSCALE);
    if (gray.empty()) throw td::IoError(image.string() + ": not an image OpenCV can read");
    const ts::DetectorFrame frame{{}, {gray.data, gray.cols, gray.rows, static_cast<std::ptrdiff_t>(gray.step)}};
    for (std::size_t d = 0; d < detectors.size(); ++d) {
      detectors[d]->reset(dictionary, id);
      const auto t0 = std::chrono::steady_clock::now();
      detectors[d]->detect(frame, found);
      const double ms = std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - t0).count();
      runs[d].push_back(ts::score_frame(labels[i], found, id));
      runs[d].back().ms = ms;
    }
    bar.draw(i + 1, labels.size());
  }
  bar.close();

  std::string text;
  const Json out = bench_report(a, names, runs, labels, dictionary, id, &text);
  if (!a.plot_path.empty())
    write_text(plot_tmp,
               bench_plot(names, runs, labels, a.threshold, "Recall of the target against distance: " + a.dataset),
               a.plot_path);
  staged.commit();
  if (a.json) {
    std::cout << out.dump() << "\n";
  } else {
    std::cout << text;
  }
  return kExitOk;
}

}  // namespace

struct ContractArgs {
  std::string system = "opencv-mls";
  std::string detector = "aruco";
  double max_time = 0;
  bool json = false;
};

CLI::App* add_contract_command(CLI::App& app, ContractArgs& a) {
  auto* cmd = app.add_subcommand(
      "contract",
      "check that a landing system keeps the LandingSystem contract (name, frameless steps, finite outputs, "
      "determinism, reset, independence); exit 1 when a clause fails");
  add_system_option(*cmd, a.system);
  add_detector_option(*cmd, a.detector);
  cmd->add_option("--max-time", a.max_time,
                  "end every run after this many simulated seconds (default 0: the scenarios' own 35 s and 12 s), "
                  "for a quicker check")
      ->check(CLI::Range(0.0, 300.0))
      ->capture_default_str();
  cmd->add_flag("--json", a.json, "one JSON object per clause instead of the table");
  return cmd;
}

int contract_command(const ContractArgs& a) {
  ts::MlsOptions mls;
  mls.detector.kind = a.detector;
  const ts::SystemFactory factory(a.system);
  (void)factory.make(mls);  // a spec that does not resolve is bad input (exit 2), not a broken clause
  ts::contract::Factory f(a.system, [factory, mls] { return factory.make(mls); });
  f.script.max_time = a.max_time;
  if (!a.json) {
    std::cout << "contract   " << a.system << ": " << ts::contract::clauses().size()
              << " clauses, closed-loop runs on the clear test scenario and a second one\n";
  }
  int failed = 0;
  (void)ts::contract::run_contract(f, [&](const ts::contract::ClauseResult& r) {
    failed += r.verdict.ok ? 0 : 1;
    if (a.json) {
      std::cout << Json{{"clause", r.clause->name},
                        {"ok", r.verdict.ok},
                        {"message", r.verdict.message},
                        {"seconds", round3(r.seconds)}}
                       .dump()
                << std::endl;
      return;
    }
    const std::string name(r.clause->name);
    std::cout << name << std::string(15 - name.size(), ' ') << (r.verdict.ok ? "ok      " : "FAILED  ")
              << format_fixed(r.seconds, 1) << " s  "
              << (r.verdict.ok ? std::string(r.clause->promise) : r.verdict.message) << std::endl;
  });
  if (!a.json) {
    std::cout << "result     "
              << (failed == 0 ? "every clause holds"
                              : std::to_string(failed) + " of " + std::to_string(ts::contract::clauses().size()) +
                                    " clauses fail")
              << "\n";
  }
  return failed == 0 ? 0 : 1;
}

struct SystemsArgs {
  std::vector<std::string> plugins;
  bool json = false;
};

CLI::App* add_systems_command(CLI::App& app, SystemsArgs& a) {
  auto* cmd = app.add_subcommand("systems",
                                 "list the landing systems under test: the built-ins and those of plug-in libraries");
  cmd->add_option("--plugin", a.plugins, "also load this plug-in library and list its systems (repeatable)")
      ->check(td::app::existing_file());
  cmd->add_flag("--json", a.json, "one JSON object per line instead of the table");
  return cmd;
}

int systems_command(const SystemsArgs& a) {
  std::map<std::string, std::string> origin;  // name -> the spec that reaches it
  for (const std::string& path : a.plugins) {
    for (const std::string& name : ts::load_system_plugin(path)) origin[name] = "plugin:" + path + ":" + name;
  }
  const auto entries = ts::system_registry().entries();
  std::size_t width = 0;
  for (const auto& e : entries) width = std::max(width, e.name.size());
  for (const auto& e : entries) {
    const auto it = origin.find(e.name);
    const std::string spec = it != origin.end() ? it->second : e.name;
    if (a.json) {
      std::cout << Json{{"name", e.name}, {"spec", spec}, {"description", e.description}}.dump() << "\n";
    } else {
      std::cout << e.name << std::string(width + 2 - e.name.size(), ' ') << e.description << "\n";
      if (it != origin.end()) std::cout << std::string(width + 2, ' ') << "--system " << spec << "\n";
    }
  }
  return 0;
}

int main(int argc, char** argv) {
  CLI::App app{
      "Run a marker-landing system under test in a scenario (weather, markers, objects) and classify the "
      "outcome; or write a random scenario.",
      "landing_scenario"};
  app.require_subcommand(1);
  RunArgs run_args;
  RandomArgs random_args;
  CampaignArgs campaign_args;
  DatasetArgs dataset_args;
  DetectArgs detect_args;
  BenchArgs bench_args;
  SystemsArgs systems_args;
  ContractArgs contract_args;
  add_run_command(app, run_args);
  auto* contract_cmd = add_contract_command(app, contract_args);
  auto* systems_cmd = add_systems_command(app, systems_args);
  auto* bench_cmd = add_bench_command(app, bench_args);
  auto* detect_cmd = add_detect_command(app, detect_args);
  auto* dataset_cmd = add_dataset_command(app, dataset_args);
  auto* random_cmd = add_random_command(app, random_args);
  auto* campaign_cmd = add_campaign_command(app, campaign_args);
  return run(app, argc, argv, [&]() -> int {
    if (*campaign_cmd) return campaign_command(campaign_args);
    if (*systems_cmd) return systems_command(systems_args);
    if (*contract_cmd) return contract_command(contract_args);
    if (*dataset_cmd) return dataset_command(dataset_args);
    if (*detect_cmd) return detect_command(detect_args);
    if (*bench_cmd) return bench_command(bench_args);
    if (*random_cmd) return random_command(random_args);
    return run_command(run_args);
  });
}
