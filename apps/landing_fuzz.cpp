// landing_fuzz: searches the marker-landing test world for violations of a
// landing system (RLaGA paper): campaigns by the four methods (rlaga,
// diverse-ga, many-objective-ga, random) into resumable results
// directories, on threads or MPI ranks; DQN pre-training; the source's
// metrics and its Table 2 comparison; and shrinking a violation to the
// genes it needs.
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

using tsr::kWeightsFile;

// ---- shared pieces ---------------------------------------------------------------------

struct Common {
  std::string system = "opencv-mls";
  std::string detector = "aruco";
  int threads = std::max(1, static_cast<int>(std::thread::hardware_concurrency()));
};

void add_common(CLI::App& cmd, Common& c) {
  add_system_option(cmd, c.system);
  add_detector_option(cmd, c.detector);
  cmd.add_option("--threads", c.threads, "worker threads per MPI rank (0 = every core)")
      ->check(CLI::NonNegativeNumber)
      ->capture_default_str();
}

tsr::EvaluatorOptions evaluator_options(const Common& c, std::shared_ptr<const tsr::QNetwork> policy) {
  tsr::EvaluatorOptions o;
  o.system = c.system;
  o.mls.detector.kind = c.detector;
  o.threads = c.threads;
  o.policy = std::move(policy);
  return o;
}

/// The detector a campaign runs (learned-mls: always the learned one).
std::string detector_of(const Common& c) { return c.system == "learned-mls" ? "learned" : c.detector; }

std::string percent(double v) { return format_fixed(v, 1) + " %"; }

std::string optional_count(const std::optional<int>& v) { return v ? std::to_string(*v) : "not found"; }

Json metrics_json(const tsr::SearchMetrics& m) {
  Json j;
  j["evaluated"] = m.evaluated;
  j["violations"] = m.violations;
  j["violation_percent"] = round3(m.violation_percent);
  j["type_i"] = m.type_i;
  j["type_ii"] = m.type_ii;
  j["type_iii"] = m.type_iii;
  j["off_marker"] = m.off_marker;
  j["unfair"] = m.unfair;
  j["system_failed"] = m.system_failed;
  j["top_10"] = m.top_k ? Json(*m.top_k) : Json(nullptr);
  j["rounds_all_types"] = m.rounds_all_types ? Json(*m.rounds_all_types) : Json(nullptr);
  j["parameter_distance"] = round3(m.parameter_distance);
  j["coverage_cells"] = m.coverage_cells;
  return j;
}

// Raw (the source's definition) and, when the records carry their facts,
// fair (issue 52: a Type II whose target was never observable long enough
// is not the system's doing).
void print_metrics(const tsr::SearchMetrics& m, const std::optional<tsr::SearchMetrics>& fair = std::nullopt) {
  std::cout << "evaluated          " << m.evaluated << " scenarios\n"
            << "violations         " << m.violations << " (" << percent(m.violation_percent) << "): type I " << m.type_i
            << ", type II " << m.type_ii << ", type III " << m.type_iii << ", off-marker " << m.off_marker << "\n";
  if (m.system_failed > 0) {
    std::cout << "system failed      " << m.system_failed
              << " runs (the system under test threw or answered garbage: not violations, results.jsonl says why)\n";
  }
  if (fair && fair->facts_recorded) {
    std::cout << "fair violations    " << fair->violations << " (" << percent(fair->violation_percent) << "): type II "
              << fair->type_ii << "; " << m.unfair << " unfair (target never observable long enough)\n";
  } else if (fair) {
    std::cout << "fair violations    n/a (results written before the observability oracle)\n";
  }
  std::cout << "top-10             " << optional_count(m.top_k) << " (scenarios evaluated until the 10th violation)\n"
            << "all three types    " << optional_count(m.rounds_all_types) << " (scenarios evaluated until found)\n"
            << "parameter distance " << format_fixed(m.parameter_distance, 3)
            << " (mean pairwise, normalised genes of the violations)\n"
            << "3-D coverage       " << m.coverage_cells << " cells of 2 m visited by violating runs\n";
}

// The DQN that drives the objects of an rlaga campaign (the library's
// campaign_policy): --weights, else the directory's copy when resuming, else
// pre-trained now (deterministic for the seed).
tsr::CampaignPolicy campaign_policy(const std::string& weights_path, const fs::path& dir, bool resume, int episodes,
                                    std::uint64_t seed, bool quiet) {
  return tsr::campaign_policy(weights_path, dir, resume, episodes, seed, [&] {
    if (!quiet) std::cerr << "pre-training the DQN (" << episodes << " surrogate episodes, seed " << seed << ")\n";
  });
}

