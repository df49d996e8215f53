// landing_mission's reports (docs/cli.md): missions as JSON, the summary,
// the trace CSV and the envelope.
#include "touchdown/mission/report.hpp"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdarg>
#include <cstdio>
#include <filesystem>
#include <nlohmann/json.hpp>
#include <numbers>
#include <sstream>

#include "core/format.hpp"
#include "core/json_number.hpp"
#include "touchdown/core/error.hpp"
#include "touchdown/core/statistics.hpp"

namespace touchdown::mission {

namespace {

using detail::format_fixed;
using detail::round3;

// printf onto a string (the summary's fixed-width figures).
__attribute__((format(printf, 2, 3))) void appendf(std::string& out, const char* format, ...) {
  char buf[1024];
  va_list args;
  va_start(args, format);
  std::vsnprintf(buf, sizeof buf, format, args);
  va_end(args);
  out += buf;
}

// The nearest-rank percentile q of the finite values of `v`; NaN when none.
double finite_percentile(std::vector<double> v, double q) {
  std::erase_if(v, [](double x) { return !std::isfinite(x); });
  return v.empty() ? std::nan("") : nearest_rank(std::move(v), q);
}

nlohmann::json run_json(const MissionResult& r, int index) {
  nlohmann::json j;
  j["run"] = index;
  j["outcome"] = std::string(to_string(r.outcome));
  j["message"] = r.message;
  j["reason"] = r.landed() ? nlohmann::json() : nlohmann::json(failure_reason(r));
  j["duration_s"] = round3(r.duration);
  j["touchdown_error_m"] =
      std::isfinite(r.touchdown_error) ? nlohmann::json(round3(r.touchdown_error)) : nlohmann::json();
  j["touchdown_speed_mps"] =
      r.touchdown_velocity.allFinite() ? nlohmann::json(round3(r.touchdown_speed())) : nlohmann::json();
  nlohmann::json states;
  for (int s = 0; s < 5; ++s) {
    states[std::string(to_string(static_cast<MissionState>(s)))] = round3(r.time_in_state[static_cast<std::size_t>(s)]);
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
                   {"from", std::string(to_string(t.from))},
                   {"to", std::string(to_string(t.to))},
                   {"reason", std::string(to_string(t.reason))}});
  }
  j["transitions"] = log;
  return j;
}

nlohmann::json reasons_json(const FailureCounts& reasons) {
  nlohmann::json j = nlohmann::json::array();
  for (const auto& [why, n] : reasons) j.push_back({{"reason", why}, {"runs", n}});
  return j;
}

std::string fixed(double v, int decimals) { return std::isfinite(v) ? format_fixed(v, decimals) : "-"; }

nlohmann::json summary_json(const MissionSummary& s) {
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

}  // namespace

