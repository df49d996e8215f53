// The violation search's campaign loop (search.hpp): the GA of the RLaGA
// paper's Algorithm 1 (rlaga, diverse-ga), NSGA-II (many-objective-ga) and
// random sampling, over a results directory that a killed campaign resumes
// from. The choices the source leaves open are in docs/architecture.md,
// "The violation search".
#include "touchdown/search/search.hpp"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <fstream>
#include <limits>
#include <map>
#include <optional>
#include <set>

#include "core/io_util.hpp"
#include "search/cover_pool.hpp"
#include "search/search_io.hpp"
#include "touchdown/core/atomic_file.hpp"
#include "touchdown/core/error.hpp"
#include "touchdown/core/random.hpp"
#include "touchdown/search/causes.hpp"
#include "touchdown/search/object_policy.hpp"
#include "touchdown/search/pareto.hpp"

namespace touchdown::search {

namespace fs = std::filesystem;

// ---- options ---------------------------------------------------------------------------

namespace {

// The campaign that runs a batch (without its per-run hooks).
scenario::CampaignOptions campaign_options(const EvaluatorOptions& o) {
  scenario::CampaignOptions c;
  c.system = o.system;
  c.mls = o.mls;
  c.run = o.run;
  c.threads = o.threads;
  return c;
}

}  // namespace

bool EvaluatorOptions::validate(std::string* why) const {
  if (!campaign_options(*this).validate(why)) return false;
  if (!(decision_period > 0 && decision_period <= 10)) return invalid(why, "decision_period: must be in (0, 10] s");
  return true;
}

bool SearchOptions::validate(std::string* why) const {
  std::string w;
  if (!ga.validate(&w)) return invalid(why, "ga." + w);
  if (budget < 1) return invalid(why, "budget: must be ≥ 1");
  if (method == Method::Rlaga && weights_id.empty()) {
    return invalid(why,
                   "weights_id: rlaga moves the scenarios' objects with a DQN, and none is given (they would stand "
                   "still): give the evaluator its policy (EvaluatorOptions::policy, search::campaign_policy) and "
                   "its id here");
  }
  if (budget < ga.population) {
    return invalid(why, "budget: " + std::to_string(budget) + " is less than the population (" +
                            std::to_string(ga.population) +
                            "): the seed pool alone needs a whole population (a smaller one: ga.population, "
                            "landing_fuzz --population)");
  }
  if (!chromosome.validate(&w)) return invalid(why, "chromosome." + w);
  if (!base.validate(&w)) return invalid(why, "base." + w);
  if (!(violation_radius > 0)) return invalid(why, "violation_radius: must be > 0");
  if (diversity && method == Method::Random) return invalid(why, "diversity: needs a GA method, not random");
  if (near_miss && (method == Method::Random || method == Method::ManyObjectiveGa)) {
    return invalid(why, "near_miss: needs a method with a scalar fitness (rlaga or diverse-ga), not " +
                            std::string(to_string(method)));
  }
  if (!(min_distance >= 0 && min_distance <= 1)) return invalid(why, "min_distance: must be in [0, 1]");
  if (static_cast<std::size_t>(diversity_pool) >= EnumNames<SeedPool>::names.size()) {
    return invalid(why, "diversity_pool: unknown pool");
  }
  if (niche_capacity < 1 || niche_capacity > ga.population) {
    return invalid(why, "niche_capacity: " + std::to_string(niche_capacity) +
                            " is outside [1, population = " + std::to_string(ga.population) + "]");
  }
  return true;
}

int SearchOptions::first_generation() const {
  if (!diversity || diversity_pool != SeedPool::CoverAndSpread) return std::min(budget, ga.population);
  const int covered = static_cast<int>(detail::cover_conditions(chromosome).size());
  return std::min(budget, covered + ga.population);
}

int SearchOptions::generations() const {
  return 1 + (std::max(0, budget - first_generation()) + ga.population - 1) / ga.population;
}

ChromosomeLayout search_layout(const SearchOptions& options) {
  ChromosomeOptions c = options.chromosome;
  c.drive_objects = options.method == Method::Rlaga;
  return ChromosomeLayout(options.base, c);
}

// ---- the local evaluator ---------------------------------------------------------------

Registry<MakeEvaluator>& evaluator_registry() {
  static Registry<MakeEvaluator>* registry = [] {
    auto* r = new Registry<MakeEvaluator>("evaluator");  // never destroyed: used until exit
    r->add("local", "the scenarios of a batch on worker threads of this process",
           [](const EvaluatorOptions& o) { return std::make_unique<LocalEvaluator>(o); });
    return r;
  }();
  return *registry;
}

LocalEvaluator::LocalEvaluator(EvaluatorOptions options) : options_(std::move(options)) {
  std::string why;
  if (!options_.validate(&why)) throw InvalidArgument("evaluator options: " + why);
  (void)options_.system.make(options_.mls);  // a bad spec fails now
}

std::vector<Evaluation> LocalEvaluator::evaluate(const std::vector<scenario::Scenario>& scenarios,
                                                 const std::function<void(std::size_t, const Evaluation&)>& on_done) {
  std::vector<Evaluation> out(scenarios.size());
  scenario::CampaignOptions c = campaign_options(options_);
  if (options_.policy) {
    c.external_for = [this](std::size_t) {
      return std::function<void(const scenario::World&, std::vector<scenario::ObjectAction>&)>(
          ObjectPolicy(options_.policy, options_.decision_period));
    };
  }
  c.inspect = [&](std::size_t i, const scenario::ScenarioResult& r) {
    out[i] = evaluate_result(r, scenarios[i].time_limit);
  };
  if (on_done) {
    c.progress = [&](const Progress& p) { on_done(p.index, out[p.index]); };
  }
  (void)scenario::run_campaign(scenarios, c);
  return out;
}

// ---- the campaign ----------------------------------------------------------------------

namespace {

// Streams of the campaign's random draws: generation g's operators use
// Rng(seed, g); the d-th drawn chromosome (seed pool, random method) comes
// from Rng(seed, kDrawStream + d). None depends on how the runs are spread.
constexpr std::uint64_t kDrawStream = std::uint64_t{1} << 40;
// The diversity option's seed pool: candidates of its own stream, so that it
// is never random sampling's first draws.
constexpr std::uint64_t kDiverseStream = std::uint64_t{1} << 41;
constexpr int kDiverseCandidates = 8;  // candidates per pool member (maximin over them)
constexpr double kCleared = 0.0;       // a cleared niche member's fitness: that of an unfair violation

std::uint64_t draw_seed(std::uint64_t seed, int d) {
  Rng rng(seed, kDrawStream + static_cast<std::uint64_t>(d));
  return rng.next() >> 11;
}

std::string scenario_file(int index) {
  std::string n = std::to_string(index);
  if (n.size() < 6) n.insert(0, 6 - n.size(), '0');
  return "scenarios/" + n + ".yaml";
}

// An unfair violation (the oracle: the target was never observable long
// enough) scores as no violation with fair_fitness: 0, below any run; so
// does a run in which the system under test failed (its TTL, the time
// limit, would otherwise rank a crash above every landing, and the budget
// would go to crashing it again: the failures are counted apart instead).
bool scores_nothing(const SearchOptions& o, const Evaluation& e) {
  return e.system_failed() || ((o.fair_fitness || o.diversity) && e.violation_found() && !e.fair_violation());
}

// eq. 7's distance between two normalised chromosomes (÷ sqrt(dimension)).
double gene_distance(const std::vector<double>& a, const std::vector<double>& b) {
  double d2 = 0;
  for (std::size_t i = 0; i < a.size() && i < b.size(); ++i) d2 += (a[i] - b[i]) * (a[i] - b[i]);
  return a.empty() ? 0.0 : std::sqrt(d2 / static_cast<double>(a.size()));
}

double fitness_of(const SearchOptions& o, const Evaluation& e) {
  if (scores_nothing(o, e)) return 0.0;
  const double f = o.method == Method::Rlaga ? fitness_eq6(e, o.violation_radius) : fitness_eq1(e, o.violation_radius);
  return o.near_miss ? f + near_miss_term(e) : f;
}

std::array<double, 2> objectives_of(const SearchOptions& o, const Evaluation& e) {
  if (scores_nothing(o, e)) return {0.0, 0.0};
  return {e.dtl, e.ttl};
}

// The results directory as the campaign writes it: results.jsonl in index
// order (a finished run waits for its predecessors), scenario files before
// their runs, state.json after each generation.
class Directory {
 public:
  Directory(fs::path dir, bool resume, const std::string& config) : dir_(std::move(dir)) {
    const fs::path campaign = dir_ / "campaign.json";
    if (!resume) {
      if (fs::exists(campaign)) {
        throw InvalidArgument(dir_.string() +
                              ": holds a campaign already (campaign.json); --resume continues it, or choose another "
                              "directory");
      }
      if (fs::exists(dir_) && !fs::is_directory(dir_)) throw InvalidArgument(dir_.string() + ": not a directory");
      fs::create_directories(dir_ / "scenarios");
      write_file_atomically(campaign, [&](const fs::path& tmp) { write(tmp, config); });
      write_file_atomically(dir_ / "results.jsonl", [&](const fs::path& tmp) { write(tmp, ""); });
      fs::remove(dir_ / "state.json");
    } else {
      if (!fs::exists(campaign)) {
        throw InvalidArgument(dir_.string() + ": no campaign to resume (no campaign.json)");
      }
      const std::string difference =
          detail::config_difference(touchdown::detail::read_text_file(campaign), config, campaign.string());
      if (!difference.empty()) {
        throw InvalidArgument(campaign.string() + ": a results directory from another campaign: " + difference);
      }
      fs::create_directories(dir_ / "scenarios");
      const fs::path results = dir_ / "results.jsonl";
      if (fs::exists(results)) {
        LoadedRecords loaded = load_records_tolerant(results);
        existing_ = std::move(loaded.records);
        if (loaded.truncated_tail) {  // a line cut by the kill: drop it, the run is done again
          std::string text;
          for (const auto& r : existing_) text += record_line(r) + "\n";
          write_file_atomically(results, [&](const fs::path& tmp) { write(tmp, text); });
        }
      }
      const fs::path state = dir_ / "state.json";
      if (fs::exists(state)) state_ = detail::parse_state(touchdown::detail::read_text_file(state), state.string());
    }
    out_.open(dir_ / "results.jsonl", std::ios::binary | std::ios::app);
    if (!out_) throw IoError((dir_ / "results.jsonl").string() + ": cannot open for appending");
  }

