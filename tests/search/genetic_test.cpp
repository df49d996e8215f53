// GA operators (genetic.hpp; RLaGA Algorithm 1, eq. 1, 2, 6): whole-gene
// crossover, eq. 2's maximin choice on hand-computed pools, the fitness on
// hand-made evaluations, tournament and elitist selection.
#include "touchdown/search/genetic.hpp"

#include <gtest/gtest.h>

#include <cmath>
#include <limits>

#include "touchdown/core/error.hpp"

namespace touchdown::search {
namespace {

ChromosomeLayout layout_for_tests() {
  scenario::Scenario base;
  base.marker.id = 5;
  return ChromosomeLayout(base);
}

std::size_t gene_index(const ChromosomeLayout& l, std::string_view name) {
  for (std::size_t i = 0; i < l.genes().size(); ++i) {
    if (l.genes()[i].name == name) return i;
  }
  throw InvalidArgument("no gene " + std::string(name));
}

// Every value at its gene's min (a) or max (b): a value tells its parent.
Chromosome filled(const ChromosomeLayout& l, bool max) {
  Chromosome c(static_cast<std::size_t>(l.values()));
  for (const NuclearGene& g : l.genes()) {
    for (int j = 0; j < g.size; ++j) c[static_cast<std::size_t>(g.offset + j)] = max ? g.max : g.min;
  }
  return c;
}

TEST(Crossover, SwapsWholeNuclearGenesAfterTheSeparation) {
  const ChromosomeLayout l = layout_for_tests();
  const Chromosome a0 = filled(l, false), b0 = filled(l, true);
  const std::size_t marker = gene_index(l, "marker.position");
  Chromosome a = a0, b = b0;
  crossover_at(l, a, b, marker);
  const auto m = static_cast<std::size_t>(l.genes()[marker].offset);
  for (std::size_t i = 0; i < m; ++i) {
    EXPECT_EQ(a[i], a0[i]) << i;  // nothing before the separation changes
    EXPECT_EQ(b[i], b0[i]) << i;
  }
  // The two-value marker gene moves as a unit, and so does every later gene.
  for (std::size_t i = m; i < a.size(); ++i) {
    EXPECT_EQ(a[i], b0[i]) << i;
    EXPECT_EQ(b[i], a0[i]) << i;
  }
  // Every separation: each gene comes whole from one parent.
  for (std::size_t s = 1; s < l.genes().size(); ++s) {
    Chromosome x = a0, y = b0;
    crossover_at(l, x, y, s);
    for (std::size_t gi = 0; gi < l.genes().size(); ++gi) {
      const NuclearGene& g = l.genes()[gi];
      for (int j = 0; j < g.size; ++j) {
        const auto i = static_cast<std::size_t>(g.offset + j);
        EXPECT_EQ(x[i], gi < s ? a0[i] : b0[i]);
      }
    }
  }
  EXPECT_THROW(crossover_at(l, a, b, 0), InvalidArgument);
  EXPECT_THROW(crossover_at(l, a, b, l.genes().size()), InvalidArgument);
}

TEST(Crossover, FiresWhenRExceedsTheThreshold) {
  const ChromosomeLayout l = layout_for_tests();
  Rng rng(7);
  int crossed = 0;
  for (int k = 0; k < 1000; ++k) {
    Chromosome a = filled(l, false), b = filled(l, true);
    Rng copy = rng;
    const bool expected = copy.uniform() > 0.2;
    const bool did = crossover(l, a, b, 0.2, rng);
    EXPECT_EQ(did, expected);
    EXPECT_EQ(a != filled(l, false), did);
    crossed += did;
  }
  EXPECT_NEAR(crossed / 1000.0, 0.8, 0.05);
  Chromosome a = filled(l, false), b = filled(l, true);
  EXPECT_FALSE(crossover(l, a, b, 1.0, rng));  // r < 1 always
}

TEST(FarthestCandidate, IsEq2Maximin) {
  // Pool {(0,0), (4,0)}; minimum distances: (2,0) 2, (2,3) sqrt(13) = 3.61,
  // (-3,0) 3, (9,0) 5, (10,0) 6 → the last.
  const std::vector<std::vector<double>> pool{{0, 0}, {4, 0}};
  EXPECT_EQ(farthest_candidate({{2, 0}, {2, 3}, {-3, 0}, {10, 0}, {9, 0}}, pool), 3u);
  // Not the largest sum of distances: (2,3) is 3.61 from both (sum 7.2),
  // (-1,0) is 1 and 5 away (sum 6) but nearer: (2,3) wins; (8,0) is 4
  // from the nearest (sum 12) and wins over both.
  EXPECT_EQ(farthest_candidate({{-1, 0}, {2, 3}}, pool), 1u);
  EXPECT_EQ(farthest_candidate({{-1, 0}, {2, 3}, {8, 0}}, pool), 2u);
  EXPECT_EQ(farthest_candidate({{1, 0}, {3, 0}}, {{2, 0}}), 0u);  // tie: the first
  EXPECT_EQ(farthest_candidate({{1}, {3}}, {}), 0u);
  EXPECT_THROW((void)farthest_candidate({}, pool), InvalidArgument);
}

TEST(MutateGene, KeepsTheCandidateFarthestFromThePool) {
  const ChromosomeLayout l = layout_for_tests();
  const std::size_t fog = gene_index(l, "weather.fog");  // range [0, 0.4]
  const auto off = static_cast<std::size_t>(l.genes()[fog].offset);
  std::vector<Chromosome> pool(2, filled(l, false));
  pool[1][off] = 0.4;  // pool fog values {0, 0.4}: the farthest point is 0.2
  Rng rng(11);
  Rng copy = rng;
  Chromosome c = filled(l, true);
  mutate_gene(l, c, fog, pool, 10, rng);
  // The ten candidates, drawn from the same stream: the nearest to 0.2 wins.
  double expected = -1;
  for (int k = 0; k < 10; ++k) {
    const double x = copy.uniform(0, 0.4);
    if (expected < 0 || std::abs(x - 0.2) < std::abs(expected - 0.2)) expected = x;
  }
  EXPECT_EQ(c[off], expected);
  Chromosome rest = filled(l, true);
  rest[off] = c[off];
  EXPECT_EQ(c, rest);  // only that gene changed
  mutate_gene(l, c, fog, pool, 2000, rng);
  EXPECT_NEAR(c[off], 0.2, 0.002);

  // An integer gene: kinds {0, 1, 3} in the pool → 2, the only integer 1 away.
  const std::size_t kind = gene_index(l, "dynamic_objects[0].kind");
  const auto koff = static_cast<std::size_t>(l.genes()[kind].offset);
  std::vector<Chromosome> kinds(3, filled(l, false));
  kinds[1][koff] = 1;
  kinds[2][koff] = 3;
  mutate_gene(l, c, kind, kinds, 50, rng);
  EXPECT_EQ(c[koff], 2.0);

  // A two-value gene: distances in the plane of (x, y).
  const std::size_t marker = gene_index(l, "marker.position");
  const auto moff = static_cast<std::size_t>(l.genes()[marker].offset);
  std::vector<Chromosome> corners(4, filled(l, false));
  corners[1][moff] = 20;
  corners[2][moff + 1] = 20;
  corners[3][moff] = corners[3][moff + 1] = 20;  // corners (±20, ±20) but one: (-20,-20), (20,-20), (-20,20), (20,20)
  mutate_gene(l, c, marker, corners, 3000, rng);
  EXPECT_NEAR(c[moff], 0, 1.5);  // the centre is farthest from four corners
  EXPECT_NEAR(c[moff + 1], 0, 1.5);
}

TEST(Mutate, OneGeneWhenRExceedsTheThreshold) {
  const ChromosomeLayout l = layout_for_tests();
  const std::vector<Chromosome> pool{filled(l, false)};
  GaOptions o;
  Rng rng(3);
  int mutated = 0;
  for (int k = 0; k < 500; ++k) {
    Chromosome c = l.draw(static_cast<std::uint64_t>(k));
    const Chromosome before = c;
    Rng copy = rng;
    const bool expected = copy.uniform() > o.mutation_threshold;
    EXPECT_EQ(mutate(l, c, pool, o, rng), expected);
    int genes_changed = 0;
    for (const NuclearGene& g : l.genes()) {
      bool changed = false;
      for (int j = 0; j < g.size; ++j)
        changed |= c[static_cast<std::size_t>(g.offset + j)] != before[static_cast<std::size_t>(g.offset + j)];
      genes_changed += changed;
    }
    EXPECT_LE(genes_changed, expected ? 1 : 0);
    mutated += expected;
    (void)l.decode(c);  // stays in range
  }
  EXPECT_NEAR(mutated / 500.0, 0.8, 0.06);
  Chromosome c = filled(l, false);
  EXPECT_FALSE(mutate_uniform(l, c, 1.0, rng));
  int redrawn = 0;
  for (int k = 0; k < 100; ++k) redrawn += mutate_uniform(l, c, 0.0, rng);
  EXPECT_EQ(redrawn, 100);
  (void)l.decode(c);
}

TEST(Fitness, Eq1AndEq6OnHandMadeEvaluations) {
  Evaluation e;
  e.dtl = 3;
  e.ttl = 30;
  e.time_limit = 60;
  EXPECT_DOUBLE_EQ(fitness_eq1(e, 1.5), 2.0 + 0.5);
  EXPECT_DOUBLE_EQ(fitness_eq6(e, 1.5), 2.5);  // ΣR = 0: no reward term
  e.reward_sum = 4;
  EXPECT_DOUBLE_EQ(fitness_eq1(e, 1.5), 2.5);
  EXPECT_DOUBLE_EQ(fitness_eq6(e, 1.5), 2.75);
  // Each term is 1 at its violation threshold.
  Evaluation at;
  at.dtl = 1.5;
  at.ttl = 60;
  at.time_limit = 60;
  EXPECT_DOUBLE_EQ(fitness_eq1(at, 1.5), 2.0);
  EXPECT_THROW((void)fitness_eq1(e, 0), InvalidArgument);
  e.time_limit = 0;
  EXPECT_THROW((void)fitness_eq6(e, 1.5), InvalidArgument);
}

TEST(Fitness, TheNearMissTermIsLinearInTheClearanceAndZeroBeyondItsRange) {
  Evaluation e;
  EXPECT_EQ(near_miss_term(e), 0.0);  // nothing recorded
  e.facts.nearest_object = "static_objects[0] (box)";
  e.facts.nearest_m = 0;  // a collision
  EXPECT_DOUBLE_EQ(near_miss_term(e), kNearMissWeight);
  e.facts.nearest_m = 0.5;
  EXPECT_DOUBLE_EQ(near_miss_term(e), kNearMissWeight * (1 - 0.5 / kNearMissRange));
  e.facts.nearest_m = kNearMissRange;
  EXPECT_EQ(near_miss_term(e), 0.0);
  e.facts.nearest_m = 7;
  EXPECT_EQ(near_miss_term(e), 0.0);
}

TEST(Selection, TournamentIsBinaryAndDeterministic) {
  const std::vector<double> f{1, 5, 3, 5};
  Rng rng(9), same(9), copy(9);
  const auto picks = tournament_select(f, 200, rng);
  EXPECT_EQ(picks, tournament_select(f, 200, same));
  ASSERT_EQ(picks.size(), 200u);
  int with_three_not_one = 0;
  for (const std::size_t p : picks) {
    const auto i = static_cast<std::size_t>(copy.next() % 4), j = static_cast<std::size_t>(copy.next() % 4);
    with_three_not_one += (i == 3 || j == 3) && i != 1 && j != 1;
    const std::size_t expected = f[i] > f[j] ? i : f[j] > f[i] ? j : std::min(i, j);
    EXPECT_EQ(p, expected);
  }
  // Index 3 ties with index 1 and beats the rest: it wins every draw with it but without 1.
  EXPECT_EQ(std::count(picks.begin(), picks.end(), 3u), with_three_not_one);
  EXPECT_THROW((void)tournament_select({}, 1, rng), InvalidArgument);
  EXPECT_TRUE(tournament_select({}, 0, rng).empty());
}

TEST(Selection, BestIndicesAreElitistWithLowerIndexOnTies) {
  const double nan = std::numeric_limits<double>::quiet_NaN();
  const std::vector<double> f{1, 3, 3, nan, 2};
  EXPECT_EQ(best_indices(f, 3), (std::vector<std::size_t>{1, 2, 4}));
  EXPECT_EQ(best_indices(f, 10), (std::vector<std::size_t>{1, 2, 4, 0, 3}));
  EXPECT_TRUE(best_indices(f, 0).empty());
}

TEST(Selection, ClearingKeepsTheFittestFewOfEachNiche) {
  const double nan = std::numeric_limits<double>::quiet_NaN();
  //                         0    1    2    3    4    5    6    7
  const std::vector<double> f{5.0, 4.0, 9.0, 3.0, 2.0, 4.0, nan, 7.0};
  const std::vector<std::string> n{"a", "a", "a", "", "", "b", "a", "b"};
  // Niche a by fitness: 2 (9), 0 (5), 1 (4), 6 (NaN); b: 7 (7), 5 (4); 3 and 4 have none.
  EXPECT_EQ(clear_niches(f, n, 2), (std::vector<double>{5.0, 0.0, 9.0, 3.0, 2.0, 4.0, 0.0, 7.0}));
  const std::vector<double> one = clear_niches(f, n, 1, -1.0);
  EXPECT_EQ(one, (std::vector<double>{-1.0, -1.0, 9.0, 3.0, 2.0, -1.0, -1.0, 7.0}));
  // Ties: the lower index keeps its fitness.
  EXPECT_EQ(clear_niches({1.0, 1.0, 1.0}, {"x", "x", "x"}, 2), (std::vector<double>{1.0, 1.0, 0.0}));
  // A capacity as large as every niche changes nothing (NaN stays NaN).
  const std::vector<double> all = clear_niches(f, n, 4);
  for (std::size_t i = 0; i < f.size(); ++i) {
    if (std::isnan(f[i])) {
      EXPECT_TRUE(std::isnan(all[i]));
    } else {
      EXPECT_EQ(all[i], f[i]) << i;
    }
  }
  EXPECT_THROW((void)clear_niches(f, n, 0), InvalidArgument);
  EXPECT_THROW((void)clear_niches(f, {"a"}, 1), InvalidArgument);
}

TEST(GaOptions, Validate) {
  std::string why;
  GaOptions o;
  EXPECT_TRUE(o.validate(&why));
  o.population = 1;
  EXPECT_FALSE(o.validate(&why));
  EXPECT_NE(why.find("population"), std::string::npos);
  o = {};
  o.crossover_threshold = 1.5;
  EXPECT_FALSE(o.validate(&why));
  EXPECT_NE(why.find("crossover_threshold"), std::string::npos);
  o = {};
  o.mutation_threshold = std::nan("");
  EXPECT_FALSE(o.validate(&why));
  o = {};
  o.mutation_candidates = 0;
  EXPECT_FALSE(o.validate(&why));
  EXPECT_NE(why.find("mutation_candidates"), std::string::npos);
}

}  // namespace
}  // namespace touchdown::search
