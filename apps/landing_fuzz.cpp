// landing_fuzz: searches the marker-landing test world for violations of a
// landing system (RLaGA paper): campaigns by the four methods (rlaga,
// diverse-ga, many-objective-ga, random) into resumable results
// directories, on threads or MPI ranks; DQN pre-training; the source's
// metrics and its Table 2 comparison; and shrinking a violation to the
// genes it needs.
//
// This file: main, the shared pieces, campaign and train-dqn; the other
// subcommands are in landing_fuzz_*.cpp (landing_fuzz.hpp).
#include "landing_fuzz.hpp"

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

namespace touchdown::app::fuzz_app {

namespace tsr = touchdown::search;
namespace fs = std::filesystem;
using Json = nlohmann::ordered_json;

// ---- shared pieces ---------------------------------------------------------------------

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

void set_detector(tsr::SearchOptions& o, const Common& c) {
  o.detector = c.system == "learned-mls" ? "learned" : c.detector;
  o.detector_model =
      o.detector == "learned" ? touchdown::scenario::learned_model_id(touchdown::scenario::default_model_path()) : "";
}

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
void print_metrics(const tsr::SearchMetrics& m, const std::optional<tsr::SearchMetrics>& fair) {
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

std::string search_detail(const tsr::SearchProgress& p) {
  return "generation " + std::to_string(p.generation + 1) + "/" + std::to_string(p.generations) + " · violations I " +
         std::to_string(p.type_i) + " · II " + std::to_string(p.type_ii) + " · III " + std::to_string(p.type_iii);
}

}  // namespace touchdown::app::fuzz_app

namespace {

namespace td = touchdown;
namespace ts = touchdown::scenario;
namespace tsr = touchdown::search;
namespace fs = std::filesystem;
using Json = nlohmann::ordered_json;
using namespace touchdown::app;
using namespace touchdown::app::fuzz_app;
using tsr::kWeightsFile;

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
  add_enum_option(*cmd, "--diversity-pool", a.search.diversity_pool,
                  "--diversity's seed pool: spread (maximin over random draws), cover (each weather, light and "
                  "object condition once at the severe end of its range, the rest benign), cover-drawn (each "
                  "condition once at its severe end, the rest of the scene as randomly drawn), cover-mixed "
                  "(cover-drawn, but a person, dog or bird condition on a benign scene, where the system descends) "
                  "or cover-and-spread (a first generation of cover-mixed's members and a population of spread "
                  "ones)")
      ->needs(diversity);
  cmd->add_flag("--near-miss", a.search.near_miss,
                "rlaga, diverse-ga: an object's nearest approach to the drone within 2 m adds up to 0.5 to the "
                "fitness, so the search climbs toward collisions");
  cmd->add_flag("--json", a.json, "the metrics as one JSON object on stdout");
  return cmd;
}

// The search's progress: scenarios of the budget, with the generation and
// the violations so far (a bar on a terminal, lines off one).
int campaign_command(CampaignArgs& a, const tsr::MpiSession& mpi) {
  a.search.system = a.common.system;
  set_detector(a.search, a.common);
  a.search.base = a.base_path.empty() ? ts::Scenario{} : ts::load_scenario(a.base_path);
  a.search.base.map = a.map;
  if (a.source_chromosome) a.search.chromosome = tsr::ChromosomeOptions::source();
  std::string why;
  // Before any rank starts serving (rlaga's weights, loaded below, have their id then).
  tsr::SearchOptions check = a.search;
  if (check.method == tsr::Method::Rlaga) check.weights_id = "(loaded below)";
  if (!check.validate(&why)) throw td::InvalidArgument(why);
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

}  // namespace

int main(int argc, char** argv) {
  namespace fa = touchdown::app::fuzz_app;
  // MPI first: under mpirun every rank parses the same command line.
  const tsr::MpiSession mpi(argc, argv);
  CLI::App app{
      "Search the marker-landing test world for violations of a landing system (RLaGA): campaigns, DQN "
      "pre-training, metrics, the source's comparison, and shrinking a violation to its causes.",
      "landing_fuzz"};
  app.require_subcommand(1);
  CampaignArgs campaign_args;
  TrainArgs train_args;
  auto* campaign_cmd = add_campaign_command(app, campaign_args);
  auto* train_cmd = add_train_command(app, train_args);
  const std::vector<Subcommand> others{fa::add_metrics(app), fa::add_compare(app), fa::add_causes(app),
                                       fa::add_shrink(app)};
  const int code = run(app, argc, argv, [&]() -> int {
    if (*campaign_cmd) return campaign_command(campaign_args, mpi);
    if (mpi.size() > 1) throw td::InvalidArgument("only `campaign` runs on several MPI ranks");
    if (*train_cmd) return train_command(train_args);
    return run_parsed(others);
  });
  // An error on one rank that the others may not see (rank 0's results
  // directory) must not leave them waiting.
  if (code != kExitOk && mpi.size() > 1) mpi.abort(code);
  return code;
}
