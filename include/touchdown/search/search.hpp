#pragma once
/// \file
/// The violation search (RLaGA paper): a campaign of `budget` scenario
/// runs that looks for violations of a landing system under test, by one
/// of four methods:
///   rlaga              the source's method: the GA of Algorithm 1 over the
///                      chromosome (Fig. 3), fitness eq. 6, and every
///                      dynamic object driven during the run by the DQN
///                      (eq. 3–5, ObjectPolicy);
///   diverse-ga         the same GA without RL (the source's ablation):
///                      fitness eq. 1, objects on their scripted motions;
///   many-objective-ga  the source's baseline: NSGA-II on (DTL, TTL), crowded
///                      tournament, the same crossover, uniform mutation;
///   random             scenarios drawn as the GA's seed pool is, no search.
///
/// A campaign writes its results directory as it goes (docs/formats.md,
/// "Violation search results directory"): campaign.json (what was asked),
/// results.jsonl (one line per evaluated scenario, in evaluation order),
/// scenarios/NNNNNN.yaml (every scenario, replayable with
/// `landing_scenario run`) and state.json (the pool after each finished
/// generation). A killed campaign resumes from it with the same final
/// results file. Every random draw comes from (seed, generation) or (seed,
/// draw index), never from a shared generator, so the results are the same
/// for any thread count and any evaluator (threads or MPI ranks).
///
/// The choices the source leaves open are in docs/architecture.md,
/// "The violation search".
#include <cstdint>
#include <filesystem>
#include <functional>
#include <memory>
#include <string>
#include <string_view>
#include <vector>

#include "touchdown/core/enum_names.hpp"
#include "touchdown/core/registry.hpp"
#include "touchdown/scenario/campaign.hpp"
#include "touchdown/search/chromosome.hpp"
#include "touchdown/search/evaluation.hpp"
#include "touchdown/search/genetic.hpp"
#include "touchdown/search/metrics.hpp"
#include "touchdown/search/records.hpp"

namespace touchdown::search {

enum class Method { Rlaga, DiverseGa, ManyObjectiveGa, Random };
/// The diversity option's seed pool (SearchOptions::diversity_pool).
enum class SeedPool { Spread, Cover, CoverDrawn, CoverMixed, CoverAndSpread };

}  // namespace touchdown::search

template <>
struct touchdown::EnumNames<touchdown::search::Method> {
  static constexpr std::array<std::string_view, 4> names{"rlaga", "diverse-ga", "many-objective-ga", "random"};
};

template <>
struct touchdown::EnumNames<touchdown::search::SeedPool> {
  static constexpr std::array<std::string_view, 5> names{"spread", "cover", "cover-drawn", "cover-mixed",
                                                         "cover-and-spread"};
};

namespace touchdown::search {

inline std::string_view to_string(Method m) { return enum_name(m); }
inline std::string_view to_string(SeedPool p) { return enum_name(p); }

class QNetwork;

/// What runs a batch of scenarios (one generation): threads in this process
/// (LocalEvaluator) or MPI ranks (mpi_evaluator.hpp). Must give the same
/// evaluations for the same scenarios, whatever runs them.
class Evaluator {
 public:
  virtual ~Evaluator() = default;
  /// Runs `scenarios` and returns one evaluation per scenario, in order.
  /// `on_done(i, e)` is called once per scenario as it finishes (in any
  /// order, one call at a time), from the thread that called evaluate() or
  /// a worker; it may throw to stop the batch (the exception propagates).
  virtual std::vector<Evaluation> evaluate(const std::vector<scenario::Scenario>& scenarios,
                                           const std::function<void(std::size_t, const Evaluation&)>& on_done) = 0;
  /// False for a worker (an MPI rank other than 0): it does not run the
  /// search but serve()s the one that does.
  [[nodiscard]] virtual bool coordinator() const { return true; }
  /// For a worker only: evaluates the coordinator's batches until it says
  /// stop (the base class has no workers and returns at once).
  virtual void serve() {}
  /// The system it evaluates (SystemFactory::name()): run_search records
  /// it and refuses a SearchOptions::system that names another; empty for
  /// an evaluator that does not say.
  [[nodiscard]] virtual std::string system_name() const { return {}; }
};

struct EvaluatorOptions {
  /// The system under test: a spec ("mm-mls", "plugin:PATH:NAME") or a
  /// factory of your own (scenario/system_registry.hpp).
  scenario::SystemFactory system;
  scenario::MlsOptions mls;
  scenario::RunOptions run;  ///< camera, flight, violation radius; callbacks must be empty
  int threads = 1;           ///< worker threads; 0 = every core (core/batch.hpp)
  /// Drives the `external` dynamic objects of every run (rlaga); null:
  /// they stay where they start.
  std::shared_ptr<const QNetwork> policy;
  double decision_period = 0.1;  ///< [s] the policy's action is held this long