  [[nodiscard]] const std::vector<EvaluationRecord>& existing() const { return existing_; }
  [[nodiscard]] const detail::PoolState& state() const { return state_; }

  [[nodiscard]] bool has_scenario(int index) const { return fs::exists(dir_ / scenario_file(index)); }
  [[nodiscard]] bool scenarios_complete() const {
    return std::all_of(existing_.begin(), existing_.end(),
                       [this](const EvaluationRecord& r) { return has_scenario(r.index); });
  }
  [[nodiscard]] scenario::Scenario read_scenario(int index) const {
    return scenario::load_scenario(dir_ / scenario_file(index));
  }
  void write_scenario(int index, const scenario::Scenario& s) const {
    write_file_atomically(dir_ / scenario_file(index), [&](const fs::path& tmp) { write(tmp, scenario::to_yaml(s)); });
  }
  void append(const EvaluationRecord& r) {
    out_ << record_line(r) << '\n';
    out_.flush();
    if (!out_) throw IoError((dir_ / "results.jsonl").string() + ": write failed");
  }
  void save_state(const detail::PoolState& s) const {
    write_file_atomically(dir_ / "state.json", [&](const fs::path& tmp) { write(tmp, detail::state_json(s)); });
  }

 private:
  static void write(const fs::path& path, const std::string& text) { touchdown::detail::write_text_file(path, text); }

