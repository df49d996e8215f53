// Order statistics (core/statistics.hpp) against a brute-force reference:
// the sorted sample, indexed.
#include "touchdown/core/statistics.hpp"

#include <gtest/gtest.h>

#include <algorithm>
#include <cstdint>
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
