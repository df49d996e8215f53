// landing_sweep's outputs (docs/cli.md, "landing_sweep"): the runs as CSV,
// the decision as JSON and the summary table.
#include "touchdown/twin/sweep_report.hpp"

#include <cmath>
#include <iomanip>
#include <nlohmann/json.hpp>
#include <sstream>

#include "core/format.hpp"
#include "touchdown/core/units.hpp"

namespace touchdown::twin {

namespace {

double round6(double v) { return std::round(v * 1e6) / 1e6 + 0.0; }

// What was flown: with --search-radius, every point the search swept; else
// the one sweep (then the same figures as the sweep's own).
struct Totals {
  std::size_t landings = 0;
  double completeness = 0, seconds = 0, simulated_seconds = 0, run_sim_to_wall = 0;
};

Totals sweep_totals(const SweepResult& r) {
  return {r.landings(), r.completeness, r.seconds, r.simulated_seconds, r.run_sim_to_wall};
}

Totals totals(const SweepOptions& o, const SearchResult& search) {
  if (search.candidates.empty()) return sweep_totals(search.sweep);
  const double planned = static_cast<double>(search.points_flown) * o.headings * o.runs;
  return {search.landings, planned > 0 ? static_cast<double>(search.landings) / planned : 0.0, search.seconds,
          search.simulated_seconds, search.run_sim_to_wall};
}

// NaN (no settled run) is JSON null, never a number standing in for it.
nlohmann::json num(double v) { return std::isnan(v) ? nlohmann::json(nullptr) : nlohmann::json(round6(v)); }

nlohmann::json headings_json(const SweepResult& r) {
  nlohmann::json hs = nlohmann::json::array();
  for (const auto& h : r.headings) {
    hs.push_back({{"yaw_deg", round6(rad_to_deg(h.yaw))},
                  {"score_rad", num(h.score)},
                  {"mean_rad", num(h.mean)},
                  {"max_touchdown_rad", num(h.max_touchdown)},
                  {"runs", h.runs},
                  {"prop_strike_runs", h.prop_strike_runs},
                  {"arm_strike_runs", h.arm_strike_runs},
                  {"body_strike_runs", h.body_strike_runs},
                  {"tipped_runs", h.tipped_runs},
                  {"invalid_runs", h.invalid_runs},
                  {"timeout_runs", h.timeout_runs},
                  {"unstable_runs", h.unstable_runs},
                  {"invalid_reason", h.invalid_reason},
                  {"unobserved_terrain", h.unobserved},
                  {"feet_not_all_down_runs", h.feet_not_all_down_runs},
                  {"max_offset_m", round6(h.max_offset)},
                  {"safe", h.safe},
                  {"reason", std::string(to_string(h.reason))},
                  {"flown", std::string(to_string(h.flown))}});
  }
  return hs;
}

// runs, completeness, seconds and the speeds.
void add_totals(nlohmann::json& j, const Totals& t) {
  j["runs"] = t.landings;
  j["completeness"] = round6(t.completeness);
  j["seconds"] = round6(t.seconds);
  j["landings_per_second"] = round6(static_cast<double>(t.landings) / t.seconds);
  j["simulated_to_wall"] = round6(t.simulated_seconds / t.seconds);
  j["run_simulated_to_wall"] = round6(t.run_sim_to_wall);
}

// Radians in the table, "-" for a heading that has no score.
std::string rad_text(double v) { return std::isnan(v) ? std::string("-") : detail::format_fixed(v, 3); }

}  // namespace

std::string runs_csv(const SweepResult& r) {
  std::ostringstream os;
  os << std::setprecision(9);
  os << "heading_deg,run,status,reason,final_nutation_rad,final_roll_rad,final_pitch_rad,max_touchdown_nutation_rad,"
        "offset_m,prop_strike,arm_strike,body_strike,tipped,all_feet_down,start_dx_m,start_dy_m,heading_error_deg,"
        "roll0_deg,pitch0_deg,land_speed_mps,friction,sim_seconds\n";
  for (const auto& run : r.runs) {
    const auto& c = run.conditions;
    const auto& x = run.result;
    os << rad_to_deg(c.heading) << "," << run.run << "," << to_string(x.status) << "," << x.message << "," << x.nutation
       << "," << x.roll << "," << x.pitch << "," << x.max_touchdown_nutation << "," << x.offset << "," << x.prop_strike
       << "," << x.arm_strike << "," << x.body_strike << "," << x.tipped << "," << x.all_feet_in_contact << ","
       << c.start_offset.x() << "," << c.start_offset.y() << "," << rad_to_deg(c.heading_error) << ","
       << rad_to_deg(c.roll) << "," << rad_to_deg(c.pitch) << "," << c.land_speed << "," << c.friction << ","
       << x.sim_time << "\n";
  }
  return os.str();
}

// The --json object.
std::string sweep_json(const SearchResult& search, const SweepReportInfo& info) {
  const SweepResult& r = search.sweep;
  const SweepOptions& o = info.options;
  const HeadingScore* best = r.best >= 0 ? &r.headings[static_cast<std::size_t>(r.best)] : nullptr;
  nlohmann::json j;
  j["terrain"] = info.terrain;
  j["airframe"] = info.airframe;
  j["contact"] = info.contact;
  j["threshold_rad"] = round6(r.threshold.value());
  j["threshold_parts"] = {{"tip_rad", round6(r.threshold.tip_rad)},
                          {"prop_strike_rad", round6(r.threshold.prop_strike_rad)}};
  j["ground_z"] = round6(r.ground_z);
  j["landing_point"] = {{"x", round6(o.landing_point.x())}, {"y", round6(o.landing_point.y())}};
  j["land"] = r.safe;
  j["mode"] = o.decide ? "decide" : "full";
  j["decided"] = r.decided;
  j["deadline_s"] = round6(o.deadline);
  j["unsafe_reasons"] = unsafe_summary(r);
  if (best) {
    j["best"] = {{"yaw_deg", round6(rad_to_deg(best->yaw))},
                 {"score_rad", num(best->score)},
                 {"safe", r.safe},
                 {"x", round6(o.landing_point.x())},
                 {"y", round6(o.landing_point.y())}};
  } else {
    j["best"] = nullptr;
  }
  nlohmann::json safe = nlohmann::json::array();
  for (const auto& h : r.headings) {
    if (h.safe) safe.push_back(round6(rad_to_deg(h.yaw)));
  }
  j["safe_headings_deg"] = safe;
  j["headings"] = headings_json(r);
  if (!search.candidates.empty()) {
    nlohmann::json cs = nlohmann::json::array();
    for (const auto& c : search.candidates) {
      if (!c.covered) continue;
      cs.push_back({{"x", round6(c.xy.x())},
                    {"y", round6(c.xy.y())},
                    {"yaw_deg", round6(rad_to_deg(c.yaw))},
                    {"score_rad", num(c.score)},
                    {"unobserved_terrain", c.unobserved},
                    {"safe", c.safe}});
    }
    j["search"] = cs;
  }
  add_totals(j, totals(o, search));
  if (!search.candidates.empty()) {
    nlohmann::json chosen = {{"x", round6(o.landing_point.x())}, {"y", round6(o.landing_point.y())}};
    add_totals(chosen, sweep_totals(r));
    j["chosen"] = chosen;
  }
  return j.dump();
}

// The human summary: the table of headings, the search's points and the decision.
std::string sweep_summary(const SearchResult& search, const SweepReportInfo& info) {
  std::ostringstream out;
  const SweepResult& r = search.sweep;
  const SweepOptions& o = info.options;
  const HeadingScore* best = r.best >= 0 ? &r.headings[static_cast<std::size_t>(r.best)] : nullptr;
  const Totals t = totals(o, search);
  const double lps = static_cast<double>(t.landings) / t.seconds;
  out << std::fixed << std::setprecision(3);
  out << "landing_sweep: " << info.terrain << ", " << detail::count_noun(static_cast<long long>(t.landings), "landing")
      << " (";
  if (search.candidates.empty() && o.decide) {
    out << "decision mode: " << detail::count_noun(static_cast<long long>(r.headings.size()), "heading") << " x "
        << "up to " << detail::count_noun(o.runs, "run") << ", " << std::setprecision(0) << 100 * r.completeness
        << " % of the full sweep";
  } else if (search.candidates.empty()) {
    out << detail::count_noun(static_cast<long long>(r.headings.size()), "heading") << " x "
        << detail::count_noun(r.rounds_completed, "run");
  } else {
    out << detail::count_noun(static_cast<long long>(search.points_flown), "point") << " x "
        << detail::count_noun(o.headings, "heading") << " x " << (t.completeness < 1 ? "up to " : "")
        << detail::count_noun(o.runs, "run");
  }
  out << std::setprecision(3) << ") in " << t.seconds << " s (" << std::setprecision(0) << lps
      << " landings/s; one landing simulates " << t.run_sim_to_wall << "x faster than real time"
      << (info.contact == "trimesh" ? "" : "; " + info.contact + " contact") << ")\n";
  if (!search.candidates.empty()) {
    out << std::setprecision(3) << "  chosen point (" << o.landing_point.x() << ", " << o.landing_point.y()
        << "): " << detail::count_noun(static_cast<long long>(r.landings()), "landing") << " ("
        << detail::count_noun(static_cast<long long>(r.headings.size()), "heading") << " x "
        << detail::count_noun(r.rounds_completed, "run") << ") in " << r.seconds << " s\n";
  }
  out << std::setprecision(3) << "  safety threshold " << r.threshold.value() << " rad (tip-over "
      << r.threshold.tip_rad << ", propeller or arm strike " << r.threshold.prop_strike_rad << ")\n"
      << "  heading  S(psi)    mean  touchdown  runs  prop   arm  body  tipped  invalid  verdict\n"
      << "    [deg]   [rad]   [rad]      [rad]        (runs with a strike)\n";
  for (const auto& h : r.headings) {
    std::string verdict = h.safe ? "safe" : "unsafe: " + std::string(to_string(h.reason));
    if (h.reason == UnsafeReason::InvalidRuns) verdict = "invalid (" + h.invalid_reason + ")";
    // The decision mode's partial headings: S so far is a lower bound.
    const bool partial = h.flown != HeadingFlown::All;
    if (h.flown == HeadingFlown::UntilOutranked) {
      verdict = "outranked: cannot beat the chosen heading" +
                (h.reason == UnsafeReason::None ? std::string() : "; " + verdict);
    } else if (h.flown == HeadingFlown::UntilDeadline) {
      verdict = "not settled by the deadline";
    }
    out << "  " << std::setw(7) << std::setprecision(1) << rad_to_deg(h.yaw) << std::setprecision(3) << " "
        << std::setw(7) << ((partial && !std::isnan(h.score) ? ">=" : "") + rad_text(h.score)) << " " << std::setw(7)
        << rad_text(h.mean) << " " << std::setw(10) << rad_text(h.max_touchdown) << std::setw(6) << h.runs << " "
        << std::setw(6) << h.prop_strike_runs << std::setw(6) << h.arm_strike_runs << std::setw(6) << h.body_strike_runs
        << std::setw(8) << h.tipped_runs << std::setw(9) << h.invalid_runs << "  " << verdict << "\n";
  }
  for (const auto& c : search.candidates) {
    if (!c.covered) continue;
    out << "  search: (" << c.xy.x() << ", " << c.xy.y() << ") best heading " << std::setprecision(1)
        << rad_to_deg(c.yaw) << std::setprecision(3) << " deg, S = " << rad_text(c.score) << " rad"
        << (c.safe         ? ""
            : c.unobserved ? " (unsafe: unobserved terrain)"
                           : " (unsafe)")
        << "\n";
  }
  int unsettled = 0;
  for (const auto& h : r.headings) unsettled += h.flown == HeadingFlown::UntilDeadline ? 1 : 0;
  if (!r.decided) {
    out << "  deadline " << std::setprecision(3) << o.deadline
        << " s reached: " << detail::count_noun(unsettled, "heading") << " not settled\n";
  }
  if (r.safe) {
    out << "  decision: land at (" << o.landing_point.x() << ", " << o.landing_point.y() << "), heading "
        << std::setprecision(1) << rad_to_deg(best->yaw) << " deg (S = " << std::setprecision(3) << best->score
        << " rad, threshold " << r.threshold.value() << " rad"
        << (r.decided ? "" : "; complete and safe, not proven the best") << ")\n";
  } else if (!r.decided) {
    out << "  decision: do not land at (" << o.landing_point.x() << ", " << o.landing_point.y()
        << "): no heading settled safe by the deadline\n";
  } else {
    out << "  decision: do not land at (" << o.landing_point.x() << ", " << o.landing_point.y()
        << "): no safe heading (" << unsafe_summary(r) << ")";
    if (best) {
      out << "; lowest S " << std::setprecision(3) << best->score << " rad at heading " << std::setprecision(1)
          << rad_to_deg(best->yaw) << " deg";
    }
    out << "\n";
  }
  return out.str();
}

}  // namespace touchdown::twin
