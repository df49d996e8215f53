// Campaigns of scenario runs in parallel threads (campaign.hpp).
#include "touchdown/scenario/campaign.hpp"

#include <chrono>
#include <utility>

#include "touchdown/core/batch.hpp"
#include "touchdown/core/error.hpp"

namespace touchdown::scenario {

bool CampaignOptions::validate(std::string* why) const {
  std::string w;
  if (!run.validate(&w)) return invalid(why, "run." + w);
  if (run.on_frame || run.external) return invalid(why, "run: frame and external callbacks are not allowed");
  if (!mls.validate(&w)) return invalid(why, "mls." + w);
  if (!check_threads(threads, "threads", why)) return false;
  return true;
}

std::vector<Scenario> random_scenarios(std::uint64_t first_seed, int count, std::optional<MapKind> map) {
  if (count < 0) throw InvalidArgument("random scenarios: count must be ≥ 0");
  std::vector<Scenario> out;
  out.reserve(static_cast<std::size_t>(count));
  for (int i = 0; i < count; ++i) {
    const std::uint64_t seed = first_seed + static_cast<std::uint64_t>(i);
    out.push_back(map ? random_scenario(seed, *map) : random_scenario(seed));
  }
  return out;
}

CampaignResult run_campaign(const std::vector<Scenario>& scenarios, const CampaignOptions& options) {
  std::string why;
  if (!options.validate(&why)) throw InvalidArgument("campaign options: " + why);
  (void)options.system.make(options.mls);  // a bad spec fails before any work
  for (std::size_t i = 0; i < scenarios.size(); ++i) {
    if (!scenarios[i].validate(&why)) throw InvalidArgument("scenario " + std::to_string(i) + ": " + why);
  }
  const auto t0 = std::chrono::steady_clock::now();
  CampaignResult result;
  result.entries.resize(scenarios.size());
  // One system per worker, made by the worker on its first scenario.
  std::vector<decltype(options.system.make(options.mls))> systems(batch_workers(scenarios.size(), options.threads));
  BatchOptions batch;
  batch.threads = options.threads;
  batch.progress = options.progress;
  batch.cancel = options.cancel;
  const auto job = [&](std::size_t i, std::size_t worker) {
    auto& system = systems[worker];
    if (!system) system = options.system.make(options.mls);
    ScenarioResult r;
    if (options.external_for) {
      RunOptions run = options.run;
      run.external = options.external_for(i);
      r = run_scenario(scenarios[i], *system, run);
    } else {
      r = run_scenario(scenarios[i], *system, options.run);
    }
    if (options.inspect) options.inspect(i, r);
    CampaignEntry& e = result.entries[i];
    e.map = scenarios[i].map;
    e.outcome = std::move(static_cast<ScenarioOutcome&>(r));
  };
  const BatchReport report = run_batch(scenarios.size(), batch, job);
  result.entries.resize(report.completed);  // cancelled: the scenarios that ran

  CampaignSummary& s = result.summary;
  for (const auto& entry : result.entries) {
    const ScenarioOutcome& e = entry.outcome;
    ++s.scenarios;
    s.violations += e.violation() ? 1 : 0;
    s.type_i += e.status == Violation::TypeI ? 1 : 0;
    s.type_ii += e.status == Violation::TypeII ? 1 : 0;
    s.type_iii += e.status == Violation::TypeIII ? 1 : 0;
    s.off_marker += e.status == Violation::OffMarker ? 1 : 0;
    s.system_failed += e.status == Violation::SystemFailed ? 1 : 0;
    s.unfair_type_ii += e.status == Violation::TypeII && !e.observability.observable_long_enough() ? 1 : 0;
    s.flight_s += e.flight_s;
    s.timing.render_s += e.timing.render_s;
    s.timing.system_s += e.timing.system_s;
    s.timing.physics_s += e.timing.physics_s;
    s.timing.oracle_s += e.timing.oracle_s;
    s.timing.total_s += e.timing.total_s;
  }
  s.wall_s = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
  return result;
}

}  // namespace touchdown::scenario
