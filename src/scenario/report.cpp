#include "touchdown/scenario/report.hpp"

#include <algorithm>
#include <cmath>
#include <nlohmann/json.hpp>
#include <sstream>

#include "core/format.hpp"
#include "core/json_number.hpp"
#include "touchdown/core/batch.hpp"
#include "touchdown/core/statistics.hpp"

namespace touchdown::scenario {

namespace {

using Json = nlohmann::ordered_json;
using detail::format_fixed;
using detail::round3;

Json vec_json(const Eigen::Ref<const Eigen::VectorXd>& v) {
  Json a = Json::array();
  for (Eigen::Index i = 0; i < v.size(); ++i) a.push_back(round3(v(i)));
  return a;
}

Json timing_json(const Timing& t) {
  return {{"render_s", round3(t.render_s)},
          {"system_s", round3(t.system_s)},
          {"physics_s", round3(t.physics_s)},
          {"oracle_s", round3(t.oracle_s)},
          {"total_s", round3(t.total_s)}};
}

Json truth_json(const DetectionTruth& d) {
  return Json{{"t", round3(d.t)},
              {"object", d.object},
              {"label", to_string(d.label)},
              {"id", d.id},
              {"ground", vec_json(d.ground)}};
}

std::string percent(int n, int of) { return format_fixed(of > 0 ? 100.0 * n / of : 0.0, 1) + " %"; }

}  // namespace

std::string result_json(const ScenarioResult& r, std::string_view scenario, std::string_view system) {
  Json j;
  j["scenario"] = scenario;
  j["system"] = system;
  j["violation"] = r.violation();
  j["type"] = to_string(r.status);
  j["message"] = r.message;
  j["landed"] = r.landed;
  j["dtl"] = round3(r.dtl);
  j["ttl"] = round3(r.ttl);
  j["final_position"] = vec_json(r.final_position);
  if (r.collided) {
    j["collision"] = {
        {"t", round3(r.collision.t)}, {"object", r.collision.what}, {"point", vec_json(r.collision.point)}};
  }
  if (r.has_nearest) {
    j["nearest"] = {{"object", r.nearest.what},
                    {"m", round3(r.nearest.distance)},
                    {"t", round3(r.nearest_t)},
                    {"phase", r.nearest_phase}};
  }
  j["descent"] = {{"started", r.descent_started}};
  if (r.descent_started) {
    j["descent"]["t"] = round3(r.descent_time);
    j["descent"]["target"] = vec_json(r.descent_target);
  }
  j["false_detection"] = r.false_detection;
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
  const Observability& ob = r.observability;
  j["observability"] = ob.measured ? Json{{"sighting_time", round3(ob.sighting_time)},
                                          {"observable_s", round3(ob.observable_s)},
                                          {"longest_s", round3(ob.longest_s)},
                                          {"probe_observable_s", round3(ob.probe_observable_s)},
                                          {"probe_longest_s", round3(ob.probe_longest_s)},
                                          {"probe_failure", to_string(ob.probe_failure)},
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
                      {"sight", to_string(f.view.sight)},
                      {"contrast", round3(f.view.contrast)}});
  }
  j["frames"] = std::move(frames);
  j["timing"] = timing_json(r.timing);
  return j.dump();
}

std::string run_summary(const ScenarioResult& r, std::string_view scenario, MapKind map, std::string_view system,
                        std::string_view detector) {
  std::ostringstream out;
  out << "scenario   " << scenario << " (" << to_string(map) << ")\n"
      << "system     " << system
      << (detector != "aruco" && system != "learned-mls" ? " (" + std::string(detector) + " detector)" : "") << "\n"
      << "outcome    "
      << (r.violation()                         ? "VIOLATION: " + r.message
          : r.status == Violation::SystemFailed ? "SYSTEM FAILED (no verdict): " + r.failure
                                                : "ok: " + r.message)
      << "\n";
  // A failed system's run has no DTL or TTL that mean anything.
  if (r.status != Violation::SystemFailed) {
    out << "DTL        " << format_fixed(r.dtl, 2) << " m   TTL " << format_fixed(r.ttl, 1) << " s\n";
  }
  out << "frames     " << r.frames.size() << "   steps " << r.trajectory.size() << "\n";
  const Observability& o = r.observability;
  if (o.measured) {
    out << "target     observable " << format_fixed(o.observable_s, 1) << " s (longest " << format_fixed(o.longest_s, 1)
        << " s) in its camera, " << format_fixed(o.probe_observable_s, 1) << " s (longest "
        << format_fixed(o.probe_longest_s, 1) << " s) from the probe above it\n";
  }
  out << "time       " << format_fixed(r.timing.total_s, 3) << " s (render " << format_fixed(r.timing.render_s, 3)
      << ", system " << format_fixed(r.timing.system_s, 3) << ", physics " << format_fixed(r.timing.physics_s, 3)
      << ", oracle " << format_fixed(r.timing.oracle_s, 3) << ")\n";
  return out.str();
}

