// Order statistics (core/statistics.hpp) against a brute-force reference:
// the sorted sample, indexed.
#include "touchdown/core/statistics.hpp"

#include <gtest/gtest.h>

#include <algorithm>
#include <cstdint>
#include <limits>
#include <vector>

#include "touchdown/core/random.hpp"

namespace touchdown {
namespace {

std::vector<double> sample(std::uint64_t seed, std::size_t n) {
  Rng rng(seed);
  std::vector<double> v(n);
  for (double& x : v) x = rng.normal(3, 2);
  if (n > 4) v[1] = v[3];  // a tie
  return v;
}

TEST(Statistics, AgreeWithTheSortedSample) {
  for (std::size_t n = 1; n <= 40; ++n) {
    const std::vector<double> v = sample(n, n);
    std::vector<double> sorted = v;
    std::sort(sorted.begin(), sorted.end());
    const double textbook = n % 2 ? sorted[n / 2] : 0.5 * (sorted[n / 2 - 1] + sorted[n / 2]);
    EXPECT_EQ(median(v), textbook) << n;
    EXPECT_EQ(upper_median(v), sorted[n / 2]) << n;
    for (const double q : {0.0, 0.1, 0.5, 0.9, 0.99, 1.0}) {
      EXPECT_EQ(quantile(v, q), sorted[static_cast<std::size_t>(q * static_cast<double>(n - 1))]) << n << " " << q;
    }
    EXPECT_EQ(quantile(v, -1), sorted.front());
    EXPECT_EQ(quantile(v, 2), sorted.back());
    for (std::size_t k = 0; k < n; ++k) {
      std::vector<double> w = v;
      EXPECT_EQ(nth_smallest(std::span(w), k), sorted[k]) << n << " " << k;
    }
  }
}

TEST(Statistics, NearestRankIsTheCeilingRankOfTheSortedSample) {
  // The nearest-rank definition: the smallest value with at least q n of the
  // sample at or below it; counted here by brute force.
  for (std::size_t n = 1; n <= 30; ++n) {
    const std::vector<double> v = sample(100 + n, n);
    for (const double q : {0.0, 0.05, 0.25, 0.5, 0.9, 0.95, 1.0}) {
      double expected = std::numeric_limits<double>::infinity();
      for (const double x : v) {
        const auto at_or_below = std::count_if(v.begin(), v.end(), [&](double y) { return y <= x; });
        if (static_cast<double>(at_or_below) >= q * static_cast<double>(n)) expected = std::min(expected, x);
      }
      EXPECT_EQ(nearest_rank(v, q), expected) << "n " << n << " q " << q;
    }
  }
  EXPECT_EQ(nearest_rank({4, 1, 3, 2}, 0.5), 2);   // rank 2 of 4
  EXPECT_EQ(nearest_rank({4, 1, 3, 2}, 0.51), 3);  // rank 3
  EXPECT_EQ(nearest_rank({4, 1, 3, 2}, 2.0), 4);   // q clamped
  EXPECT_EQ(nearest_rank({}, 0.5), 0);
}

TEST(Statistics, InPlaceFormsWorkOnFloatsAndPrefixes) {
  std::vector<float> f{4.f, 1.f, 3.f, 2.f};
  EXPECT_EQ(median_in_place(std::span(f)), 2.5f);
  std::vector<float> g{4.f, 1.f, 3.f, 2.f};
  EXPECT_EQ(upper_median_in_place(std::span(g)), 3.f);
  // Only the first n are the sample: the rest is a buffer's stale tail.
  std::vector<std::uint16_t> depth{900, 1000, 1100, 0, 0, 0};
  EXPECT_EQ(upper_median_in_place(std::span(depth).first(3)), 1000);
  EXPECT_EQ(depth[3], 0);
}

TEST(Statistics, AnEmptySampleGivesZero) {
  EXPECT_EQ(median({}), 0.0);
  EXPECT_EQ(upper_median({}), 0.0);
  EXPECT_EQ(quantile({}, 0.5), 0.0);
}

}  // namespace
}  // namespace touchdown