  [[nodiscard]] bool validate(std::string* why) const;
};

/// Makes an evaluator from its options; throws InvalidArgument for options
/// it cannot use.
using MakeEvaluator = std::function<std::unique_ptr<Evaluator>(const EvaluatorOptions&)>;

/// The registry of evaluators (core/registry.hpp, the idiom of the test
/// world's systems): `local` (LocalEvaluator) built in; `mpi`
/// (MpiEvaluator) added by register_mpi_evaluator() of touchdown::search_mpi.
/// landing_fuzz names `mpi` under an MPI launcher, `local` otherwise.
Registry<MakeEvaluator>& evaluator_registry();

/// Runs a batch with scenario::run_campaign's worker threads.
class LocalEvaluator final : public Evaluator {
 public:
  explicit LocalEvaluator(EvaluatorOptions options);  ///< throws InvalidArgument for invalid options
  std::vector<Evaluation> evaluate(const std::vector<scenario::Scenario>& scenarios,
                                   const std::function<void(std::size_t, const Evaluation&)>& on_done) override;
  [[nodiscard]] const EvaluatorOptions& options() const { return options_; }
  [[nodiscard]] std::string system_name() const override { return options_.system.name(); }

 private:
  EvaluatorOptions options_;
};

struct SearchOptions {
  Method method = Method::Rlaga;
  /// Recorded in campaign.json: the evaluator's system (Evaluator::
  /// system_name()). Empty: taken from the evaluator ("unknown" when it
  /// names none); a different name is refused, so campaign.json never
  /// names a system that did not run.
  std::string system;
  std::string detector = "aruco";  ///< the system's marker detector, recorded likewise
  /// The learned detector's model (scenario::learned_model_id), recorded
  /// likewise so a campaign never resumes on another model; empty: none.
  std::string detector_model;
  int budget = 300;  ///< scenarios evaluated in all (≥ population)
  std::uint64_t seed = 1;
  GaOptions ga;  ///< population, thresholds, mutation candidates
  /// Gene slots. The method sets drive_objects (rlaga: true, else false).
  ChromosomeOptions chromosome;
  /// Every field that is not a gene (map, time limit, marker type, drone
  /// start); default: Scenario{} on the ground map.
  scenario::Scenario base;
  double violation_radius = 1.5;  ///< [m] scales DTL in the fitness (the evaluator's run.violation_radius)
  /// Text identifying the DQN weights (rlaga; recorded in campaign.json so
  /// that --resume refuses other weights). Empty for the other methods.
  std::string weights_id;
  /// Unfair violations (a Type II whose target the oracle never found
  /// observable long enough, Facts::fair) score as no violation: fitness 0,
  /// objectives (0, 0). Recorded in campaign.json when set.
  bool fair_fitness = false;
  /// Distinct defects instead of near-duplicates (issue 52): the seed pool is
  /// spread (maximin over 8 × population draws of its own stream, never
  /// random sampling's pool); a fair violation whose cause (causes.hpp) was
  /// found n times before scores its fitness / (1 + n), unfair ones 0 (as
  /// fair_fitness); the survivors are chosen after clearing (clear_niches):
  /// at most niche_capacity fair violations of one cause keep their
  /// fitness, the others score 0, so one easy defect cannot fill the pool;
  /// a child nearer than min_distance (eq. 7's normalised distance) to a
  /// scenario already run is mutated again, as an exact duplicate is. GA
  /// methods only. Recorded in campaign.json when set.
  bool diversity = false;
  double min_distance = 0.05;
  int niche_capacity = 2;  ///< [1, population]
  /// The diversity option's seed pool. Spread: as above. Cover: a covering
  /// design (one factor at a time at its boundary): each member a benign
  /// scene with one condition at the severe end of its range (each weather
  /// and light property; a distractor, moving object or static object of
  /// each kind by the marker), so a defect at one factor's extreme is in
  /// the first generation (cover_pool.hpp lists the rules); members beyond
  /// the conditions come from the spread pool. CoverDrawn: the same
  /// conditions, each on a randomly drawn scene instead of a benign one
  /// (the condition at its severe end, every other factor as drawn), so
  /// the first generation also holds the combinations a benign scene
  /// never shows (a look-alike in dusk, fog with a walker). CoverMixed:
  /// CoverDrawn's members, but a moving object's (person, dog, bird) on
  /// Cover's benign scene: a walk-in is a hazard only while the system
  /// descends, and a drawn scene often keeps it from descending at all, so
  /// the drawn member is neither a collision nor a near miss.
  /// CoverAndSpread: a first generation of both kinds, CoverMixed's members
  /// and then a population of the spread pool's (first_generation() runs,
  /// 40 for the default chromosome and population), from which selection
  /// keeps a population: a system that handles every single condition
  /// still leaves the search scenes with many conditions to breed. Recorded
  /// in campaign.json when not Spread (absent: Spread, so campaigns from
  /// before it resume).
  SeedPool diversity_pool = SeedPool::Spread;
  /// The near-miss term (issue 52's collisions): a run that scores at all
  /// gains near_miss_weight × (1 − d / near_miss_range) when an object came
  /// within d < near_miss_range of the drone in flight (Facts::nearest_m;
  /// 0 at a collision), so that selection climbs toward collisions, which
  /// eq. 1's DTL and TTL do not see; the weight (0.5) makes a near
  /// miss worth half of one violation threshold's term. Because eq. 1 puts
  /// any violation above any landing, a quarter of each next pool is kept
  /// for the frontier (the fittest runs without a violation that had a
  /// near miss) and every fourth pair of parents is drawn from it, so near
  /// misses breed with near misses and can be brought nearer. GA methods
  /// with a scalar fitness (rlaga, diverse-ga). Recorded in campaign.json
  /// when set.
  bool near_miss = false;

