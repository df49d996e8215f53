// landing_fuzz metrics, causes and compare: a results directory's figures,
// its violations' causes, and the source's Table 2 over campaigns.
#include <algorithm>
#include <cmath>
#include <cstdint>
#include <filesystem>
#include <iostream>
#include <memory>
#include <nlohmann/json.hpp>
#include <opencv2/core.hpp>
#include <optional>
#include <sstream>
#include <string>
#include <thread>
#include <vector>

#include "app_common.hpp"
#include "core/io_util.hpp"
#include "landing_fuzz.hpp"
#include "system_option.hpp"
#include "touchdown/core/atomic_file.hpp"
#include "touchdown/search/campaign_policy.hpp"
#include "touchdown/search/causes.hpp"
#include "touchdown/search/compare.hpp"
#include "touchdown/search/dqn.hpp"
#include "touchdown/search/metrics.hpp"
#include "touchdown/search/mpi_evaluator.hpp"
#include "touchdown/search/search.hpp"
#include "touchdown/search/shrink.hpp"
#include "touchdown/search/surrogate.hpp"

namespace {

namespace td = touchdown;
namespace ts = touchdown::scenario;
namespace tsr = touchdown::search;
namespace fs = std::filesystem;
using Json = nlohmann::ordered_json;
using namespace touchdown::app;
using namespace touchdown::app::fuzz_app;
using tsr::kWeightsFile;

// ---- metrics ---------------------------------------------------------------------------

struct MetricsArgs {
  std::string dir;
  bool json = false;
};

CLI::App* add_metrics_command(CLI::App& app, MetricsArgs& a) {
  auto* cmd = app.add_subcommand("metrics", "the source's metrics of a results directory");
  cmd->add_option("RESULT_DIR", a.dir, "results directory of a campaign")->required();
  cmd->add_flag("--json", a.json, "the metrics as one JSON object on stdout");
  return cmd;
}

int metrics_command(const MetricsArgs& a) {
  const tsr::ResultsDirectory d = tsr::load_results_directory(a.dir);
  const tsr::SearchMetrics m = tsr::compute_metrics(d.records);
  const tsr::SearchMetrics fair = tsr::compute_metrics(d.records, 10, tsr::Count::Fair);
  const std::vector<tsr::CauseCount> causes = tsr::count_causes(a.dir);
  const Json campaign = Json::parse(d.campaign_json);
  if (a.json) {
    Json j;
    j["directory"] = a.dir;
    j["campaign"] = {{"method", campaign.value("method", "")},
                     {"system", campaign.value("system", "")},
                     {"map", campaign.value("map", "")},
                     {"budget", campaign.value("budget", 0)},
                     {"seed", campaign.value("seed", 0)}};
    j["metrics"] = metrics_json(m);
    j["fair_metrics"] = fair.facts_recorded ? metrics_json(fair) : Json(nullptr);
    j["distinct_fair_causes"] = fair.facts_recorded ? Json(tsr::distinct_fair_causes(causes)) : Json(nullptr);
    std::cout << j.dump() << "\n";
  } else {
    std::cout << "campaign           " << campaign.value("method", "") << " on " << campaign.value("system", "")
              << ", map " << campaign.value("map", "") << ", seed " << campaign.value("seed", 0) << ", "
              << d.records.size() << " of " << campaign.value("budget", 0) << " scenarios\n";
    print_metrics(m, fair);
    if (fair.facts_recorded) {
      std::cout << "distinct causes    " << tsr::distinct_fair_causes(causes) << " fair, "
                << causes.size() - static_cast<std::size_t>(tsr::distinct_fair_causes(causes))
                << " unfair (landing_fuzz causes " << a.dir << ")\n";
    }
  }
  return kExitOk;
}

// ---- causes ----------------------------------------------------------------------------

struct CausesArgs {
  std::string dir;
  bool json = false;
};

CLI::App* add_causes_command(CLI::App& app, CausesArgs& a) {
  auto* cmd = app.add_subcommand("causes", "the distinct causes of a results directory's violations, with counts");
  cmd->add_option("RESULT_DIR", a.dir, "results directory of a campaign")->required();
  cmd->add_flag("--json", a.json, "the causes as one JSON object on stdout");
  return cmd;
}

int causes_command(const CausesArgs& a) {
  const std::vector<tsr::CauseCount> causes = tsr::count_causes(a.dir);
  if (a.json) {
    Json rows = Json::array();
    for (const tsr::CauseCount& c : causes) {
      rows.push_back({{"cause", c.cause},
                      {"fair", c.fair},
                      {"count", c.count},
                      {"first_index", c.first_index},
                      {"scenario", c.scenario}});
    }
    Json j;
    j["directory"] = a.dir;
    j["distinct_fair_causes"] = tsr::distinct_fair_causes(causes);
    j["causes"] = std::move(rows);
    std::cout << j.dump() << "\n";
    return kExitOk;
  }
  const int fair = tsr::distinct_fair_causes(causes);
  std::cout << a.dir << ": " << count_noun(fair, "distinct fair cause") << ", "
            << count_noun(static_cast<int>(causes.size()) - fair, "unfair one") << "\n";
  std::size_t width = 5;
  for (const tsr::CauseCount& c : causes) width = std::max(width, c.cause.size());
  for (const tsr::CauseCount& c : causes) {
    std::string count = std::to_string(c.count);
    count.insert(0, count.size() < 4 ? 4 - count.size() : 0, ' ');
    std::string cause = c.cause;
    cause.append(width - cause.size(), ' ');
    std::cout << count << "  " << cause << "  e.g. " << (fs::path(a.dir) / c.scenario).string() << "\n";
  }
  if (!causes.empty())
    std::cout << "replay one: landing_scenario run " << (fs::path(a.dir) / causes.front().scenario).string() << "\n";
  return kExitOk;
}

// ---- compare ---------------------------------------------------------------------------

struct CompareArgs {
  Common common;
  std::vector<std::string> methods{"rlaga", "diverse-ga", "many-objective-ga", "random"};
  std::vector<std::string> maps{"ground", "lawn"};
  int seeds = 3, budget = 300, population = 20, episodes = 800;
  std::string out, plot, weights;
  bool json = false;
};

// A compare method: its base and the options after '+' (rlaga+cover+near-miss).
struct MethodSpec {
  std::string base;
  bool diversity = false, near_miss = false;
  /// '+cover', '+cover-drawn', '+cover-mixed' or '+cover-and-spread' (each implies the diversity option)
  std::optional<tsr::SeedPool> pool;
  std::string error;  ///< empty: valid (the base is checked apart)
};

MethodSpec parse_method_spec(const std::string& m) {
  MethodSpec spec;
  spec.base = m.substr(0, m.find('+'));
  std::size_t at = spec.base.size();
  while (at < m.size()) {
    const std::size_t next = m.find('+', at + 1);
    const std::string option = m.substr(at + 1, next == std::string::npos ? std::string::npos : next - at - 1);
    const auto& pools = td::EnumNames<tsr::SeedPool>::names;
    if (option != "spread" && std::find(pools.begin(), pools.end(), option) != pools.end()) {
      const auto pool = td::from_string<tsr::SeedPool>(option);
      if (spec.pool) {
        spec.error = spec.pool == pool ? "'+" + option + "' given twice"
                                       : "'+" + std::string(td::enum_name(*spec.pool)) + "' and '+" + option +
                                             "' are two seed pools: give one";
        return spec;
      }
      spec.pool = pool;
      at = next == std::string::npos ? m.size() : next;
      continue;
    }
    bool* flag = option == "diversity" ? &spec.diversity : option == "near-miss" ? &spec.near_miss : nullptr;
    if (!flag) {
      spec.error = "unknown option '+" + option +
                   "' (+diversity, +cover, +cover-drawn, +cover-mixed, +cover-and-spread or +near-miss)";
      return spec;
    }
    if (*flag) {
      spec.error = "'+" + option + "' given twice";
      return spec;
    }
    *flag = true;
    at = next == std::string::npos ? m.size() : next;
  }
  if (spec.diversity && spec.pool) {
    spec.error = "'+" + std::string(td::enum_name(*spec.pool)) + "' already is the diversity option: drop '+diversity'";
  }
  const bool any = spec.diversity || spec.pool || spec.near_miss;
  if (spec.error.empty() && any && spec.base == "random") spec.error = "random has no options";
  if (spec.error.empty() && spec.near_miss && spec.base == "many-objective-ga") {
    spec.error = "many-objective-ga has no scalar fitness for '+near-miss'";
  }
  return spec;
}

CLI::App* add_compare_command(CLI::App& app, CompareArgs& a) {
  auto* cmd = app.add_subcommand(
      "compare", "the source's Table 2: every method on every map over seeds 1..N (resumable campaigns in --out)");
  cmd->add_option("--methods", a.methods,
                  "methods, each with options after '+': '+diversity' the diversity option (e.g. rlaga+diversity), "
                  "'+cover', '+cover-drawn', '+cover-mixed' or '+cover-and-spread' the diversity option with that "
                  "seed pool (--diversity-pool), "
                  "'+near-miss' the near-miss term (e.g. rlaga+cover-drawn+near-miss)")
      ->check(CLI::Validator(
          [](std::string& m) -> std::string {
            const MethodSpec spec = parse_method_spec(m);
            if (!spec.error.empty()) return spec.error;
            return one_of<tsr::Method>()(spec.base);
          },
          "METHOD[+diversity|+cover|+cover-drawn|+cover-mixed|+cover-and-spread][+near-miss]"))
      ->capture_default_str()
      ->delimiter(',');
  cmd->add_option("--maps", a.maps, "maps")->check(one_of<ts::MapKind>())->capture_default_str()->delimiter(',');
  cmd->add_option("--seeds", a.seeds, "campaign seeds 1..N per method and map")
      ->check(CLI::Range(1, 1000))
      ->capture_default_str();
  cmd->add_option("--budget", a.budget, "scenarios per campaign")->check(CLI::Range(1, 1000000))->capture_default_str();
  cmd->add_option("--population", a.population, "GA population")->check(CLI::Range(2, 10000))->capture_default_str();
  add_common(*cmd, a.common);
  cmd->add_option("--out", a.out,
                  "directory of the campaigns (MAP/METHOD/seed-K; an existing campaign there is resumed)")
      ->required();
  cmd->add_option("--weights", a.weights, "rlaga: DQN weights (default: pre-trained per seed)")
      ->check(td::app::existing_file())
      ->default_str("pre-train");
  cmd->add_option("--episodes", a.episodes, "rlaga without --weights: pre-training episodes")
      ->check(CLI::Range(1, 1000000))
      ->capture_default_str();
  cmd->add_option("--plot", a.plot, "cumulative violations against scenarios evaluated")
      ->check(output_extension(".svg"))
      ->default_str("none");
  cmd->add_flag("--json", a.json, "the table as one JSON object on stdout");
  return cmd;
}

int compare_command(const CompareArgs& a) {
  require_parent_directory(a.out, "--out");
  td::StagedOutputs staged;
  const fs::path plot_tmp = stage(staged, a.plot, "--plot");
  if (a.budget < a.population) {
    throw td::InvalidArgument("--budget " + std::to_string(a.budget) + " is less than --population " +
                              std::to_string(a.population) + ": the seed pool alone needs a whole population");
  }
  cv::setNumThreads(1);
  // Seeds outermost: a compare stopped early (or still running) has every
  // method and map at the seeds it finished. Cells stay in map, method order.
  std::vector<tsr::CompareCell> cells;
  for (const std::string& map : a.maps) {
    for (const std::string& method : a.methods) {
      tsr::CompareCell cell;
      cell.method = method;
      cell.map = map;
      cells.push_back(std::move(cell));
    }
  }
  const int total = static_cast<int>(cells.size()) * a.seeds;
  int done = 0;
  const bool terminal = ProgressBar::on_terminal();
  for (int k = 1; k <= a.seeds; ++k) {
    for (tsr::CompareCell& cell : cells) {
      tsr::SearchOptions o;
      const MethodSpec spec = parse_method_spec(cell.method);
      o.method = td::from_string<tsr::Method>(spec.base);
      o.diversity = spec.diversity || spec.pool;
      o.diversity_pool = spec.pool.value_or(tsr::SeedPool::Spread);
      o.near_miss = spec.near_miss;
      o.system = a.common.system;
      set_detector(o, a.common);
      o.budget = a.budget;
      o.ga.population = a.population;
      o.seed = static_cast<std::uint64_t>(k);
      o.base.map = td::from_string<ts::MapKind>(cell.map);
      const fs::path dir = fs::path(a.out) / cell.map / cell.method / ("seed-" + std::to_string(k));
      const bool resume = fs::exists(dir / "campaign.json");
      std::shared_ptr<const tsr::QNetwork> policy;
      if (o.method == tsr::Method::Rlaga) {
        const tsr::CampaignPolicy p = campaign_policy(a.weights, dir, resume, a.episodes, o.seed, true);
        policy = p.network;
        o.weights_id = p.id;
      }
      tsr::LocalEvaluator evaluator(evaluator_options(a.common, policy));
      if (terminal) {
        std::cerr << "[" << done + 1 << "/" << total << "] " << cell.method << " on " << cell.map << ", seed " << k
                  << "\n";
      }
      ProgressBar line("landing_fuzz", "scenarios");
      const std::string which = cell.method + " on " + cell.map + ", seed " + std::to_string(k) + " · ";
      const tsr::SearchResult r = tsr::run_search(o, evaluator, dir, resume, [&](const tsr::SearchProgress& p) {
        line.draw(static_cast<std::size_t>(p.done), static_cast<std::size_t>(p.budget),
                  (terminal ? "" : which) + search_detail(p));
      });
      line.close();
      keep_weights(policy, dir);
      cell.per_seed.push_back(r.metrics);
      cell.per_seed_fair.push_back(tsr::compute_metrics(r.records, 10, tsr::Count::Fair));
      cell.fair_causes.push_back(
          cell.per_seed_fair.back().facts_recorded ? tsr::distinct_fair_causes(tsr::count_causes(dir)) : -1);
      cell.cumulative.push_back(tsr::cumulative_violations(r.records));
      ++done;
    }
  }
  const std::string title = "Violations found: " + a.common.system + ", budget " + std::to_string(a.budget) + ", " +
                            count_noun(a.seeds, "seed");
  if (!a.plot.empty()) write_text(plot_tmp, tsr::compare_plot_svg(cells, title), a.plot);
  staged.commit();
  if (a.json) {
    Json j;
    j["system"] = a.common.system;
    j["budget"] = a.budget;
    j["population"] = a.population;
    j["seeds"] = a.seeds;
    Json rows = Json::array();
    for (const auto& c : cells) {
      Json per_seed = Json::array();
      for (std::size_t k = 0; k < c.per_seed.size(); ++k) {
        Json seed = metrics_json(c.per_seed[k]);
        const bool facts = c.per_seed_fair[k].facts_recorded;
        seed["fair"] = facts ? metrics_json(c.per_seed_fair[k]) : Json(nullptr);
        seed["distinct_fair_causes"] = facts ? Json(c.fair_causes[k]) : Json(nullptr);
        per_seed.push_back(std::move(seed));
      }
      rows.push_back({{"method", c.method}, {"map", c.map}, {"per_seed", per_seed}});
    }
    j["rows"] = std::move(rows);
    std::cout << j.dump() << "\n";
  } else {
    std::cout << title << "\n" << tsr::compare_table(cells);
  }
  return kExitOk;
}

}  // namespace

namespace touchdown::app::fuzz_app {

Subcommand add_metrics(CLI::App& app) {
  return make_subcommand<MetricsArgs>(app, add_metrics_command, metrics_command);
}

Subcommand add_causes(CLI::App& app) { return make_subcommand<CausesArgs>(app, add_causes_command, causes_command); }

Subcommand add_compare(CLI::App& app) {
  return make_subcommand<CompareArgs>(app, add_compare_command, compare_command);
}

}  // namespace touchdown::app::fuzz_app