  fs::path dir_;
  std::vector<EvaluationRecord> existing_;
  detail::PoolState state_;
  std::ofstream out_;
};

struct Individual {
  Chromosome chromosome;
  int index = 0;  // its record
};

class Campaign {
 public:
  Campaign(const SearchOptions& o, Evaluator& evaluator, Directory& dir,
           const std::function<void(const SearchProgress&)>& progress)
      : o_(o), layout_(search_layout(o)), evaluator_(evaluator), dir_(dir), progress_(progress) {
    progress_state_.generations = o.generations();
    progress_state_.budget = o.budget;
  }

  [[nodiscard]] double evaluation_s() const { return evaluation_s_; }

  std::vector<EvaluationRecord> run() {
    // state.json is a shortcut past the finished generations. A directory
    // kept without its scenario files (docs/results/table2 keeps only
    // campaign.json and results.jsonl) is replayed from
    // generation 0 instead: the same draws and operators rebuild every
    // chromosome (checked against the recorded genes), the records are read
    // back, not run, and each missing scenario file is written again.
    const detail::PoolState replay;
    const detail::PoolState& state = dir_.scenarios_complete() ? dir_.state() : replay;
    int generation = state.generation + 1;
    if (state.generation >= 0) {
      for (const auto& m : state.pool) pool_.push_back({m.chromosome, m.index});
      evaluated_ = state.evaluated;
      records_.assign(dir_.existing().begin(),
                      dir_.existing().begin() +
                          std::min<std::ptrdiff_t>(evaluated_, static_cast<std::ptrdiff_t>(dir_.existing().size())));
      if (static_cast<int>(records_.size()) != evaluated_) {
        throw InvalidArgument("results directory: state.json says " + std::to_string(evaluated_) +
                              " scenarios were evaluated, results.jsonl has " + std::to_string(dir_.existing().size()));
      }
      for (const auto& r : records_) {
        count(r, true);
        std::string cause;
        if (o_.diversity && r.evaluation.fair_violation()) {
          cause = violation_cause(r.evaluation, dir_.read_scenario(r.index));
          ++cause_counts_[cause];
        }
        causes_.push_back(std::move(cause));
      }
    }
    for (; evaluated_ < o_.budget; ++generation) {
      progress_state_.generation = generation;
      const int n = generation == 0 ? o_.first_generation() : std::min(o_.ga.population, o_.budget - evaluated_);
      std::vector<Chromosome> batch = o_.method == Method::Random ? draws(n)
                                      : generation == 0           ? seed_pool(n)
                                                                  : offspring(generation, n);
      const std::vector<Individual> evaluated = evaluate(batch, generation);
      if (o_.method != Method::Random) select(evaluated);
      detail::PoolState s;
      s.generation = generation;
      s.evaluated = evaluated_;
      for (const auto& p : pool_) s.pool.push_back({p.index, p.chromosome});
      dir_.save_state(s);
    }
    return records_;
  }

