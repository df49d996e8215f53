// Genetic operators of the violation search (genetic.hpp; RLaGA paper,
// Algorithm 1, eq. 1, 2 and 6).
#include "touchdown/search/genetic.hpp"

#include <algorithm>
#include <cmath>
#include <limits>
#include <map>
#include <numeric>
#include <string>

#include "touchdown/core/error.hpp"

namespace touchdown::search {

namespace {

void check_length(const ChromosomeLayout& layout, const Chromosome& c, const char* what) {
  if (c.size() != static_cast<std::size_t>(layout.values())) {
    throw InvalidArgument(std::string(what) + ": chromosome has " + std::to_string(c.size()) + " values, the layout " +
                          std::to_string(layout.values()));
  }
}

// Uniform over [0, n) (n >= 1).
std::size_t uniform_index(Rng& rng, std::size_t n) { return static_cast<std::size_t>(rng.next() % n); }

// One value of gene g, uniform in its range (integers: over the integers).
double draw_value(const NuclearGene& g, Rng& rng) {
  if (!g.integer) return rng.uniform(g.min, g.max);
  const auto span = static_cast<std::uint64_t>(g.max - g.min) + 1;
  return g.min + static_cast<double>(rng.next() % span);
}

bool better(double a, double b) {  // a strictly fitter than b (NaN never fitter, always beaten)
  if (std::isnan(a)) return false;
  return std::isnan(b) || a > b;
}

}  // namespace

bool GaOptions::validate(std::string* why) const {
  const auto fail = [&](const std::string& m) {
    if (why) *why = m;
    return false;
  };
  if (population < 2) return fail("population: must be at least 2, got " + std::to_string(population));
  if (!(crossover_threshold >= 0 && crossover_threshold <= 1))
    return fail("crossover_threshold: must be in [0, 1], got " + std::to_string(crossover_threshold));
  if (!(mutation_threshold >= 0 && mutation_threshold <= 1))
    return fail("mutation_threshold: must be in [0, 1], got " + std::to_string(mutation_threshold));
  if (mutation_candidates < 1)
    return fail("mutation_candidates: must be at least 1, got " + std::to_string(mutation_candidates));
  return true;
}

void crossover_at(const ChromosomeLayout& layout, Chromosome& a, Chromosome& b, std::size_t separation) {
  check_length(layout, a, "crossover");
  check_length(layout, b, "crossover");
  const auto& genes = layout.genes();
  if (separation < 1 || separation >= genes.size()) {
    throw InvalidArgument("crossover: separation must be in [1, " + std::to_string(genes.size() - 1) + "], got " +
                          std::to_string(separation));
  }
  // Nuclear genes are contiguous and in order: everything from the first
  // value of gene `separation` on is swapped, whole genes only.
  const auto from = static_cast<std::ptrdiff_t>(genes[separation].offset);
  std::swap_ranges(a.begin() + from, a.end(), b.begin() + from);
}

bool crossover(const ChromosomeLayout& layout, Chromosome& a, Chromosome& b, double threshold, Rng& rng) {
  // Algorithm 1: adjacent pairs cross over when r > threshold_c.
  if (!(rng.uniform() > threshold)) return false;
  const std::size_t separation = 1 + uniform_index(rng, layout.genes().size() - 1);
  crossover_at(layout, a, b, separation);
  return true;
}

std::size_t farthest_candidate(const std::vector<std::vector<double>>& candidates,
                               const std::vector<std::vector<double>>& pool_values) {
  if (candidates.empty()) throw InvalidArgument("farthest_candidate: no candidates");
  // eq. 2: x* = argmax_{x in candidates} min_{p in pool} ||x - p||.
  std::size_t best = 0;
  double best_distance = -1;
  for (std::size_t i = 0; i < candidates.size(); ++i) {
    double nearest = std::numeric_limits<double>::infinity();
    for (const std::vector<double>& p : pool_values) {
      if (p.size() != candidates[i].size()) throw InvalidArgument("farthest_candidate: size mismatch");
      double d2 = 0;
      for (std::size_t j = 0; j < p.size(); ++j) d2 += (candidates[i][j] - p[j]) * (candidates[i][j] - p[j]);
      nearest = std::min(nearest, std::sqrt(d2));
    }
    if (nearest > best_distance) {
      best_distance = nearest;
      best = i;
    }
  }
  return best;
}

void mutate_gene(const ChromosomeLayout& layout, Chromosome& c, std::size_t gene, const std::vector<Chromosome>& pool,
                 int candidates, Rng& rng) {
  check_length(layout, c, "mutate");
  if (gene >= layout.genes().size()) throw InvalidArgument("mutate: gene index out of range");
  if (candidates < 1) throw InvalidArgument("mutate: candidates must be at least 1");
  const NuclearGene& g = layout.genes()[gene];
  const auto size = static_cast<std::size_t>(g.size);
  const auto offset = static_cast<std::size_t>(g.offset);
  std::vector<std::vector<double>> pool_values;
  pool_values.reserve(pool.size());
  for (const Chromosome& p : pool) {
    check_length(layout, p, "mutate (pool)");
    pool_values.emplace_back(p.begin() + static_cast<std::ptrdiff_t>(offset),
                             p.begin() + static_cast<std::ptrdiff_t>(offset + size));
  }
  std::vector<std::vector<double>> drawn(static_cast<std::size_t>(candidates), std::vector<double>(size));
  for (auto& x : drawn) {
    for (double& v : x) v = draw_value(g, rng);
  }
  const std::vector<double>& chosen = drawn[farthest_candidate(drawn, pool_values)];
  std::copy(chosen.begin(), chosen.end(), c.begin() + static_cast<std::ptrdiff_t>(offset));
}

bool mutate(const ChromosomeLayout& layout, Chromosome& c, const std::vector<Chromosome>& pool,
            const GaOptions& options, Rng& rng) {
  if (!(rng.uniform() > options.mutation_threshold)) return false;
  const std::size_t gene = uniform_index(rng, layout.genes().size());
  mutate_gene(layout, c, gene, pool, options.mutation_candidates, rng);
  return true;
}

bool mutate_uniform(const ChromosomeLayout& layout, Chromosome& c, double threshold, Rng& rng) {
  check_length(layout, c, "mutate_uniform");
  if (!(rng.uniform() > threshold)) return false;
  const NuclearGene& g = layout.genes()[uniform_index(rng, layout.genes().size())];
  for (int j = 0; j < g.size; ++j) c[static_cast<std::size_t>(g.offset + j)] = draw_value(g, rng);
  return true;
}

double fitness_eq1(const Evaluation& e, double violation_radius) {
  if (!(violation_radius > 0)) throw InvalidArgument("fitness: violation_radius must be positive");
  if (!(e.time_limit > 0)) throw InvalidArgument("fitness: the evaluation's time_limit must be positive");
  // eq. 1: F = DTL + TTL, each term scaled to 1 at its violation threshold.
  return e.dtl / violation_radius + e.ttl / e.time_limit;
}

double fitness_eq6(const Evaluation& e, double violation_radius) {
  // eq. 6: F = DTL + TTL + 1 / ΣR, the last term only when ΣR != 0.
  const double f = fitness_eq1(e, violation_radius);
  return e.reward_sum != 0 ? f + 1.0 / e.reward_sum : f;
}

double near_miss_term(const Evaluation& e) {
  const Facts& f = e.facts;
  if (f.nearest_object.empty() || !(f.nearest_m < kNearMissRange)) return 0.0;
  return kNearMissWeight * (1.0 - std::max(0.0, f.nearest_m) / kNearMissRange);
}

std::vector<std::size_t> tournament_select(const std::vector<double>& fitness, std::size_t count, Rng& rng) {
  if (fitness.empty() && count > 0) throw InvalidArgument("tournament_select: no fitness values");
  std::vector<std::size_t> chosen;
  chosen.reserve(count);
  for (std::size_t k = 0; k < count; ++k) {
    const std::size_t i = uniform_index(rng, fitness.size());
    const std::size_t j = uniform_index(rng, fitness.size());
    const std::size_t lo = std::min(i, j), hi = std::max(i, j);
    chosen.push_back(better(fitness[hi], fitness[lo]) ? hi : lo);
  }
  return chosen;
}

std::vector<std::size_t> best_indices(const std::vector<double>& fitness, std::size_t n) {
  std::vector<std::size_t> order(fitness.size());
  std::iota(order.begin(), order.end(), std::size_t{0});
  std::stable_sort(order.begin(), order.end(),
                   [&](std::size_t a, std::size_t b) { return better(fitness[a], fitness[b]); });
  order.resize(std::min(n, order.size()));
  return order;
}

std::vector<double> clear_niches(const std::vector<double>& fitness, const std::vector<std::string>& niche,
                                 int capacity, double cleared) {
  if (capacity < 1) throw InvalidArgument("clear_niches: capacity " + std::to_string(capacity) + " < 1");
  if (niche.size() != fitness.size()) {
    throw InvalidArgument("clear_niches: " + std::to_string(niche.size()) + " niche labels for " +
                          std::to_string(fitness.size()) + " fitnesses");
  }
  std::vector<double> out = fitness;
  std::map<std::string, int> kept;  // per niche: members that kept their fitness so far
  for (std::size_t i : best_indices(fitness, fitness.size())) {
    if (niche[i].empty()) continue;
    if (++kept[niche[i]] > capacity) out[i] = cleared;
  }
  return out;
}

}  // namespace touchdown::search
