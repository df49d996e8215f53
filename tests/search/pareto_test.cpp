// NSGA-II ranking (pareto.hpp): fronts and crowding on hand-computed fronts,
// survivors by the crowded-comparison order, the crowded tournament.
#include "touchdown/search/pareto.hpp"

#include <gtest/gtest.h>

#include <cmath>
#include <limits>

#include "touchdown/core/error.hpp"

namespace touchdown::search {
namespace {

constexpr double kInf = std::numeric_limits<double>::infinity();

// Maximised: front 0 = (0,4), (1,2), (3,1), (4,0); (1,1) is dominated by
// (1,2) and (3,1) → front 1; (0,0) by (1,1) → front 2.
const std::vector<std::array<double, 2>> kPoints{{1, 1}, {0, 4}, {3, 1}, {0, 0}, {1, 2}, {4, 0}};

TEST(ParetoRanking, FrontsAndHandComputedCrowding) {
  const ParetoRanking r = pareto_ranking(kPoints);
  EXPECT_EQ(r.rank, (std::vector<int>{1, 0, 0, 2, 0, 0}));
  // Front 0, ranges 4 and 4: (1,2): (3-0)/4 + (4-1)/4 = 1.5;
  // (3,1): (4-1)/4 + (2-0)/4 = 1.25; the ends infinite.
  EXPECT_EQ(r.crowding[1], kInf);
  EXPECT_EQ(r.crowding[5], kInf);
  EXPECT_DOUBLE_EQ(r.crowding[4], 1.5);
  EXPECT_DOUBLE_EQ(r.crowding[2], 1.25);
  EXPECT_EQ(r.crowding[0], kInf);  // a front of one point
  EXPECT_EQ(r.crowding[3], kInf);
}

TEST(ParetoRanking, SmallFrontsAndDuplicates) {
  EXPECT_TRUE(pareto_ranking({}).rank.empty());
  const ParetoRanking one = pareto_ranking({{2, 3}});
  EXPECT_EQ(one.rank, std::vector<int>{0});
  EXPECT_EQ(one.crowding[0], kInf);
  const ParetoRanking two = pareto_ranking({{0, 1}, {1, 0}});
  EXPECT_EQ(two.crowding, (std::vector<double>{kInf, kInf}));
  // Copies of a point: the first keeps its crowding, the later get 0.
  const ParetoRanking dup = pareto_ranking({{1, 1}, {1, 1}, {1, 1}});
  EXPECT_EQ(dup.rank, (std::vector<int>{0, 0, 0}));
  EXPECT_EQ(dup.crowding, (std::vector<double>{kInf, 0, 0}));
  const ParetoRanking mid = pareto_ranking({{0, 3}, {1, 2}, {1, 2}, {3, 0}});
  EXPECT_EQ(mid.crowding[0], kInf);
  EXPECT_DOUBLE_EQ(mid.crowding[1], 3.0 / 3 + 3.0 / 3);
  EXPECT_EQ(mid.crowding[2], 0);
  EXPECT_EQ(mid.crowding[3], kInf);
  EXPECT_THROW((void)pareto_ranking({{0, std::nan("")}}), InvalidArgument);
}

TEST(Nsga2Survivors, WholeFrontsThenCrowding) {
  // Three of front 0: both ends (infinite, lower index first), then (1,2).
  EXPECT_EQ(nsga2_survivors(kPoints, 3), (std::vector<std::size_t>{1, 5, 4}));
  EXPECT_EQ(nsga2_survivors(kPoints, 5), (std::vector<std::size_t>{1, 5, 4, 2, 0}));
  EXPECT_EQ(nsga2_survivors(kPoints, 10).size(), 6u);
  EXPECT_TRUE(nsga2_survivors(kPoints, 0).empty());
}

TEST(CrowdedTournament, RankThenCrowdingThenIndex) {
  const ParetoRanking r = pareto_ranking(kPoints);
  Rng rng(5), copy(5);
  const auto picks = crowded_tournament(r, 300, rng);
  int both_worst = 0;
  for (const std::size_t p : picks) {
    const auto i = static_cast<std::size_t>(copy.next() % 6), j = static_cast<std::size_t>(copy.next() % 6);
    both_worst += i == 3 && j == 3;
    std::size_t expected = std::min(i, j);
    const std::size_t other = std::max(i, j);
    if (r.rank[other] < r.rank[expected] ||
        (r.rank[other] == r.rank[expected] && r.crowding[other] > r.crowding[expected])) {
      expected = other;
    }
    EXPECT_EQ(p, expected);
  }
  // (0,0) is beaten by every other point: it wins only against itself.
  EXPECT_EQ(std::count(picks.begin(), picks.end(), 3u), both_worst);
  EXPECT_THROW((void)crowded_tournament(ParetoRanking{}, 1, rng), InvalidArgument);
}

}  // namespace
}  // namespace touchdown::search