 private:
  void count(const EvaluationRecord& r, bool resumed) {
    ++progress_state_.done;
    if (resumed) ++progress_state_.resumed;
    progress_state_.type_i += r.evaluation.violation == scenario::Violation::TypeI;
    progress_state_.type_ii += r.evaluation.violation == scenario::Violation::TypeII;
    progress_state_.type_iii += r.evaluation.violation == scenario::Violation::TypeIII;
  }

  Chromosome canonical(const Chromosome& c) const { return layout_.encode(layout_.decode(c)); }

  std::vector<Chromosome> draws(int n) const {
    std::vector<Chromosome> out;
    for (int k = 0; k < n; ++k) out.push_back(layout_.draw(draw_seed(o_.seed, evaluated_ + k)));
    return out;
  }

  // Generation 0: random sampling's draws, or the diversity option's pool.
  std::vector<Chromosome> seed_pool(int n) const {
    if (!o_.diversity) return draws(n);
    if (o_.diversity_pool == SeedPool::Spread) return spread_draws(n);
    // The covering design's members, then (a population larger than its
    // conditions, or CoverAndSpread's first generation) the spread pool's.
    const int covered = std::min(n, static_cast<int>(detail::cover_conditions(layout_.options()).size()));
    std::vector<Chromosome> out;
    const auto background = o_.diversity_pool == SeedPool::Cover ? detail::Background::Benign
                            : o_.diversity_pool == SeedPool::CoverDrawn
                                ? detail::Background::Drawn
                                : detail::Background::Mixed;  // and CoverAndSpread
    for (const detail::CoverMember& m : detail::cover_pool(layout_, o_.seed, 0, covered, background)) {
      out.push_back(layout_.fit(m.scenario));
    }
    if (covered < n) {
      std::vector<Chromosome> rest = spread_draws(n - covered);
      out.insert(out.end(), rest.begin(), rest.end());
    }
    return out;
  }