  [[nodiscard]] bool validate(std::string* why) const;
  /// Generations the budget allows: 1 + ceil((budget − first_generation())
  /// / population), the seed pool counting as generation 0.
  [[nodiscard]] int generations() const;
  /// Runs in generation 0: the population, or with the diversity option's
  /// CoverAndSpread pool its covering members (cover_conditions of the
  /// chromosome) and a population; at most the budget.
  [[nodiscard]] int first_generation() const;
};

/// Where a campaign stands, after each evaluated scenario.
struct SearchProgress {
  int generation = 0, generations = 0;
  int done = 0, budget = 0;  ///< scenarios evaluated (including those resumed from the directory)
  int type_i = 0, type_ii = 0, type_iii = 0;
  int resumed = 0;  ///< of `done`, read back from the results directory
};

struct SearchResult {
  std::vector<EvaluationRecord> records;  ///< every evaluated scenario, in order
  SearchMetrics metrics;
  int resumed = 0;    ///< records read back from the directory, not run again
  double wall_s = 0;  ///< of this call
  /// Of wall_s, the time inside Evaluator::evaluate: the runs, with each
  /// generation's idle tail (a thread that has no scenario left waits for
  /// the batch's last run: the generational GA's barrier).
  double evaluation_s = 0;
  /// The search's own work: wall_s − evaluation_s (GA operators, selection,
  /// NSGA-II, scenario files, results.jsonl, state.json, metrics). DQN
  /// inference runs inside the runs (once per object per decision, ~0.2 µs).
  [[nodiscard]] double search_s() const { return wall_s - evaluation_s; }
};

/// Runs the campaign into `out_dir`. Without `resume` the directory must not
/// hold a campaign (an empty or missing directory is fine); with `resume` it
/// must hold one with the same campaign.json (else InvalidArgument naming
/// the key that differs). Throws InvalidArgument for invalid options.
SearchResult run_search(const SearchOptions& options, Evaluator& evaluator, const std::filesystem::path& out_dir,
                        bool resume, const std::function<void(const SearchProgress&)>& progress = {});

/// The layout a campaign with these options searches over (its base with
/// the method's drive_objects).
ChromosomeLayout search_layout(const SearchOptions& options);

/// Reads a results directory's records (results.jsonl) and its campaign.json
/// as text (for `landing_fuzz metrics`). Throws ParseError / IoError naming
/// the file.
struct ResultsDirectory {
  std::string campaign_json;
  std::vector<EvaluationRecord> records;
};
ResultsDirectory load_results_directory(const std::filesystem::path& dir);

}  // namespace touchdown::search
