// landing_mission: fly the closed-loop landing on a moving vehicle in
// simulation, N seeded missions, and report how often and how well it lands
// (issue 34); `envelope` maps the success rate over vehicle speed × wind.

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <iostream>
#include <nlohmann/json.hpp>
#include <opencv2/imgproc.hpp>
#include <optional>
#include <sstream>

#include "app_common.hpp"
#include "core/format.hpp"
#include "touchdown/mission/mission.hpp"
#include "touchdown/mission/mission_io.hpp"
#include "touchdown/mission/mission_plot.hpp"
#include "touchdown/mission/perception_render.hpp"
#include "video.hpp"

namespace {

namespace td = touchdown;
namespace tdm = touchdown::mission;
using td::detail::format_fixed;

struct Args {
  std::string mission_path;
  int runs = 1;
  std::uint64_t seed = 1;
  int threads = 0;
  std::string perception = "model";
  bool json = false;
  std::string plot_dir, log_path, video_path;
  // envelope
  std::vector<double> speeds{0, 3, 0.5}, winds{0, 8, 2};
  std::string envelope_plot;
};

// The percentile q of `v` (nearest rank); NaN when empty.
double percentile(std::vector<double> v, double q) {
  v.erase(std::remove_if(v.begin(), v.end(), [](double x) { return !std::isfinite(x); }), v.end());
  if (v.empty()) return std::nan("");
  std::sort(v.begin(), v.end());
  const auto k = static_cast<std::size_t>(std::ceil(q * static_cast<double>(v.size()))) - (q > 0 ? 1 : 0);
  return v[std::min(k, v.size() - 1)];
}

tdm::MissionFile load(const Args& a) {
  if (a.mission_path.empty()) return {};  // the built-in default: the paper's setup
  return tdm::load_mission(a.mission_path);
}

std::string source_name(const Args& a) { return a.mission_path.empty() ? "built-in circle mission" : a.mission_path; }

nlohmann::json run_json(const tdm::MissionResult& r, int index) {
  using td::app::round3;
  nlohmann::json j;
  j["run"] = index;
  j["outcome"] = std::string(tdm::to_string(r.outcome));
  j["message"] = r.message;
  j["reason"] = r.landed() ? nlohmann::json() : nlohmann::json(tdm::failure_reason(r));
  j["duration_s"] = round3(r.duration);
  j["touchdown_error_m"] =
      std::isfinite(r.touchdown_error) ? nlohmann::json(round3(r.touchdown_error)) : nlohmann::json();
  j["touchdown_speed_mps"] =
      r.touchdown_velocity.allFinite() ? nlohmann::json(round3(r.touchdown_speed())) : nlohmann::json();
  nlohmann::json states;
  for (int s = 0; s < 5; ++s) {
    states[std::string(tdm::to_string(static_cast<tdm::MissionState>(s)))] =
        round3(r.time_in_state[static_cast<std::size_t>(s)]);
  }
  j["time_in_state_s"] = states;
  j["max_tracking_error_m"] = round3(r.max_tracking_error);
  j["max_axis_speed_mps"] = round3(r.max_axis_speed);
  j["max_axis_acceleration_mps2"] = round3(r.max_axis_acceleration);
  j["replans"] = r.replans;
  j["replan_failures"] = r.replan_failures;
  j["pose_frames"] = r.pose_frames;
  j["pose_ok"] = r.pose_ok;
  j["pose_error_median_m"] = std::round(r.pose_error_median * 1e5) / 1e5;
  j["pose_error_max_m"] = std::round(r.pose_error_max * 1e5) / 1e5;
  j["landing_attempts"] = r.landing_attempts;
  nlohmann::json log = nlohmann::json::array();
  for (const auto& t : r.transitions) {
    log.push_back({{"t_s", round3(t.t)},
                   {"from", std::string(tdm::to_string(t.from))},
                   {"to", std::string(tdm::to_string(t.to))},
                   {"reason", std::string(tdm::to_string(t.reason))}});
  }
  j["transitions"] = log;
  return j;
}

// The summary over runs: counts, success rate, percentiles.
struct Summary {
  int runs = 0, landed = 0, crashed = 0, aborted = 0, timeout = 0;
  tdm::FailureCounts reasons;  ///< why the others did not land, most frequent first
  double error_median = 0, error_p95 = 0, error_max = 0;
  double speed_median = 0, speed_p95 = 0, speed_max = 0;
  double tracking_max = 0, axis_speed_max = 0, axis_accel_max = 0, v_limit = 0, a_limit = 0;
  double replan_ms_median = 0, pose_error_median = 0, duration_median = 0;
  double landing_time_median = 0;
  [[nodiscard]] double success() const { return runs ? static_cast<double>(landed) / runs : 0.0; }
};

Summary summarise(const std::vector<tdm::MissionResult>& results) {
  Summary s;
  std::vector<double> err, spd, ms, pose, dur, landing;
  for (const auto& r : results) {
    ++s.runs;
    switch (r.outcome) {
      case tdm::MissionOutcome::Landed:
        ++s.landed;
        err.push_back(r.touchdown_error);
        spd.push_back(r.touchdown_speed());
        dur.push_back(r.duration);
        landing.push_back(r.time_in_state[static_cast<std::size_t>(tdm::MissionState::Landing)]);
        break;
      case tdm::MissionOutcome::Crashed:
        ++s.crashed;
        break;
      case tdm::MissionOutcome::Aborted:
        ++s.aborted;
        break;
      case tdm::MissionOutcome::Timeout:
        ++s.timeout;
        break;
    }
    s.tracking_max = std::max(s.tracking_max, r.max_tracking_error);
    s.axis_speed_max = std::max(s.axis_speed_max, r.max_axis_speed);
    s.axis_accel_max = std::max(s.axis_accel_max, r.max_axis_acceleration);
    s.v_limit = r.v_limit;
    s.a_limit = r.a_limit;
    ms.push_back(r.replan_median_ms);
    pose.push_back(r.pose_error_median);
  }
  s.reasons = tdm::count_failure_reasons(results);
  s.error_median = percentile(err, 0.5);
  s.error_p95 = percentile(err, 0.95);
  s.error_max = percentile(err, 1.0);
  s.speed_median = percentile(spd, 0.5);
  s.speed_p95 = percentile(spd, 0.95);
  s.speed_max = percentile(spd, 1.0);
  s.replan_ms_median = percentile(ms, 0.5);
  s.pose_error_median = percentile(pose, 0.5);
  s.duration_median = percentile(dur, 0.5);
  s.landing_time_median = percentile(landing, 0.5);
  return s;
}

// "gave up: low_off_centre 2, timeout in tracking 1"
std::string reasons_text(const tdm::FailureCounts& reasons) {
  std::string out;
  for (const auto& [why, n] : reasons) out += (out.empty() ? "" : ", ") + why + " " + std::to_string(n);
  return out;
}

nlohmann::json reasons_json(const tdm::FailureCounts& reasons) {
  nlohmann::json j = nlohmann::json::array();
  for (const auto& [why, n] : reasons) j.push_back({{"reason", why}, {"runs", n}});
  return j;
}

std::string fixed(double v, int decimals) { return std::isfinite(v) ? format_fixed(v, decimals) : "-"; }

void print_summary(const Args& a, const tdm::MissionOptions& o, const Summary& s, double wall) {
  std::printf("%s: %d mission%s, vehicle %s at %.2f m/s, perception %s, seed %llu\n", source_name(a).c_str(), s.runs,
              s.runs == 1 ? "" : "s", std::string(tdm::to_string(o.vehicle.path)).c_str(), o.vehicle.speed,
              a.perception.c_str(), static_cast<unsigned long long>(a.seed));
  std::printf("  landed %d (%.1f %%), crashed %d, aborted %d, timeout %d\n", s.landed, 100 * s.success(), s.crashed,
              s.aborted, s.timeout);
  if (!s.reasons.empty()) std::printf("  why not landed: %s\n", reasons_text(s.reasons).c_str());
  std::printf("  touchdown error from the pad centre: median %s m, 95th percentile %s m, max %s m\n",
              fixed(s.error_median, 3).c_str(), fixed(s.error_p95, 3).c_str(), fixed(s.error_max, 3).c_str());
  std::printf("  relative speed at touchdown: median %s m/s, 95th percentile %s m/s, max %s m/s\n",
              fixed(s.speed_median, 2).c_str(), fixed(s.speed_p95, 2).c_str(), fixed(s.speed_max, 2).c_str());
  std::printf("  in landing: largest axis speed %.2f m/s (limit %.2f), acceleration %.2f m/s^2 (limit %.2f)\n",
              s.axis_speed_max, s.v_limit, s.axis_accel_max, s.a_limit);
  std::printf("  max tracking error %.2f m; replans %s ms median; pose error %s mm median\n", s.tracking_max,
              fixed(s.replan_ms_median, 3).c_str(), fixed(1e3 * s.pose_error_median, 1).c_str());
  std::printf("  mission %s s median (landing phase %s s); %.2f s wall\n", fixed(s.duration_median, 1).c_str(),
              fixed(s.landing_time_median, 1).c_str(), wall);
}

nlohmann::json summary_json(const Summary& s) {
  using td::app::round3;
  const auto num = [](double v) { return std::isfinite(v) ? nlohmann::json(round3(v)) : nlohmann::json(); };
  return {
      {"runs", s.runs},
      {"landed", s.landed},
      {"crashed", s.crashed},
      {"aborted", s.aborted},
      {"timeout", s.timeout},
      {"reasons", reasons_json(s.reasons)},
      {"success_rate", round3(s.success())},
      {"touchdown_error_m", {{"median", num(s.error_median)}, {"p95", num(s.error_p95)}, {"max", num(s.error_max)}}},
      {"touchdown_speed_mps", {{"median", num(s.speed_median)}, {"p95", num(s.speed_p95)}, {"max", num(s.speed_max)}}},
      {"max_axis_speed_mps", round3(s.axis_speed_max)},
      {"v_limit_mps", round3(s.v_limit)},
      {"max_axis_acceleration_mps2", round3(s.axis_accel_max)},
      {"a_limit_mps2", round3(s.a_limit)},
      {"max_tracking_error_m", round3(s.tracking_max)},
      {"replan_ms_median", num(s.replan_ms_median)}};
}

std::string trace_csv(const tdm::MissionResult& r) {
  std::ostringstream os;
  os.precision(6);
  os << "t_s,state,x_m,y_m,z_m,vx_mps,vy_mps,vz_mps,est_x_m,est_y_m,est_z_m,sp_x_m,sp_y_m,sp_z_m,sp_vx_mps,sp_vy_mps,"
        "sp_vz_mps,pad_x_m,pad_y_m,pad_z_m,pad_yaw_rad,rel_x_m,rel_y_m,rel_z_m,pose_error_m,tracking_error_m\n";
  for (const auto& s : r.trace) {
    os << s.t << "," << tdm::to_string(s.state);
    for (const Eigen::Vector3d* v : {&s.drone, &s.drone_v, &s.estimate, &s.setpoint, &s.setpoint_v, &s.pad}) {
      os << "," << v->x() << "," << v->y() << "," << v->z();
    }
    os << "," << s.pad_yaw << "," << s.relative.x() << "," << s.relative.y() << "," << s.relative.z() << ","
       << s.pose_error << "," << s.tracking_error << "\n";
  }
  return os.str();
}

// --plot DIR and --log FILE: staged before any work (a run that fails
// leaves nothing), written from run 0 flown again with its trace recorded.
struct Recorded {
  td::StagedOutputs staged;
  std::filesystem::path log, video;
  std::vector<std::pair<std::string, std::filesystem::path>> plots;
};

// One video frame: the camera image with the tracker's blobs (yellow
// circles), the constellation at the estimated pose (green crosses) and a
// status line.
cv::Mat overlay(const tdm::PerceptionFrame& f) {
  const td::BgrImage& c = *f.colour;
  cv::Mat img = cv::Mat(c.height, c.width, CV_8UC3, const_cast<std::uint8_t*>(c.pixels.data())).clone();
  for (const auto& b : *f.blobs) {
    cv::circle(img, cv::Point2d(b.uv_px.x(), b.uv_px.y()), 9, cv::Scalar(0, 220, 255), 1, cv::LINE_AA);
  }
  for (const Eigen::Vector2d& p : f.reprojected) {
    const cv::Point2d q(p.x(), p.y());
    cv::line(img, q - cv::Point2d(6, 0), q + cv::Point2d(6, 0), cv::Scalar(0, 255, 0), 1, cv::LINE_AA);
    cv::line(img, q - cv::Point2d(0, 6), q + cv::Point2d(0, 6), cv::Scalar(0, 255, 0), 1, cv::LINE_AA);
  }
  const auto& e = *f.estimate;
  std::string line = "t " + format_fixed(f.t, 2) + " s   " + std::string(tdm::to_string(f.state)) +
                     "   pose: " + std::string(td::pose::to_string(e.status));
  if (e.ok()) {
    line += " (" + std::to_string(e.points) + " LEDs, sigma " + format_fixed(1e3 * e.sigma_position_m, 1) + " mm)";
  }
  cv::rectangle(img, cv::Rect(0, 0, img.cols, 30), cv::Scalar(0, 0, 0), cv::FILLED);
  cv::putText(img, line, cv::Point(8, 21), cv::FONT_HERSHEY_SIMPLEX, 0.65, cv::Scalar(255, 255, 255), 1, cv::LINE_AA);
  return img;
}

void stage_recorded(const Args& a, Recorded& out) {
  if (!a.plot_dir.empty()) std::filesystem::create_directories(a.plot_dir);
  if (!a.log_path.empty()) out.log = out.staged.add(a.log_path, "--log");
  if (!a.video_path.empty()) out.video = out.staged.add(a.video_path, "--video");
  if (!a.plot_dir.empty()) {
    for (const char* name : {"positions.svg", "velocities.svg", "errors.svg", "top_view.svg"}) {
      out.plots.emplace_back(name, out.staged.add(std::filesystem::path(a.plot_dir) / name, "--plot"));
    }
  }
}

void write_recorded(const Args& a, const tdm::MissionOptions& o, Recorded& out) {
  if (out.log.empty() && out.plots.empty() && out.video.empty()) return;
  std::optional<td::app::VideoFile> video;
  tdm::PerceptionFactory factory;
  if (!out.video.empty()) {
    // Run 0 again with a render perception that hands each frame to the video.
    factory = [&](const tdm::MissionOptions& mo, std::uint64_t seed) {
      const tdm::PerceptionModelOptions m = mo.perception_options();
      auto p = std::make_unique<tdm::RenderPerception>(mo.render, m.camera.T_pad_camera,
                                                       mo.drone.airframe.centre_of_mass(), m.rate_hz, m.latency, seed);
      p->on_frame(
          [&, fps = m.rate_hz, w = mo.render.camera.width, h = mo.render.camera.height](const tdm::PerceptionFrame& f) {
            if (!video) video.emplace(out.video, a.video_path, fps, w, h);
            video->write(overlay(f));
          });
      return p;
    };
  }
  const tdm::MissionResult r = tdm::run_mission(o, a.seed, 0, true, factory);
  if (video) video->finish();
  // The outcome and, when it did not land, why (issue 58 item 8).
  const std::string title = source_name(a) + ", run 0, seed " + std::to_string(a.seed) + " (" +
                            (r.landed() ? std::string("landed") : tdm::failure_reason(r)) + ")";
  for (const auto& [name, tmp] : out.plots) {
    const std::string svg = name == "positions.svg"    ? tdm::plot_positions(r, title)
                            : name == "velocities.svg" ? tdm::plot_velocities(r, title)
                            : name == "errors.svg"     ? tdm::plot_errors(r, title)
                                                       : tdm::plot_top_view(r, title);
    td::app::write_text(tmp, svg, "--plot");
  }
  if (!out.log.empty()) td::app::write_text(out.log, trace_csv(r), "--log");
  out.staged.commit();
}

// "lo:hi:step" → values.
std::vector<double> range_of(const std::vector<double>& r) {
  std::vector<double> v;
  for (double x = r[0]; x <= r[1] + 1e-9 * std::max(1.0, std::abs(r[1])); x += r[2]) v.push_back(x);
  return v;
}

int run_envelope(const Args& a) {
  tdm::MissionFile file = load(a);
  td::app::print_warnings("landing_mission", file.warnings);
  td::StagedOutputs staged;
  std::filesystem::path plot;
  if (!a.envelope_plot.empty()) plot = staged.add(a.envelope_plot, "--plot");
  std::vector<tdm::EnvelopeCell> cells;
  std::vector<std::pair<double, std::string>> refused;  // speed, why
  const auto speeds = range_of(a.speeds), winds = range_of(a.winds);
  td::app::ProgressBar bar("landing_mission", "missions");
  const std::size_t total = speeds.size() * winds.size() * static_cast<std::size_t>(a.runs);
  std::size_t done = 0;
  for (const double wind : winds) {
    for (const double speed : speeds) {
      tdm::MissionOptions o = file.options;
      o.vehicle.speed = std::max(speed, 1e-3);  // 0: a vehicle standing still
      // The vehicle is what the sweep varies: its wheels may go as fast as
      // the speed needs; the drone's limits stay the file's.
      const double outer = o.vehicle.speed * (1 + 0.5 * o.vehicle.track_width / o.vehicle.radius) + 0.1;
      o.vehicle.max_wheel_speed = std::max(o.vehicle.max_wheel_speed, outer);
      o.wind.mean = Eigen::Vector3d(wind, 0, 0);
      o.wind.gust_sigma = 0.25 * wind;
      std::string why;
      tdm::EnvelopeCell cell{speed, wind, a.runs, 0, 0, true, {}};
      if (o.validate(&why)) {
        const auto results =
            tdm::run_missions(o, a.runs, a.seed, a.threads, {}, [&](const td::Progress&) { bar.draw(++done, total); });
        cell.landed =
            static_cast<int>(std::count_if(results.begin(), results.end(), [](const auto& r) { return r.landed(); }));
        cell.crashed = static_cast<int>(std::count_if(
            results.begin(), results.end(), [](const auto& r) { return r.outcome == tdm::MissionOutcome::Crashed; }));
        cell.reasons = tdm::count_failure_reasons(results);
      } else {
        done += static_cast<std::size_t>(a.runs);  // beyond what the drone's options allow: not flown
        cell.valid = false;
        refused.emplace_back(speed, why);
      }
      cells.push_back(cell);
    }
  }
  bar.close();
  if (!plot.empty()) {
    td::app::write_text(
        plot, tdm::plot_envelope(cells, source_name(a) + ", " + std::to_string(a.runs) + " runs per cell"), "--plot");
  }
  staged.commit();
  if (a.json) {
    nlohmann::json j = nlohmann::json::array();
    for (const auto& c : cells) {
      if (c.valid) {
        j.push_back({{"speed_mps", c.speed},
                     {"wind_mps", c.wind},
                     {"runs", c.runs},
                     {"landed", c.landed},
                     {"crashed", c.crashed},
                     {"reasons", reasons_json(c.reasons)},
                     {"success_rate", td::app::round3(c.success())}});
      } else {
        j.push_back({{"speed_mps", c.speed},
                     {"wind_mps", c.wind},
                     {"runs", 0},
                     {"landed", 0},
                     {"crashed", 0},
                     {"reasons", nlohmann::json::array()},
                     {"success_rate", nullptr}});
      }
    }
    std::cout << nlohmann::json{{"mission", source_name(a)}, {"seed", a.seed}, {"cells", j}}.dump() << "\n";
    return td::app::kExitOk;
  }
  std::printf("%s: share landed over vehicle speed x wind, %d runs per cell (gusts 25 %% of the wind)\n",
              source_name(a).c_str(), a.runs);
  std::printf("%10s", "wind \\ v");
  for (const double s : speeds) std::printf(" %6.2f ", s);
  std::printf("\n");
  for (std::size_t j = winds.size(); j-- > 0;) {
    std::printf("%6.2f m/s", winds[j]);
    for (std::size_t i = 0; i < speeds.size(); ++i) {
      const auto& c = cells[j * speeds.size() + i];
      if (c.valid) {
        std::printf(" %5.0f%%%s", 100 * c.success(), c.crashed > 0 ? "*" : " ");
      } else {
        std::printf(" %6s ", "n/a");
      }
    }
    std::printf("\n");
  }
  if (std::any_of(cells.begin(), cells.end(), [](const auto& c) { return c.crashed > 0; })) {
    std::printf("  * some missions of the cell crashed (--json has the counts per cell)\n");
  }
  tdm::FailureCounts all;
  for (const auto& c : cells) all = tdm::merge_failure_reasons(all, c.reasons);
  if (all.empty()) {
    std::printf("  every mission flown landed\n");
  } else {
    std::printf("  why not landed (all cells): %s\n", reasons_text(all).c_str());
  }
  double last = -1;
  for (const auto& [speed, why] : refused) {
    if (speed != last) std::printf("  n/a at %.2f m/s: %s\n", speed, why.c_str());
    last = speed;
  }
  return td::app::kExitOk;
}

}  // namespace