  // The diversity option's seed pool: kDiverseCandidates × n draws of its own
  // stream, of which n are picked greedily farthest from those already
  // picked (maximin in normalised gene space: a space-filling pool).
  std::vector<Chromosome> spread_draws(int n) const {
    std::vector<Chromosome> candidates;
    std::vector<std::vector<double>> genes;
    for (int d = 0; d < kDiverseCandidates * n; ++d) {
      Rng rng(o_.seed, kDiverseStream + static_cast<std::uint64_t>(evaluated_ + d));
      candidates.push_back(canonical(layout_.draw(rng.next() >> 11)));
      genes.push_back(layout_.normalised(candidates.back()));
    }
    std::vector<Chromosome> out{candidates.front()};
    std::vector<double> nearest(candidates.size(), std::numeric_limits<double>::infinity());
    std::size_t last = 0;
    while (static_cast<int>(out.size()) < n) {
      std::size_t best = 0;
      for (std::size_t i = 0; i < candidates.size(); ++i) {
        nearest[i] = std::min(nearest[i], gene_distance(genes[i], genes[last]));
        if (nearest[i] > nearest[best]) best = i;
      }
      out.push_back(candidates[best]);
      last = best;
    }
    return out;
  }

  // Algorithm 1 (and NSGA-II's loop): parents by tournament from the pool,
  // adjacent pairs cross over, each child mutates; a child equal to a pool
  // member or to an earlier child is mutated again (a scenario already run
  // is not run again: ours are deterministic), at most 20 times.
  std::vector<Chromosome> offspring(int generation, int n) const {
    Rng rng(o_.seed, static_cast<std::uint64_t>(generation));
    const std::size_t parents_needed = static_cast<std::size_t>(n + (n % 2));
    std::vector<std::size_t> parents;
    if (o_.method == Method::ManyObjectiveGa) {
      std::vector<std::array<double, 2>> objectives;
      for (const auto& p : pool_)
        objectives.push_back(objectives_of(o_, records_[static_cast<std::size_t>(p.index)].evaluation));
      parents = crowded_tournament(pareto_ranking(objectives), parents_needed, rng);
    } else {
      // With the diversity option the tournaments see the pool's fitness
      // after clearing, as its selection did.
      parents = tournament_select(selection_fitness(pool_), parents_needed, rng);
      // With the near-miss term every fourth pair is drawn from the pool's
      // frontier alone (select()), so near misses breed with near misses.
      const std::vector<std::size_t> front = frontier(pool_, pool_.size());
      if (o_.near_miss && !front.empty()) {
        std::vector<double> fitness;
        for (std::size_t i : front) fitness.push_back(records_[static_cast<std::size_t>(pool_[i].index)].fitness);
        for (std::size_t k = 0; k + 1 < parents.size(); k += 8) {
          const std::vector<std::size_t> pair = tournament_select(fitness, 2, rng);
          parents[k] = front[pair[0]];
          parents[k + 1] = front[pair[1]];
        }
      }
    }
    std::vector<Chromosome> pool_chromosomes;
    for (const auto& p : pool_) pool_chromosomes.push_back(p.chromosome);
    std::vector<Chromosome> children;
    for (std::size_t k = 0; k < parents.size(); ++k) children.push_back(pool_chromosomes[parents[k]]);
    for (std::size_t k = 0; k + 1 < children.size(); k += 2) {
      (void)crossover(layout_, children[k], children[k + 1], o_.ga.crossover_threshold, rng);
    }
    children.resize(static_cast<std::size_t>(n));
    std::set<Chromosome> seen(pool_chromosomes.begin(), pool_chromosomes.end());
    const bool diverse = o_.method != Method::ManyObjectiveGa;
    // With the diversity option a child nearer than min_distance to a
    // scenario already run (or an earlier child) counts as seen too.
    std::vector<std::vector<double>> ran;
    if (o_.diversity) {
      for (const EvaluationRecord& r : records_) ran.push_back(r.genes);
    }
    const auto too_near = [&](const Chromosome& c) {
      if (seen.count(c) > 0) return true;
      if (!o_.diversity) return false;
      const std::vector<double> g = layout_.normalised(c);
      return std::any_of(ran.begin(), ran.end(),
                         [&](const std::vector<double>& r) { return gene_distance(g, r) < o_.min_distance; });
    };
    for (Chromosome& c : children) {
      if (diverse) {
        (void)mutate(layout_, c, pool_chromosomes, o_.ga, rng);
      } else {
        (void)mutate_uniform(layout_, c, o_.ga.mutation_threshold, rng);
      }
      c = canonical(c);
      for (int attempt = 0; attempt < 20 && too_near(c); ++attempt) {
        if (diverse) {
          mutate_gene(layout_, c, rng.next() % layout_.genes().size(), pool_chromosomes, o_.ga.mutation_candidates,
                      rng);
        } else {
          (void)mutate_uniform(layout_, c, -1.0, rng);  // r > -1 always: a forced redraw
        }
        c = canonical(c);
      }
      seen.insert(c);
      if (o_.diversity) ran.push_back(layout_.normalised(c));
    }
    return children;
  }