std::string trajectory_csv(const ScenarioResult& r, double dt) {
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

std::string campaign_csv(const CampaignResult& c, const std::vector<std::string>& names) {
  std::ostringstream os;
  os << "scenario,map,violation,type,landed,dtl,ttl,false_detection,flight_s,frames,wall_s,render_s,system_s,"
        "message\n";
  for (std::size_t i = 0; i < c.entries.size(); ++i) {
    const ScenarioOutcome& e = c.entries[i].outcome;
    std::string msg = e.message;
    std::replace(msg.begin(), msg.end(), '"', '\'');
    os << (i < names.size() ? names[i] : std::to_string(i)) << ',' << to_string(c.entries[i].map) << ','
       << (e.violation() ? 1 : 0) << ',' << to_string(e.status) << ',' << (e.landed ? 1 : 0) << ','
       << format_fixed(e.dtl, 3) << ',' << format_fixed(e.ttl, 2) << ',' << (e.false_detection ? 1 : 0) << ','
       << format_fixed(e.flight_s, 2) << ',' << e.frame_count << ',' << format_fixed(e.timing.total_s, 3) << ','
       << format_fixed(e.timing.render_s, 3) << ',' << format_fixed(e.timing.system_s, 3) << ",\"" << msg << "\"\n";
  }
  return os.str();
}

std::string campaign_json(const CampaignResult& c, std::string_view source, const CampaignOptions& o) {
  const CampaignSummary& s = c.summary;
  Json j;
  j["scenarios"] = source;
  j["system"] = o.system.name();
  j["detection_roi"] = o.mls.detector.roi;
  j["threads"] = resolve_threads(o.threads);
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
  j["timing"] = timing_json(s.timing);
  return j.dump();
}

std::string campaign_summary(const CampaignResult& c, std::string_view source, const CampaignOptions& o,
                             const std::vector<std::string>& names) {
  const CampaignSummary& s = c.summary;
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
  std::ostringstream out;
  out << "campaign   " << s.scenarios << " scenarios: " << source << "\n"
      << "system     " << o.system.name()
      << (o.mls.detector.kind != "aruco" && o.system != "learned-mls" ? " (" + o.mls.detector.kind + " detector)" : "")
      << (o.mls.detector.roi ? "" : " (whole-frame detection)") << "\n"
      << "violations " << s.violations << "/" << s.scenarios << " (" << percent(s.violations, s.scenarios)
      << "): type I " << s.type_i << " (" << percent(s.type_i, s.scenarios) << "), type II " << s.type_ii << " ("
      << percent(s.type_ii, s.scenarios) << "; " << s.unfair_type_ii << " unfair), type III " << s.type_iii << " ("
      << percent(s.type_iii, s.scenarios) << "), off-marker " << s.off_marker << "\n";
  if (s.system_failed > 0) {
    const auto first = std::find_if(c.entries.begin(), c.entries.end(),
                                    [](const CampaignEntry& e) { return e.outcome.status == Violation::SystemFailed; });
    const auto i = static_cast<std::size_t>(first - c.entries.begin());
    out << "failed     " << s.system_failed << " runs: the system under test failed (first, "
        << (i < names.size() ? names[i] : "scenario " + std::to_string(i)) << ": " << first->outcome.failure << ")\n";
  }
  out << "landed     " << dtl.size();
  if (!dtl.empty()) {
    out << ": median DTL " << format_fixed(median(dtl), 2) << " m, median TTL " << format_fixed(median(ttl), 1) << " s";
  }
  out << "\n"
      << "time       " << format_fixed(s.wall_s, 1) << " s wall on " << resolve_threads(o.threads) << " threads for "
      << format_fixed(s.flight_s, 0) << " s of flight (" << format_fixed(s.wall_s > 0 ? s.flight_s / s.wall_s : 0.0, 0)
      << "x real time); per scenario " << format_fixed(s.scenarios > 0 ? s.timing.total_s / s.scenarios : 0.0, 2)
      << " s: render " << share(s.timing.render_s) << ", system " << share(s.timing.system_s) << ", physics "
      << share(s.timing.physics_s) << ", oracle " << share(s.timing.oracle_s) << ", other " << share(other) << "\n";
  return out.str();
}

}  // namespace touchdown::scenario