void keep_weights(const std::shared_ptr<const tsr::QNetwork>& policy, const fs::path& dir) {
  if (policy) tsr::keep_weights(*policy, dir);
}

// ---- campaign --------------------------------------------------------------------------

struct CampaignArgs {
  Common common;
  tsr::SearchOptions search;
  ts::MapKind map = ts::MapKind::Ground;
  std::string out, weights, base_path;
  int episodes = 800;
  bool resume = false, json = false, source_chromosome = false;
};

CLI::App* add_campaign_command(CLI::App& app, CampaignArgs& a) {
  auto* cmd = app.add_subcommand("campaign", "search for violations: one method, one map, one seed");
  add_enum_option(*cmd, "--method", a.search.method, "search method: " + td::enum_names_list<tsr::Method>());
  add_common(*cmd, a.common);
  add_enum_option(*cmd, "--map", a.map, "map: " + td::enum_names_list<ts::MapKind>());
  cmd->add_option("--budget", a.search.budget, "scenarios to evaluate")
      ->check(CLI::Range(1, 1000000))
      ->capture_default_str();
  cmd->add_option("--population", a.search.ga.population, "GA population (and batch size)")
      ->check(CLI::Range(2, 10000))
      ->capture_default_str();
  add_seed_option(*cmd, "--seed", a.search.seed, "campaign seed (seed pool, operators, DQN pre-training)");
  cmd->add_option("--out", a.out, "results directory (created; must not hold another campaign)")->required();
  cmd->add_flag("--resume", a.resume, "continue the campaign in --out where it stopped");
  cmd->add_option("--weights", a.weights,
                  "rlaga: DQN weights file (default: pre-train now; the directory keeps a copy, " +
                      std::string(kWeightsFile) + ")")
      ->check(td::app::existing_file())
      ->default_str("pre-train");
  cmd->add_option("--episodes", a.episodes, "rlaga without --weights: surrogate pre-training episodes")
      ->check(CLI::Range(1, 1000000))
      ->capture_default_str();
  cmd->add_option("--base", a.base_path,
                  "scenario giving every field that is not a gene (marker type, drone start, time limit; default: "
                  "the built-in one)")
      ->check(td::app::existing_file())
      ->default_str("built-in");
  cmd->add_flag("--source-chromosome", a.source_chromosome,
                "the source's chromosome: no static-object and distractor genes");
  cmd->add_flag("--fair-fitness", a.search.fair_fitness,
                "unfair violations (the target never observable long enough) score as no violation");
  auto* diversity = cmd->add_flag(
      "--diversity", a.search.diversity,
      "distinct defects: a spread seed pool, repeated causes score less and fill at most --niche-capacity "
      "places of the pool, near-duplicates are not run");
  // Issue 58, item 6: an option that does not apply is refused, not ignored.
  cmd->add_option("--min-distance", a.search.min_distance,
                  "--diversity: a child nearer than this (normalised genes) to a scenario run is mutated again")
      ->check(CLI::Range(0.0, 1.0))
      ->capture_default_str()
      ->needs(diversity);
  cmd->add_option("--niche-capacity", a.search.niche_capacity,
                  "--diversity: fair violations of one cause that keep their fitness in the pool (clearing)")
      ->check(CLI::PositiveNumber)
      ->capture_default_str()
      ->needs(diversity);
  cmd->add_flag("--json", a.json, "the metrics as one JSON object on stdout");
  return cmd;
}

// The search's progress: scenarios of the budget, with the generation and
// the violations so far (a bar on a terminal, lines off one).
std::string search_detail(const tsr::SearchProgress& p) {
  return "generation " + std::to_string(p.generation + 1) + "/" + std::to_string(p.generations) + " · violations I " +
         std::to_string(p.type_i) + " · II " + std::to_string(p.type_ii) + " · III " + std::to_string(p.type_iii);
}