  // Runs the batch (records already in the directory are read back, not
  // run), appending each record in index order as soon as its predecessors
  // are there.
  std::vector<Individual> evaluate(const std::vector<Chromosome>& batch, int generation) {
    const int first = evaluated_;
    std::vector<scenario::Scenario> scenarios;
    std::vector<std::size_t> pending;  // batch positions to run
    std::vector<std::optional<EvaluationRecord>> done(batch.size());
    std::vector<EvaluationRecord> waiting;    // the records of `pending`, without their evaluation
    std::vector<scenario::Scenario> decoded;  // every batch member's scenario (the causes need it)
    for (std::size_t k = 0; k < batch.size(); ++k) decoded.push_back(layout_.decode(batch[k]));
    for (std::size_t k = 0; k < batch.size(); ++k) {
      const int index = first + static_cast<int>(k);
      EvaluationRecord r;
      r.index = index;
      r.generation = generation;
      r.scenario = scenario_file(index);
      r.genes = layout_.normalised(batch[k]);
      if (static_cast<std::size_t>(index) < dir_.existing().size()) {
        const EvaluationRecord& old = dir_.existing()[static_cast<std::size_t>(index)];
        if (old.genes != r.genes || old.generation != generation) {
          throw InvalidArgument("results directory: results.jsonl line " + std::to_string(index + 1) +
                                " is not this campaign's scenario " + std::to_string(index) +
                                " (the directory was changed by hand?)");
        }
        done[k] = old;
        if (!dir_.has_scenario(index)) dir_.write_scenario(index, decoded[k]);
        continue;
      }
      dir_.write_scenario(index, decoded[k]);
      scenarios.push_back(decoded[k]);
      pending.push_back(k);
      waiting.push_back(std::move(r));
    }
    std::size_t next = 0;  // the first batch position not yet written
    const auto flush = [&] {
      for (; next < batch.size() && done[next]; ++next) {
        if (first + static_cast<int>(next) >= static_cast<int>(records_.size())) {
          const bool resumed = static_cast<std::size_t>(first) + next < dir_.existing().size();
          // Novelty, in index order (the same for any completion order): a
          // fair violation whose cause was found n times before scores its
          // fitness / (1 + n).
          std::string cause;
          if (o_.diversity && done[next]->evaluation.fair_violation()) {
            cause = violation_cause(done[next]->evaluation, decoded[next]);
            int& n = cause_counts_[cause];
            if (!resumed) done[next]->fitness /= 1 + n;
            ++n;
          }
          if (!resumed) dir_.append(*done[next]);
          records_.push_back(*done[next]);
          causes_.push_back(std::move(cause));
          count(*done[next], resumed);
          if (progress_) progress_(progress_state_);
        }
      }
    };
    flush();
    if (!scenarios.empty()) {
      const auto t0 = std::chrono::steady_clock::now();
      (void)evaluator_.evaluate(scenarios, [&](std::size_t i, const Evaluation& e) {
        EvaluationRecord r = waiting[i];
        r.evaluation = e;
        r.fitness = fitness_of(o_, e);
        done[pending[i]] = std::move(r);
        flush();
      });
      evaluation_s_ += std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
    }
    flush();
    TD_ASSERT(next == batch.size());
    evaluated_ = first + static_cast<int>(batch.size());
    std::vector<Individual> out;
    for (std::size_t k = 0; k < batch.size(); ++k) out.push_back({batch[k], first + static_cast<int>(k)});
    return out;
  }

