// The causes of violations (causes.hpp): a label per violation from its
// recorded facts and its scenario, and the distinct causes of a results
// directory.
#include "touchdown/search/causes.hpp"

#include <algorithm>
#include <array>
#include <cmath>
#include <map>
#include <utility>

#include "touchdown/core/error.hpp"
#include "touchdown/search/search.hpp"

namespace touchdown::search {

std::string object_kind(const std::string& object) {
  const auto open = object.rfind(" (");
  if (open == std::string::npos || object.back() != ')') return object;
  return object.substr(open + 2, object.size() - open - 3);
}

namespace {

/// Whether the descent was aimed farther than the violation radius from the marker.
bool aimed_off(const Facts& f, const scenario::Scenario& s) {
  return f.descent_started &&
         (Eigen::Vector2d(f.descent_target[0], f.descent_target[1]) - s.marker.position).norm() > 1.5;
}

/// The label of a false detection of `on` (an object's name, or "ground").
std::string false_positive_on(const std::string& on, const scenario::Scenario& s) {
  const std::string kind = object_kind(on);
  if (kind == "lookalike") return "look-alike accepted";
  if (kind == "wrong_id") return "wrong id accepted";
  if (kind == "pattern") return "false positive on pattern";
  if (kind == "ground")
    return s.weather.ground_wetness >= 0.5 ? "false positive on the ground (glare)" : "false positive on the ground";
  return "false positive on " + kind;
}

/// Type I: what the descent was committed on; one committed on the marker
/// and re-aimed by the false detection it last accepted (run.cpp) is that
/// detection's label "while descending".
std::string false_positive(const Facts& f, const scenario::Scenario& s) {
  const std::string& on = !f.trigger.empty() ? f.trigger : f.last_accepted;
  if (on.empty() || on == "marker") {
    if (!f.last_accepted.empty() && f.last_accepted != "marker" && !aimed_off(f, s))
      return false_positive_on(f.last_accepted, s) + " while descending";
    return "estimate pulled off by false detections";
  }
  return false_positive_on(on, s);
}

/// The occluder that hid the target longest while descending; "" if none.
std::string descent_occluder(const Facts& f) {
  const OccluderFact* best = nullptr;
  for (const OccluderFact& o : f.occluders) {
    if (o.frames_descending > 0 && (!best || o.frames_descending > best->frames_descending)) best = &o;
  }
  return best ? object_kind(best->object) : std::string();
}

/// An unfair Type II: why no camera could have read the target.
std::string unfair(const Facts& f, const scenario::Scenario& s) {
  const std::string weather = dominant_weather(s.weather);
  const scenario::Weather& w = s.weather;
  // A marker under snow or leaves reads as one colour: low contrast as in
  // fog. Cover it is when the ground is covered (≥ 0.3) and the air at the
  // probe's 10 m passes more than 30 % of the light (fog and dust as the
  // renderer attenuates them: exp(−(fog + 0.05·dust)·10)).
  const bool clear_air = std::exp(-(w.fog + 0.05 * w.dust) * 10.0) > 0.3;
  const bool ground_cover = std::max(w.ground_snow, w.ground_leaves) >= 0.3;
  const bool unreadable = f.probe_failure == "low-contrast" || f.probe_failure == "noisy";
  if (f.probe_failure == "covered" || (unreadable && ground_cover && clear_air)) {
    if (w.ground_snow >= w.ground_leaves && w.ground_snow > 0) return "unfair: target covered by ground snow";
    if (w.ground_leaves > 0) return "unfair: target covered by ground leaves";
    // Cells read the wrong colour with nothing on the ground: what is in
    // the air (falling snow, rain, dust) or the light garbled the code.
    return "unfair: target not readable in " + weather;
  }
  if (f.probe_failure == "hidden") {
    // The object standing over it: a static one within its size of the marker.
    for (const scenario::StaticObject& o : s.static_objects) {
      if ((o.position - s.marker.position).norm() <= 0.5 * (o.size.head<2>().norm() + s.marker.size))
        return "unfair: target hidden by " + std::string(scenario::to_string(o.kind));
    }
    if (!f.occluders.empty()) return "unfair: target hidden by " + object_kind(f.occluders.front().object);
    return "unfair: target hidden";
  }
  if (f.probe_failure == "low-contrast" || f.probe_failure == "noisy")
    return "unfair: target not visible in " + weather;
  return "unfair: target " + f.probe_failure;
}

/// A fair Type II: the target was observable long enough, yet no landing.
std::string no_landing(const Facts& f, const scenario::Scenario& s) {
  const std::string weather = dominant_weather(s.weather);
  if (f.descent_started) {
    const std::string occluder = descent_occluder(f);
    if (!occluder.empty()) return occluder + " between camera and target during descent";
    return "descent not completed in " + weather;
  }
  if (f.longest_s + 1e-9 < f.sighting_time) {
    // The probe saw it long enough; the system's own camera did not.
    if (f.observable_s <= 0) return "target never brought into view in " + weather;
    for (const OccluderFact& o : f.occluders) {
      if (o.frames > 0) return object_kind(o.object) + " hid the target while tracking";
    }
    return "target not kept in view in " + weather;
  }
  if (f.last_accepted.empty()) return "observable target not detected in " + weather;
  return "sighting not held in " + weather;
}

// " while approaching" for a phase of the reference systems (their phase
// names: approach, search, track, descend, land; "descent" as a synonym),
// " during PHASE" for any other a system names itself (mm-mls's
// "replan-climb", a system from outside's own).
std::string while_phase(const std::string& phase) {
  static constexpr std::array<std::pair<std::string_view, std::string_view>, 6> kGerunds{{{"approach", "approaching"},
                                                                                          {"search", "searching"},
                                                                                          {"track", "tracking"},
                                                                                          {"descend", "descending"},
                                                                                          {"descent", "descending"},
                                                                                          {"land", "landing"}}};
  if (phase.empty()) return "";
  for (const auto& [verb, gerund] : kGerunds) {
    if (phase == verb) return " while " + std::string(gerund);
  }
  return " during " + phase;
}

}  // namespace

std::string violation_cause(const Evaluation& e, const scenario::Scenario& s) {
  if (!e.violation_found()) return "";
  const Facts& f = e.facts;
  if (!f.recorded) return "unknown (no facts recorded)";
  switch (e.violation) {
    case scenario::Violation::TypeIII:
      return "collision with " + object_kind(f.collided_with.empty() ? std::string("an object") : f.collided_with) +
             while_phase(f.collision_phase);
    case scenario::Violation::TypeI:
      return false_positive(f, s);
    case scenario::Violation::OffMarker:
      if (f.trigger.empty() && f.last_accepted.empty()) return "blind landing (no detection)";
      if (aimed_off(f, s)) return "descent aimed off a true detection";
      return "drift off the marker after a true detection";
    case scenario::Violation::TypeII:
      return f.fair ? no_landing(f, s) : unfair(f, s);
    case scenario::Violation::None:
    case scenario::Violation::SystemFailed:
      break;
  }
  return "";
}

std::vector<CauseCount> count_causes(const std::vector<EvaluationRecord>& records,
                                     const std::vector<scenario::Scenario>& scenarios) {
  if (scenarios.size() != records.size())
    throw InvalidArgument("count_causes: " + std::to_string(scenarios.size()) + " scenarios for " +
                          std::to_string(records.size()) + " records");
  std::vector<CauseCount> out;
  std::map<std::string, std::size_t> at;
  for (std::size_t i = 0; i < records.size(); ++i) {
    const Evaluation& e = records[i].evaluation;
    if (!e.violation_found()) continue;
    const std::string cause = violation_cause(e, scenarios[i]);
    auto [it, fresh] = at.emplace(cause, out.size());
    if (fresh) out.push_back({cause, e.fair_violation(), 0, records[i].index, records[i].scenario});
    ++out[it->second].count;
  }
  std::stable_sort(out.begin(), out.end(), [](const CauseCount& a, const CauseCount& b) {
    if (a.fair != b.fair) return a.fair;
    if (a.count != b.count) return a.count > b.count;
    return a.first_index < b.first_index;
  });
  return out;
}

std::vector<CauseCount> count_causes(const std::filesystem::path& results_dir) {
  const ResultsDirectory dir = load_results_directory(results_dir);
  std::vector<scenario::Scenario> scenarios(dir.records.size());
  for (std::size_t i = 0; i < dir.records.size(); ++i) {
    if (dir.records[i].evaluation.violation_found())
      scenarios[i] = scenario::load_scenario(results_dir / dir.records[i].scenario);
  }
  return count_causes(dir.records, scenarios);
}

int distinct_fair_causes(const std::vector<CauseCount>& causes) {
  return static_cast<int>(std::count_if(causes.begin(), causes.end(), [](const CauseCount& c) { return c.fair; }));
}

}  // namespace touchdown::search