int campaign_command(CampaignArgs& a, const tsr::MpiSession& mpi) {
  a.search.system = a.common.system;
  a.search.detector = detector_of(a.common);
  a.search.base = a.base_path.empty() ? ts::Scenario{} : ts::load_scenario(a.base_path);
  a.search.base.map = a.map;
  if (a.source_chromosome) a.search.chromosome = tsr::ChromosomeOptions::source();
  std::string why;
  if (!a.search.validate(&why)) throw td::InvalidArgument(why);  // before any rank starts serving
  const fs::path dir = a.out;
  const bool rank0 = mpi.rank() == 0;
  require_parent_directory(a.out, "--out");
  if (rank0 && !a.resume && fs::exists(dir / "campaign.json")) {
    throw td::InvalidArgument(a.out +
                              ": holds a campaign already (campaign.json); --resume continues it, or "
                              "choose another --out");
  }
  std::shared_ptr<const tsr::QNetwork> policy;
  if (a.search.method == tsr::Method::Rlaga) {
    const tsr::CampaignPolicy p =
        campaign_policy(a.weights, dir, a.resume, a.episodes, a.search.seed, !rank0 || a.json);
    policy = p.network;
    a.search.weights_id = p.id;
  }
  cv::setNumThreads(1);  // the campaign's threads are the parallelism
  const tsr::EvaluatorOptions eo = evaluator_options(a.common, policy);
  tsr::register_mpi_evaluator();
  const std::unique_ptr<tsr::Evaluator> evaluator =
      tsr::evaluator_registry().get(mpi.size() > 1 ? "mpi" : "local").factory(eo);
  if (!evaluator->coordinator()) {
    evaluator->serve();
    return kExitOk;
  }
  ProgressBar line("landing_fuzz", "scenarios");
  tsr::SearchResult r;
  try {
    r = tsr::run_search(a.search, *evaluator, dir, a.resume, [&](const tsr::SearchProgress& p) {
      line.draw(static_cast<std::size_t>(p.done), static_cast<std::size_t>(p.budget), search_detail(p));
    });
  } catch (...) {
    line.close();
    throw;
  }
  line.close();
  keep_weights(policy, dir);
  if (a.json) {
    Json j;
    j["directory"] = a.out;
    j["method"] = tsr::to_string(a.search.method);
    j["system"] = a.search.system;
    j["map"] = ts::to_string(a.map);
    j["seed"] = a.search.seed;
    j["resumed"] = r.resumed;
    j["metrics"] = metrics_json(r.metrics);
    j["fair_metrics"] = metrics_json(tsr::compute_metrics(r.records, 10, tsr::Count::Fair));
    j["wall_s"] = round3(r.wall_s);
    j["evaluation_s"] = round3(r.evaluation_s);
    j["search_s"] = round3(r.search_s());
    std::cout << j.dump() << "\n";
  } else {
    std::cout << "campaign           " << tsr::to_string(a.search.method) << " on " << a.search.system << ", map "
              << ts::to_string(a.map) << ", seed " << a.search.seed << " -> " << a.out << "\n";
    print_metrics(r.metrics, tsr::compute_metrics(r.records, 10, tsr::Count::Fair));
    std::cout << "time               " << format_fixed(r.wall_s, 1) << " s wall on " << mpi.size() << " x "
              << td::resolve_threads(a.common.threads) << " threads"
              << (r.resumed > 0 ? " (" + std::to_string(r.resumed) + " resumed)" : "") << "; the search's own work "
              << format_fixed(r.search_s(), 2) << " s ("
              << format_fixed(r.wall_s > 0 ? 100 * r.search_s() / r.wall_s : 0.0, 2) << " %)\n";
  }
  return kExitOk;
}

// ---- train-dqn -------------------------------------------------------------------------

struct TrainArgs {
  int episodes = 800;
  std::uint64_t seed = 1;
  std::string out;
  bool json = false;
};

CLI::App* add_train_command(CLI::App& app, TrainArgs& a) {
  auto* cmd = app.add_subcommand("train-dqn", "pre-train the objects' DQN in the surrogate environment");
  cmd->add_option("--episodes", a.episodes, "surrogate episodes")->check(CLI::Range(1, 1000000))->capture_default_str();
  add_seed_option(*cmd, "--seed", a.seed, "training seed");
  cmd->add_option("-o,--output", a.out, "weights file to write (docs/formats.md, \"DQN weights file\")")->required();
  cmd->add_flag("--json", a.json, "the summary as one JSON object on stdout");
  return cmd;
}