  // The near-miss frontier (SearchOptions::near_miss): of `members`, the
  // at most `n` fittest runs without a violation that had a near miss
  // (near_miss_term > 0), fittest first; empty without the option.
  std::vector<std::size_t> frontier(const std::vector<Individual>& members, std::size_t n) const {
    if (!o_.near_miss) return {};
    std::vector<double> fitness(members.size(), -std::numeric_limits<double>::infinity());
    std::size_t count = 0;
    for (std::size_t i = 0; i < members.size(); ++i) {
      const EvaluationRecord& r = records_[static_cast<std::size_t>(members[i].index)];
      if (r.evaluation.violation_found() || r.evaluation.system_failed() || !(near_miss_term(r.evaluation) > 0)) {
        continue;
      }
      fitness[i] = r.fitness;
      ++count;
    }
    return best_indices(fitness, std::min(n, count));
  }

  // The members' fitness as selection sees it: their records' fitness,
  // after clearing with the diversity option (at most niche_capacity fair
  // violations of one cause keep theirs).
  std::vector<double> selection_fitness(const std::vector<Individual>& members) const {
    std::vector<double> fitness;
    std::vector<std::string> niche;
    for (const auto& m : members) {
      fitness.push_back(records_[static_cast<std::size_t>(m.index)].fitness);
      niche.push_back(causes_[static_cast<std::size_t>(m.index)]);
    }
    return o_.diversity ? clear_niches(fitness, niche, o_.niche_capacity, kCleared) : fitness;
  }