MissionSummary summarise(const std::vector<MissionResult>& results) {
  MissionSummary s;
  std::vector<double> err, spd, ms, pose, dur, landing;
  for (const auto& r : results) {
    ++s.runs;
    switch (r.outcome) {
      case MissionOutcome::Landed:
        ++s.landed;
        err.push_back(r.touchdown_error);
        spd.push_back(r.touchdown_speed());
        dur.push_back(r.duration);
        landing.push_back(r.time_in_state[static_cast<std::size_t>(MissionState::Landing)]);
        break;
      case MissionOutcome::Crashed:
        ++s.crashed;
        break;
      case MissionOutcome::Aborted:
        ++s.aborted;
        break;
      case MissionOutcome::Timeout:
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
  s.reasons = count_failure_reasons(results);
  s.error_median = finite_percentile(err, 0.5);
  s.error_p95 = finite_percentile(err, 0.95);
  s.error_max = finite_percentile(err, 1.0);
  s.speed_median = finite_percentile(spd, 0.5);
  s.speed_p95 = finite_percentile(spd, 0.95);
  s.speed_max = finite_percentile(spd, 1.0);
  s.replan_ms_median = finite_percentile(ms, 0.5);
  s.pose_error_median = finite_percentile(pose, 0.5);
  s.duration_median = finite_percentile(dur, 0.5);
  s.landing_time_median = finite_percentile(landing, 0.5);
  return s;
}

std::string reasons_text(const FailureCounts& reasons) {
  std::string out;
  for (const auto& [why, n] : reasons) out += (out.empty() ? "" : ", ") + why + " " + std::to_string(n);
  return out;
}

std::string summary_text(const MissionRunInfo& info, const MissionOptions& o, const MissionSummary& s, double wall) {
  std::string out;
  std::string vehicle = std::string(to_string(o.vehicle.path));
  if (o.vehicle.path == VehiclePath::Log && o.vehicle.log) {
    vehicle += " " + std::filesystem::path(o.vehicle.log->source()).filename().string() + " (" +
               fixed(o.vehicle.log->duration(), 0) + " s, up to " + fixed(o.vehicle.log->top_speed(0), 1) + " m/s)";
  } else {
    vehicle += " at " + fixed(o.vehicle.speed, 2) + " m/s";
  }
  // The wind, when there is any.
  std::string wind;
  if (o.wind.mean.norm() > 0) {
    wind += ", wind [" + touchdown::detail::format_trimmed(o.wind.mean.x(), 2) + ", " +
            touchdown::detail::format_trimmed(o.wind.mean.y(), 2) + ", " +
            touchdown::detail::format_trimmed(o.wind.mean.z(), 2) + "] m/s";
  }
  if (o.wind.turbulence != TurbulenceLevel::None)
    wind += ", " + std::string(to_string(o.wind.turbulence)) + " turbulence";
  appendf(out, "%s: %d mission%s, vehicle %s%s, perception %s, seed %llu\n", info.source.c_str(), s.runs,
          s.runs == 1 ? "" : "s", vehicle.c_str(), wind.c_str(), info.perception.c_str(),
          static_cast<unsigned long long>(info.seed));
  appendf(out, "  landed %d (%.1f %%), crashed %d, aborted %d, timeout %d\n", s.landed, 100 * s.success(), s.crashed,
          s.aborted, s.timeout);
  if (!s.reasons.empty()) appendf(out, "  why not landed: %s\n", reasons_text(s.reasons).c_str());
  appendf(out, "  touchdown error from the pad centre: median %s m, 95th percentile %s m, max %s m\n",
          fixed(s.error_median, 3).c_str(), fixed(s.error_p95, 3).c_str(), fixed(s.error_max, 3).c_str());
  appendf(out, "  relative speed at touchdown: median %s m/s, 95th percentile %s m/s, max %s m/s\n",
          fixed(s.speed_median, 2).c_str(), fixed(s.speed_p95, 2).c_str(), fixed(s.speed_max, 2).c_str());
  appendf(out, "  in landing: largest axis speed %.2f m/s (limit %.2f), acceleration %.2f m/s^2 (limit %.2f)\n",
          s.axis_speed_max, s.v_limit, s.axis_accel_max, s.a_limit);
  appendf(out, "  max tracking error %.2f m; replans %s ms median; pose error %s mm median\n", s.tracking_max,
          fixed(s.replan_ms_median, 3).c_str(), fixed(1e3 * s.pose_error_median, 1).c_str());
  appendf(out, "  mission %s s median (landing phase %s s); %.2f s wall\n", fixed(s.duration_median, 1).c_str(),
          fixed(s.landing_time_median, 1).c_str(), wall);
  return out;
}

std::string trace_csv(const MissionResult& r) {
  std::ostringstream os;
  os.precision(6);
  os << "t_s,state,x_m,y_m,z_m,vx_mps,vy_mps,vz_mps,est_x_m,est_y_m,est_z_m,sp_x_m,sp_y_m,sp_z_m,sp_vx_mps,sp_vy_mps,"
        "sp_vz_mps,pad_x_m,pad_y_m,pad_z_m,pad_yaw_rad,rel_x_m,rel_y_m,rel_z_m,pose_error_m,tracking_error_m,tilt_deg,"
        "thrust_n,wind_x_mps,wind_y_mps,wind_z_mps,wind_est_x_mps,wind_est_y_mps,wind_est_z_mps\n";
  for (const auto& s : r.trace) {
    os << s.t << "," << to_string(s.state);
    for (const Eigen::Vector3d* v : {&s.drone, &s.drone_v, &s.estimate, &s.setpoint, &s.setpoint_v, &s.pad}) {
      os << "," << v->x() << "," << v->y() << "," << v->z();
    }
    os << "," << s.pad_yaw << "," << s.relative.x() << "," << s.relative.y() << "," << s.relative.z() << ","
       << s.pose_error << "," << s.tracking_error << "," << s.tilt * 180 / std::numbers::pi << "," << s.thrust;
    for (const Eigen::Vector3d* v : {&s.wind, &s.wind_estimate}) os << "," << v->x() << "," << v->y() << "," << v->z();
    os << "\n";
  }
  return os.str();
}

std::string missions_json(const MissionRunInfo& info, const std::vector<MissionResult>& results, double seconds) {
  nlohmann::json runs = nlohmann::json::array();
  for (std::size_t i = 0; i < results.size(); ++i) runs.push_back(run_json(results[i], static_cast<int>(i)));
  return nlohmann::json{{"mission", info.source},
                        {"seed", info.seed},
                        {"perception", info.perception},
                        {"summary", summary_json(summarise(results))},
                        {"seconds", std::round(seconds * 1e3) / 1e3},
                        {"missions", runs}}
      .dump();
}

Envelope run_envelope(const MissionOptions& base, const std::vector<double>& speeds, const std::vector<double>& winds,
                      int runs, std::uint64_t seed, int threads, const ProgressCallback& progress) {
  if (base.vehicle.path == VehiclePath::Log) {
    throw InvalidArgument(
        "envelope: vehicle.path is log, whose speeds are the log's; the envelope varies the speed of a path the "
        "vehicle drives itself (circle, line, figure_eight, random)");
  }
  Envelope e;
  e.speeds = speeds;
  e.winds = winds;
  e.turbulence = base.wind.turbulence;
  e.runs = runs;
  const auto start = std::chrono::steady_clock::now();
  const std::size_t total = speeds.size() * winds.size() * static_cast<std::size_t>(std::max(0, runs));
  std::size_t done = 0;
  for (const double wind : winds) {
    for (const double speed : speeds) {
      MissionOptions o = base;
      o.vehicle.speed = std::max(speed, 1e-3);  // 0: a vehicle standing still
      // The vehicle is what the sweep varies: its wheels may go as fast as
      // the speed needs; the drone's limits stay the file's.
      const double outer = o.vehicle.speed * (1 + 0.5 * o.vehicle.track_width / o.vehicle.radius) + 0.1;
      o.vehicle.max_wheel_speed = std::max(o.vehicle.max_wheel_speed, outer);
      o.wind.mean = Eigen::Vector3d(wind, 0, 0);
      o.wind.gust_sigma = 0.25 * wind;
      std::string why;
      EnvelopeCell cell{speed, wind, runs, 0, 0, true, {}};
      if (o.validate(&why)) {
        const auto results = run_missions(o, runs, seed, threads, {}, [&](const Progress&) {
          ++done;
          if (progress) progress(progress_since(start, done, total, done - 1));
        });
        cell.landed =
            static_cast<int>(std::count_if(results.begin(), results.end(), [](const auto& r) { return r.landed(); }));
        cell.crashed = static_cast<int>(std::count_if(
            results.begin(), results.end(), [](const auto& r) { return r.outcome == MissionOutcome::Crashed; }));
        cell.reasons = count_failure_reasons(results);
        const MissionSummary sum = summarise(results);
        cell.error_median = sum.error_median;
        cell.error_p95 = sum.error_p95;
        cell.speed_median = sum.speed_median;
        cell.speed_p95 = sum.speed_p95;
      } else {
        done += static_cast<std::size_t>(runs);  // beyond what the drone's options allow: not flown
        if (progress) progress(progress_since(start, done, total, done - 1));
        cell.valid = false;
        e.refused.emplace_back(speed, why);
      }
      e.cells.push_back(cell);
    }
  }
  return e;
}

std::string envelope_json(const Envelope& e, std::string_view source, std::uint64_t seed) {
  nlohmann::json j = nlohmann::json::array();
  for (const auto& c : e.cells) {
    if (c.valid) {
      j.push_back({{"speed_mps", c.speed},
                   {"wind_mps", c.wind},
                   {"runs", c.runs},
                   {"landed", c.landed},
                   {"crashed", c.crashed},
                   {"reasons", reasons_json(c.reasons)},
                   {"success_rate", round3(c.success())},
                   {"touchdown_error_m",
                    c.landed > 0 ? nlohmann::json{{"median", round3(c.error_median)}, {"p95", round3(c.error_p95)}}
                                 : nlohmann::json(nullptr)},
                   {"touchdown_speed_mps",
                    c.landed > 0 ? nlohmann::json{{"median", round3(c.speed_median)}, {"p95", round3(c.speed_p95)}}
                                 : nlohmann::json(nullptr)}});
    } else {
      j.push_back({{"speed_mps", c.speed},
                   {"wind_mps", c.wind},
                   {"runs", 0},
                   {"landed", 0},
                   {"crashed", 0},
                   {"reasons", nlohmann::json::array()},
                   {"success_rate", nullptr},
                   {"touchdown_error_m", nullptr},
                   {"touchdown_speed_mps", nullptr}});
    }
  }
  return nlohmann::json{{"mission", source}, {"seed", seed}, {"cells", j}}.dump();
}

std::string envelope_text(const Envelope& e, std::string_view source) {
  std::string out;
  appendf(out, "%s: share landed over vehicle speed x wind, %d runs per cell (gusts 25 %% of the wind%s)\n",
          std::string(source).c_str(), e.runs,
          e.turbulence == TurbulenceLevel::None
              ? ""
              : (", " + std::string(to_string(e.turbulence)) + " turbulence").c_str());
  // One grid per figure: the share landed, then of the landed runs the
  // touchdown error's and the touchdown speed's 95th percentiles.
  const auto grid = [&](const char* title, const auto& cell_text) {
    appendf(out, "%s\n%10s", title, "wind \\ v");
    for (const double s : e.speeds) appendf(out, " %6.2f ", s);
    appendf(out, "\n");
    for (std::size_t j = e.winds.size(); j-- > 0;) {
      appendf(out, "%6.2f m/s", e.winds[j]);
      for (std::size_t i = 0; i < e.speeds.size(); ++i) {
        const auto& c = e.cells[j * e.speeds.size() + i];
        appendf(out, " %s", c.valid ? cell_text(c).c_str() : "   n/a ");
      }
      appendf(out, "\n");
    }
  };
  grid("  share landed", [](const EnvelopeCell& c) {
    std::string t;
    appendf(t, "%5.0f%%%s", 100 * c.success(), c.crashed > 0 ? "*" : " ");
    return t;
  });
  grid("  touchdown error, 95th percentile of the landed [m]", [](const EnvelopeCell& c) {
    std::string t;
    appendf(t, "%6.3f ", c.error_p95);
    return c.landed > 0 ? t : std::string("     - ");
  });
  grid("  touchdown speed relative to the pad, 95th percentile of the landed [m/s]", [](const EnvelopeCell& c) {
    std::string t;
    appendf(t, "%6.2f ", c.speed_p95);
    return c.landed > 0 ? t : std::string("     - ");
  });
  if (std::any_of(e.cells.begin(), e.cells.end(), [](const auto& c) { return c.crashed > 0; })) {
    appendf(out, "  * some missions of the cell crashed (--json has the counts per cell)\n");
  }
  FailureCounts all;
  for (const auto& c : e.cells) all = merge_failure_reasons(all, c.reasons);
  if (std::none_of(e.cells.begin(), e.cells.end(), [](const auto& c) { return c.valid; })) {
    appendf(out, "  no mission flown: every cell is beyond the drone's options (n/a below)\n");
  } else if (all.empty()) {
    appendf(out, "  every mission flown landed\n");
  } else {
    appendf(out, "  why not landed (all cells): %s\n", reasons_text(all).c_str());
  }
  // Each reason once, with the speeds it holds at.
  std::vector<std::pair<std::string, std::string>> refused;  // reason, speeds
  double last = -1;
  for (const auto& cell : e.refused) {
    const double speed = cell.first;
    const std::string& why = cell.second;
    if (speed == last) continue;
    last = speed;
    std::string at;
    appendf(at, "%.2f", speed);
    const auto it = std::find_if(refused.begin(), refused.end(), [&why](const auto& r) { return r.first == why; });
    if (it == refused.end()) {
      refused.emplace_back(why, at);
    } else {
      it->second += ", " + at;
    }
  }
  for (const auto& [why, speeds] : refused) appendf(out, "  n/a at %s m/s: %s\n", speeds.c_str(), why.c_str());
  return out;
}

}  // namespace touchdown::mission
