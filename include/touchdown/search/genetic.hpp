#pragma once
/// \file
/// The genetic operators of the violation search (RLaGA paper, Algorithm 1):
/// nuclear-gene crossover, the property-level max-distance mutation (eq. 2),
/// the baselines' uniform mutation, the fitness (eq. 1, eq. 6), binary
/// tournament selection and elitist survivors. The search loop that strings
/// them together lives elsewhere; every operator here is a pure function of
/// its inputs and the Rng it is handed (one stream per task), so a seed
/// reproduces a generation bit for bit.
///
/// Random draws, in order (part of the results' reproducibility):
/// crossover: r = uniform(), then (if r > threshold) the separation point;
/// mutate / mutate_uniform: r = uniform(), then (if r > threshold) the
/// gene, then its candidates' values in value order (candidate by candidate).
///
/// Thread-safety: free functions without shared state. They allocate.
#include <cstddef>
#include <string>
#include <vector>

#include "touchdown/core/random.hpp"
#include "touchdown/search/chromosome.hpp"
#include "touchdown/search/evaluation.hpp"

namespace touchdown::search {

struct GaOptions {
  int population = 20;  ///< scenarios per generation, >= 2
  /// Algorithm 1: a pair crosses over when r > threshold_c, r uniform in
  /// [0, 1) (so with probability 0.8 at the supplement's 0.2). In [0, 1].
  double crossover_threshold = 0.2;
  double mutation_threshold = 0.2;  ///< an offspring mutates when r > threshold_m; in [0, 1]
  int mutation_candidates = 10;     ///< m of eq. 2, >= 1

  /// False (with "option: what") when an option is outside its range.
  [[nodiscard]] bool validate(std::string* why) const;
};

/// Swaps the values of every nuclear gene with index >= separation between
/// a and b (whole genes: a position's x and y move together). Throws
/// InvalidArgument unless 1 <= separation < genes().size() and both have
/// the layout's length.
void crossover_at(const ChromosomeLayout& layout, Chromosome& a, Chromosome& b, std::size_t separation);
/// Algorithm 1's crossover: when r > threshold, crossover_at a separation
/// point uniform in [1, genes().size()); returns whether it crossed.
bool crossover(const ChromosomeLayout& layout, Chromosome& a, Chromosome& b, double threshold, Rng& rng);
/// eq. 2's choice: the index of the candidate whose MINIMUM Euclidean
/// distance to the pool's values is largest (maximin; ties: the first). An
/// empty pool makes every candidate equally far: 0. Throws InvalidArgument
/// for no candidates or a size mismatch.
std::size_t farthest_candidate(const std::vector<std::vector<double>>& candidates,
                               const std::vector<std::vector<double>>& pool_values);
/// eq. 2 on nuclear gene `gene` of c: `candidates` draws uniform in its
/// range (integer genes uniform over the integers), and the one farthest
/// from that gene's values across `pool` is written into c.
void mutate_gene(const ChromosomeLayout& layout, Chromosome& c, std::size_t gene, const std::vector<Chromosome>& pool,
                 int candidates, Rng& rng);
/// Algorithm 1's mutation: when r > options.mutation_threshold, ONE nuclear
/// gene chosen uniformly is mutated by mutate_gene; returns whether.
bool mutate(const ChromosomeLayout& layout, Chromosome& c, const std::vector<Chromosome>& pool,
            const GaOptions& options, Rng& rng);
/// The baselines' mutation: the same trigger, the chosen gene redrawn
/// uniformly in its range (no diversity term); returns whether.
bool mutate_uniform(const ChromosomeLayout& layout, Chromosome& c, double threshold, Rng& rng);

/// eq. 1: DTL / violation_radius + TTL / time_limit. The paper adds the raw
/// metres and seconds; each term is scaled here to be 1 at its violation
/// threshold (landing violation_radius off the marker; not landing within
/// the time limit), so neither unit dominates. Higher = nearer a
/// violation. Throws InvalidArgument for violation_radius or time_limit <= 0.
double fitness_eq1(const Evaluation& e, double violation_radius);
/// eq. 6: eq. 1 + 1 / ΣR when ΣR != 0 (ΣR = e.reward_sum, eq. 5 summed
/// over the run's frames).
double fitness_eq6(const Evaluation& e, double violation_radius);
/// The near-miss term (SearchOptions::near_miss): kNearMissWeight × (1 −
/// d / kNearMissRange) for the nearest approach d < kNearMissRange of an
/// object to the drone in flight (Facts::nearest_m, 0 at a collision);
/// 0 with none recorded.
inline constexpr double kNearMissWeight = 0.5;
inline constexpr double kNearMissRange = 2.0;  ///< [m]
double near_miss_term(const Evaluation& e);

/// `count` binary tournaments: two indices drawn uniformly (with
/// replacement), the higher fitness wins, ties (and NaN) the lower index.
/// Throws InvalidArgument for an empty fitness list when count > 0.
std::vector<std::size_t> tournament_select(const std::vector<double>& fitness, std::size_t count, Rng& rng);
/// Elitist survivors (mu + lambda): the indices of the n highest fitnesses
/// (NaN lowest), ties the lower index, best first. n larger than the list
/// gives every index.
std::vector<std::size_t> best_indices(const std::vector<double>& fitness, std::size_t n);

/// Clearing (Pétrowski, "A clearing procedure as a niching method for
/// genetic algorithms", ICEC 1996), with niches given by label instead of a
/// radius: within each niche (equal non-empty `niche[i]`) the `capacity`
/// highest fitnesses (ties: the lower index; NaN lowest) keep their value,
/// every other member's becomes `cleared`. An empty label is no niche: its
/// fitness is kept. The diversity option's niches are the fair violations'
/// causes, so that one defect cannot fill the pool. Throws InvalidArgument
/// for capacity < 1 or a size mismatch.
std::vector<double> clear_niches(const std::vector<double>& fitness, const std::vector<std::string>& niche,
                                 int capacity, double cleared = 0.0);

}  // namespace touchdown::search