int train_command(const TrainArgs& a) {
  td::StagedOutputs staged;
  const fs::path tmp = staged.add(a.out, "--output");
  ProgressBar bar("landing_fuzz", "episodes");
  const auto t0 = std::chrono::steady_clock::now();
  tsr::DqnTraining t = tsr::train_dqn(tsr::DqnOptions{}, tsr::SurrogateOptions{}, a.episodes, a.seed,
                                      [&](const td::Progress& p) { bar.draw(p.done, p.total); });
  const double wall = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
  write_text(tmp, tsr::weights_text(t.network), a.out);
  staged.commit();
  const std::size_t n = t.episode_returns.size(), last = std::min<std::size_t>(100, n);
  double mean_last = 0;
  for (std::size_t i = n - last; i < n; ++i) mean_last += t.episode_returns[i] / static_cast<double>(last);
  if (a.json) {
    Json j;
    j["weights"] = a.out;
    j["episodes"] = a.episodes;
    j["seed"] = a.seed;
    j["mean_return_last_100"] = round3(mean_last);
    j["wall_s"] = round3(wall);
    std::cout << j.dump() << "\n";
  } else {
    std::cout << "weights   " << a.out << " (" << t.network.parameter_count() << " parameters, 2 x "
              << t.network.hidden() << " hidden units)\n"
              << "training  " << a.episodes << " surrogate episodes, seed " << a.seed << ", in "
              << format_fixed(wall, 1) << " s\n"
              << "return    " << format_fixed(mean_last, 2) << " (eq. 5, mean of the last " << last << " episodes)\n";
  }
  return kExitOk;
}

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

CLI::App* add_compare_command(CLI::App& app, CompareArgs& a) {
  auto* cmd = app.add_subcommand(
      "compare", "the source's Table 2: every method on every map over seeds 1..N (resumable campaigns in --out)");
  cmd->add_option("--methods", a.methods,
                  "methods; a method with '+diversity' runs with the diversity option (e.g. rlaga+diversity)")
      ->check(CLI::Validator(
          [](std::string& m) -> std::string {
            std::string base = m.substr(0, m.find('+'));
            const std::string extra = m.substr(base.size());
            if (!extra.empty() && extra != "+diversity") return "unknown option '" + extra + "' (only +diversity)";
            if (base == "random" && !extra.empty()) return "random has no +diversity";
            return one_of<tsr::Method>()(base);
          },
          "METHOD[+diversity]"))
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
      o.method = td::from_string<tsr::Method>(cell.method.substr(0, cell.method.find('+')));
      o.diversity = cell.method.find("+diversity") != std::string::npos;
      o.system = a.common.system;
      o.detector = detector_of(a.common);
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

// ---- shrink ----------------------------------------------------------------------------

struct ShrinkArgs {
  Common common;
  std::string input, out, weights;
  int index = -1;
  bool json = false;
};

CLI::App* add_shrink_command(CLI::App& app, ShrinkArgs& a) {
  auto* cmd = app.add_subcommand(
      "shrink",
      "why did it fail: reset genes to benign values while the violation stays; the smallest failing "
      "scenario and the genes it needs");
  cmd->add_option("INPUT", a.input, "a results directory (its campaign's system and weights) or a scenario file")
      ->required();
  cmd->add_option("--index", a.index, "results directory: the scenario's index (default: the first violation)")
      ->check(CLI::Range(0, 100000000));
  add_common(*cmd, a.common);
  cmd->add_option("--weights", a.weights, "scenario file: DQN weights driving its external objects")
      ->check(td::app::existing_file());
  cmd->add_option("-o,--output", a.out, "the smallest failing scenario (YAML)")
      ->required()
      ->check(output_extension(".yaml"));
  cmd->add_flag("--json", a.json, "the result as one JSON object on stdout");
  return cmd;
}

int shrink_command(ShrinkArgs& a) {
  td::StagedOutputs staged;
  const fs::path tmp = staged.add(a.out, "--output");
  ts::Scenario scenario, base;
  std::string source = a.input;
  std::shared_ptr<const tsr::QNetwork> policy;
  if (!fs::is_directory(a.input) && a.index >= 0) {
    throw td::InvalidArgument("--index: picks a scenario of a results directory; " + a.input +
                              " is a scenario file (issue 58: an option that does not apply is refused)");
  }
  if (!a.weights.empty()) policy = std::make_shared<const tsr::QNetwork>(tsr::load_weights(a.weights));
  if (fs::is_directory(a.input)) {
    const tsr::ResultsDirectory d = tsr::load_results_directory(a.input);
    const Json campaign = Json::parse(d.campaign_json);
    const tsr::EvaluationRecord* pick = nullptr;
    for (const auto& r : d.records) {
      if (a.index >= 0 ? r.index == a.index : r.evaluation.violation_found()) {
        pick = &r;
        break;
      }
    }
    if (!pick) {
      throw td::InvalidArgument(
          a.input + ": " +
          (a.index >= 0 ? "no scenario with index " + std::to_string(a.index) : std::string("no violation to shrink")));
    }
    source = (fs::path(a.input) / pick->scenario).string();
    scenario = ts::load_scenario(source);
    base = ts::parse_scenario(campaign.at("base_scenario").dump(), a.input + "/campaign.json: base_scenario");
    a.common.system = campaign.value("system", a.common.system);
    a.common.detector = campaign.value("detector", std::string("aruco"));
    const fs::path stored = fs::path(a.input) / kWeightsFile;
    if (!policy && fs::exists(stored)) policy = std::make_shared<const tsr::QNetwork>(tsr::load_weights(stored));
  } else {
    scenario = ts::load_scenario(a.input);
    base.map = scenario.map;
  }
  cv::setNumThreads(1);
  tsr::LocalEvaluator evaluator(evaluator_options(a.common, policy));
  ProgressBar bar("landing_fuzz", "evaluations");
  const tsr::ShrinkResult r =
      tsr::shrink(scenario, base, evaluator, [&](const td::Progress& p) { bar.draw(p.done, p.total); });
  bar.close();
  if (!r.ok()) {
    throw td::InvalidArgument(source + ": not a violation on " + a.common.system + " (" + r.message +
                              "): nothing to shrink");
  }
  write_text(tmp, ts::to_yaml(r.smallest), a.out);
  staged.commit();
  if (a.json) {
    Json j;
    j["scenario"] = source;
    j["system"] = a.common.system;
    j["violation"] = ts::to_string(r.violation);
    j["message"] = r.message;
    j["necessary"] = r.necessary;
    Json steps = Json::array();
    for (const auto& s : r.steps) {
      steps.push_back({{"gene", s.gene},
                       {"tried", s.tried},
                       {"outcome", ts::to_string(s.outcome)},
                       {"kept", s.kept},
                       {"message", s.message}});
    }
    j["steps"] = std::move(steps);
    j["smallest"] = a.out;
    j["runs"] = r.runs();
    std::cout << j.dump() << "\n";
  } else {
    std::cout << "scenario   " << source << " on " << a.common.system << ": type " << ts::to_string(r.violation) << " ("
              << r.message << ")\n";
    for (const auto& s : r.steps) {
      std::cout << "  reset " << s.gene << ": "
                << (!s.tried ? s.message
                             : (s.kept ? "still type " + std::string(ts::to_string(s.outcome)) + ", kept"
                                       : "now " +
                                             (s.outcome == ts::Violation::None
                                                  ? std::string("no violation")
                                                  : "type " + std::string(ts::to_string(s.outcome))) +
                                             ": needed"))
                << "\n";
    }
    std::cout << "needs      ";
    for (std::size_t i = 0; i < r.necessary.size(); ++i) std::cout << (i ? ", " : "") << r.necessary[i];
    std::cout << (r.necessary.empty() ? "none of its genes (with every gene reset it still fails: the cause lies in "
                                        "the base scenario's own fields)"
                                      : "")
              << "\n"
              << "smallest   " << a.out << " (" << r.runs() << " runs)\n";
  }
  return kExitOk;
}

}  // namespace

