#pragma once
/// \file
/// A campaign: many scenarios, one landing system, run in parallel threads,
/// with the violation rate and type mix (the RLaGA paper's Table 1 for
/// random sampling). Scenario i of a seeded campaign is
/// random_scenario(first_seed + i, map); results are in scenario order and
/// identical for any thread count.
#include <atomic>
#include <cstddef>
#include <cstdint>
#include <functional>
#include <optional>
#include <string>
#include <vector>

#include "touchdown/core/batch.hpp"
#include "touchdown/scenario/run.hpp"
#include "touchdown/scenario/scenario.hpp"
#include "touchdown/scenario/system_registry.hpp"

namespace touchdown::scenario {

/// One scenario of a campaign: its map and its run's outcome (without the
/// trajectory and frames).
struct CampaignEntry {
  MapKind map = MapKind::Ground;
  ScenarioOutcome outcome;
};

struct CampaignOptions {
  /// The system under test: a spec ("mm-mls", "plugin:PATH:NAME") or a
  /// factory of your own; one system is made per worker thread.
  SystemFactory system;
  MlsOptions mls;
  /// Camera, flight and violation radius; its callbacks must be empty (a
  /// campaign runs scenarios concurrently).
  RunOptions run;
  int threads = 1;  ///< worker threads; 0 = every core (core/batch.hpp's rule)
  /// Called once after each scenario finishes (`index` the scenario's), from
  /// the worker thread that ran it but one call at a time (under a lock),
  /// with `done` counting up 1, 2, …, total across the calls: for a
  /// progress bar. It does not change the results (each goes to its
  /// scenario's slot). May be empty; an exception from it stops the campaign
  /// and propagates.
  ProgressCallback progress;
  /// When it becomes true no further scenario starts; the result then holds
  /// the entries [0, n) that ran. May be null.
  const std::atomic<bool>* cancel = nullptr;
  /// Per scenario, a controller for its `external` dynamic objects (the
  /// search's DQN): called once per scenario, in the worker thread that runs
  /// it, before the run; the callable it returns drives that run only (so it
  /// may keep per-run state). May be empty: the objects stay.
  std::function<std::function<void(const World&, std::vector<ObjectAction>&)>(std::size_t index)> external_for;
  /// Called in the worker thread right after scenario `index` ran, with its
  /// whole result (trajectory and frames records), concurrently for
  /// different indices: to keep more of a run than its outcome. May be empty.
  std::function<void(std::size_t index, const ScenarioResult&)> inspect;

  [[nodiscard]] bool validate(std::string* why) const;
};

struct CampaignSummary {
  int scenarios = 0;
  int violations = 0;
  int type_i = 0, type_ii = 0, type_iii = 0;
  int off_marker = 0;      ///< landed off the marker after a true detection (or none)
  int unfair_type_ii = 0;  ///< of type_ii: the target never observable long enough (oracle.hpp)
  int system_failed = 0;   ///< runs in which the system under test failed: not violations
  double flight_s = 0;     ///< simulated, summed
  Timing timing;           ///< summed over scenarios (CPU-side, per thread)
  double wall_s = 0;       ///< of the whole campaign
  [[nodiscard]] double violation_rate() const { return scenarios > 0 ? double(violations) / scenarios : 0.0; }
};

struct CampaignResult {
  std::vector<CampaignEntry> entries;  ///< in scenario order
  CampaignSummary summary;
};

/// Runs `scenarios` with a fresh system each. Throws InvalidArgument for
/// invalid options or an invalid scenario (naming its index).
CampaignResult run_campaign(const std::vector<Scenario>& scenarios, const CampaignOptions& options);

/// Scenarios random_scenario(first_seed + i[, map]) for i < count; `map`
/// empty draws the map too.
std::vector<Scenario> random_scenarios(std::uint64_t first_seed, int count, std::optional<MapKind> map);

}  // namespace touchdown::scenario