  // The next pool: generation 0 is the pool; after it, the best of pool and
  // offspring (elitist, (μ + λ)) by fitness, or NSGA-II's survivors.
  // With the diversity option, survivors are chosen after clearing: of
  // each cause's fair violations only the niche_capacity fittest keep their
  // fitness (or objectives), the rest score 0 / (0, 0).
  void select(const std::vector<Individual>& offspring) {
    std::vector<Individual> all = pool_;
    all.insert(all.end(), offspring.begin(), offspring.end());
    const std::size_t n = std::min<std::size_t>(static_cast<std::size_t>(o_.ga.population), all.size());
    const std::vector<double> kept = selection_fitness(all);
    std::vector<std::size_t> keep;
    if (o_.method == Method::ManyObjectiveGa) {
      std::vector<std::array<double, 2>> objectives;
      for (std::size_t i = 0; i < all.size(); ++i) {
        const bool cleared =
            kept[i] == kCleared && records_[static_cast<std::size_t>(all[i].index)].fitness != kCleared;
        objectives.push_back(cleared ? std::array<double, 2>{0.0, 0.0}
                                     : objectives_of(o_, records_[static_cast<std::size_t>(all[i].index)].evaluation));
      }
      keep = nsga2_survivors(objectives, n);
    } else if (o_.near_miss) {
      // A quarter of the pool is the frontier, the rest the fittest after
      // clearing: the fair violations of distinct causes fill a pool on
      // their own (eq. 1 puts a violation above any landing), and a near
      // miss would never survive to be brought nearer.
      keep = frontier(all, static_cast<std::size_t>(o_.ga.population) / 4);
      std::vector<double> rest = kept;
      for (std::size_t k : keep) rest[k] = -std::numeric_limits<double>::infinity();
      for (std::size_t k : best_indices(rest, n - keep.size())) keep.push_back(k);
    } else {
      keep = best_indices(kept, n);
    }
    std::vector<Individual> next;
    for (std::size_t k : keep) next.push_back(all[k]);
    pool_ = std::move(next);
  }

  const SearchOptions& o_;
  ChromosomeLayout layout_;
  Evaluator& evaluator_;
  Directory& dir_;
  const std::function<void(const SearchProgress&)>& progress_;
  SearchProgress progress_state_;
  std::vector<Individual> pool_;
  std::vector<EvaluationRecord> records_;
  int evaluated_ = 0;
  double evaluation_s_ = 0;
  std::map<std::string, int> cause_counts_;  // the diversity option's: fair causes found so far
  std::vector<std::string> causes_;          // per record: its fair violation's cause with diversity, else ""
};

}  // namespace

SearchResult run_search(const SearchOptions& options, Evaluator& evaluator, const fs::path& out_dir, bool resume,
                        const std::function<void(const SearchProgress&)>& progress) {
  std::string why;
  if (!options.validate(&why)) throw InvalidArgument("search options: " + why);
  const auto t0 = std::chrono::steady_clock::now();
  // What campaign.json records is the system the evaluator runs.
  SearchOptions recorded = options;
  if (const std::string evaluated = evaluator.system_name(); !evaluated.empty()) {
    if (recorded.system.empty()) {
      recorded.system = evaluated;
    } else if (recorded.system != evaluated) {
      throw InvalidArgument("search options: system '" + recorded.system + "' is not the evaluator's system '" +
                            evaluated + "' (leave it empty to record the evaluator's)");
    }
  }
  if (recorded.system.empty()) recorded.system = "unknown";  // an evaluator of one's own that names none
  Directory dir(out_dir, resume, detail::campaign_config(recorded));
  if (static_cast<int>(dir.existing().size()) > options.budget) {
    throw InvalidArgument((out_dir / "results.jsonl").string() + ": holds " + std::to_string(dir.existing().size()) +
                          " records, more than the budget");
  }
  Campaign campaign(recorded, evaluator, dir, progress);
  SearchResult result;
  result.records = campaign.run();
  result.resumed = static_cast<int>(std::min(dir.existing().size(), result.records.size()));
  result.metrics = compute_metrics(result.records);
  result.evaluation_s = campaign.evaluation_s();
  result.wall_s = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
  return result;
}

ResultsDirectory load_results_directory(const fs::path& dir) {
  ResultsDirectory r;
  const fs::path campaign = dir / "campaign.json";
  if (!fs::is_directory(dir)) throw IoError(dir.string() + ": not a directory");
  if (!fs::exists(campaign)) throw IoError(dir.string() + ": not a results directory (no campaign.json)");
  r.campaign_json = touchdown::detail::read_text_file(campaign);
  r.records = load_records(dir / "results.jsonl");
  return r;
}

}  // namespace touchdown::search