int main(int argc, char** argv) {
  CLI::App app{"Fly the closed-loop landing on a moving vehicle in simulation: N seeded missions, outcome and errors.",
               "landing_mission"};
  Args a;
  app.add_option("mission", a.mission_path, "MISSION.yaml (docs/formats.md); default: the built-in circle mission")
      ->check(td::app::existing_file());
  app.add_option("--runs", a.runs, "missions")->check(CLI::Range(1, 1000000))->capture_default_str();
  td::app::add_seed_option(app, "--seed", a.seed, "seed of the first mission (run i: (seed, i))");
  app.add_option("--threads", a.threads, "worker threads (0 = every core)")
      ->check(CLI::Range(0, 1024))
      ->capture_default_str();
  CLI::Option* perception =
      app.add_option("--perception", a.perception, "perception in the loop (default: the mission file's)")
          ->check(td::app::one_of_names(tdm::perception_registry().names()))
          ->default_str("the file's");
  app.add_flag("--json", a.json, "one JSON object on stdout");
  app.add_option("--plot", a.plot_dir, "write positions/velocities/errors/top_view SVGs of run 0 to this directory")
      ->default_str("off");
  app.add_option("--log", a.log_path, "write run 0's trace (50 Hz) as CSV")
      ->check(td::app::output_extension(".csv"))
      ->default_str("off");
  app.add_option("--video", a.video_path, "render mode: the vehicle camera's view of run 0 (MP4)")
      ->check(td::app::output_extension(".mp4"))
      ->default_str("off");
  CLI::App* envelope = app.add_subcommand("envelope", "success rate over vehicle speed x wind");
  envelope->add_option("mission", a.mission_path, "MISSION.yaml")->check(td::app::existing_file());
  envelope->add_option("--speeds", a.speeds, "vehicle speeds lo hi step [m/s]")
      ->delimiter(':')
      ->expected(3)
      ->check(td::app::number_in(0, 50))
      ->capture_default_str();
  envelope->add_option("--winds", a.winds, "mean winds lo hi step [m/s]")
      ->delimiter(':')
      ->expected(3)
      ->check(td::app::number_in(0, 50))
      ->capture_default_str();
  envelope->add_option("--runs", a.runs, "missions per cell")->check(CLI::Range(1, 100000))->capture_default_str();
  td::app::add_seed_option(*envelope, "--seed", a.seed, "seed");
  envelope->add_option("--threads", a.threads, "worker threads (0 = every core)")->check(CLI::Range(0, 1024));
  envelope->add_option("--plot", a.envelope_plot, "write the envelope as SVG")
      ->check(td::app::output_extension(".svg"))
      ->default_str("off");
  envelope->add_flag("--json", a.json, "one JSON object on stdout");

  return td::app::run(app, argc, argv, [&]() -> int {
    if (envelope->parsed()) {
      for (const auto* r : {&a.speeds, &a.winds}) {
        if (!((*r)[2] > 0) || (*r)[1] < (*r)[0]) {
          throw td::InvalidArgument(std::string(r == &a.speeds ? "--speeds" : "--winds") +
                                    ": expected lo:hi:step with lo <= hi and step > 0");
        }
      }
      return run_envelope(a);
    }
    tdm::MissionFile file = load(a);
    td::app::print_warnings(app.get_name(), file.warnings);
    if (perception->count() == 0) a.perception = file.options.perception;
    file.options.perception = a.perception;
    if (!a.video_path.empty() && a.perception != "render") {
      throw td::InvalidArgument("--video: needs --perception render (the camera's frames are rendered only then)");
    }
    Recorded recorded;
    stage_recorded(a, recorded);
    const auto t0 = std::chrono::steady_clock::now();
    td::app::ProgressBar bar("landing_mission", "missions");
    const bool draw = a.runs > 1;
    const auto results = tdm::run_missions(file.options, a.runs, a.seed, a.threads, {}, [&](const td::Progress& p) {
      if (draw) bar.draw(p.done, p.total);
    });
    bar.close();
    const double wall = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
    write_recorded(a, file.options, recorded);
    const Summary s = summarise(results);
    if (a.json) {
      nlohmann::json runs = nlohmann::json::array();
      for (std::size_t i = 0; i < results.size(); ++i) runs.push_back(run_json(results[i], static_cast<int>(i)));
      std::cout << nlohmann::json{{"mission", source_name(a)},
                                  {"seed", a.seed},
                                  {"perception", a.perception},
                                  {"summary", summary_json(s)},
                                  {"seconds", std::round(wall * 1e3) / 1e3},
                                  {"missions", runs}}
                       .dump()
                << "\n";
    } else {
      print_summary(a, file.options, s, wall);
    }
    return td::app::kExitOk;
  });
}