int main(int argc, char** argv) {
  // MPI first: under mpirun every rank parses the same command line.
  const tsr::MpiSession mpi(argc, argv);
  CLI::App app{
      "Search the marker-landing test world for violations of a landing system (RLaGA): campaigns, DQN "
      "pre-training, metrics, the source's comparison, and shrinking a violation to its causes.",
      "landing_fuzz"};
  app.require_subcommand(1);
  CampaignArgs campaign_args;
  TrainArgs train_args;
  MetricsArgs metrics_args;
  CompareArgs compare_args;
  ShrinkArgs shrink_args;
  CausesArgs causes_args;
  auto* campaign_cmd = add_campaign_command(app, campaign_args);
  auto* train_cmd = add_train_command(app, train_args);
  auto* metrics_cmd = add_metrics_command(app, metrics_args);
  auto* compare_cmd = add_compare_command(app, compare_args);
  auto* causes_cmd = add_causes_command(app, causes_args);
  add_shrink_command(app, shrink_args);
  const int code = run(app, argc, argv, [&]() -> int {
    if (*campaign_cmd) return campaign_command(campaign_args, mpi);
    if (mpi.size() > 1) throw td::InvalidArgument("only `campaign` runs on several MPI ranks");
    if (*train_cmd) return train_command(train_args);
    if (*metrics_cmd) return metrics_command(metrics_args);
    if (*compare_cmd) return compare_command(compare_args);
    if (*causes_cmd) return causes_command(causes_args);
    return shrink_command(shrink_args);
  });
  // An error on one rank that the others may not see (rank 0's results
  // directory) must not leave them waiting.
  if (code != kExitOk && mpi.size() > 1) mpi.abort(code);
  return code;
}
