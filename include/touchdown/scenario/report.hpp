#pragma once
/// \file
/// The test world's reports as text, in the formats the apps write
/// (docs/formats.md, "Scenario results"): one run's result as one JSON line
/// (`landing_scenario run --json`) and its trajectory as CSV (`--log`); a
/// campaign's table (CSV, `campaign --csv`), its figures (one JSON line,
/// `campaign --json`) and its summary for a person (`campaign`). A program
/// of your own that runs scenarios writes the same files through these.
#include <string>
#include <string_view>
#include <vector>

#include "touchdown/scenario/campaign.hpp"
#include "touchdown/scenario/run.hpp"

namespace touchdown::scenario {

/// One run: outcome, violation type and message, DTL/TTL, collision,
/// descent, the detections that triggered and last re-aimed the descent,
/// occluders, the oracle's observability, every camera frame's record and
/// the timing; `scenario` and `system` name what ran. One line, no newline.
[[nodiscard]] std::string result_json(const ScenarioResult& r, std::string_view scenario, std::string_view system);

/// The same for a person: outcome and message, DTL/TTL, frames and steps,
/// the target's observable time (camera and probe) and where the time went.
/// `detector` is the system's detector kind, named when not the system's own.
/// Ends in a newline.
[[nodiscard]] std::string run_summary(const ScenarioResult& r, std::string_view scenario, MapKind map,
                                      std::string_view system, std::string_view detector);

/// Every physics step (t, position, velocity, yaw, phase) and, on the steps
/// that took a camera frame, that frame's marker area and detections. `dt`
/// is the physics step [s] (RunOptions' flight rate).
[[nodiscard]] std::string trajectory_csv(const ScenarioResult& r, double dt);

/// One row per scenario, `names[i]` naming entry i (its file or seed).
[[nodiscard]] std::string campaign_csv(const CampaignResult& c, const std::vector<std::string>& names);

/// The campaign's figures: counts and rate of each violation type, the
/// unfair Type II, the failed runs, flight and wall time. `source` names the
/// scenarios (a directory or "random, seeds A-B"). One line, no newline.
[[nodiscard]] std::string campaign_json(const CampaignResult& c, std::string_view source, const CampaignOptions& o);

/// The same figures for a person: violations by type, the first failure,
/// median DTL/TTL of the landings, and where the time went. Ends in a newline.
/// `names`: each scenario's name, as campaign_csv's (empty: its index).
[[nodiscard]] std::string campaign_summary(const CampaignResult& c, std::string_view source, const CampaignOptions& o,
                                           const std::vector<std::string>& names = {});

}  // namespace touchdown::scenario
