// The search metrics (metrics.hpp, RLaGA §4.3) on a hand-made results file
// whose every answer is worked out by hand below.
#include "touchdown/search/metrics.hpp"

#include <gtest/gtest.h>

#include <cmath>
#include <filesystem>
#include <fstream>
#include <string>
#include <vector>

#include "test_util.hpp"
#include "touchdown/core/error.hpp"

namespace {

namespace ts = touchdown::search;
using touchdown::scenario::Violation;

ts::EvaluationRecord make(int index, Violation v, std::vector<double> genes, std::vector<std::array<int, 3>> cells) {
  ts::EvaluationRecord r;
  r.index = index;
  r.generation = index / 4;
  r.scenario = "scenarios/" + std::to_string(index) + ".yaml";
  r.genes = std::move(genes);
  r.evaluation.violation = v;
  r.evaluation.cells = std::move(cells);
  return r;
}

// 8 evaluations, 3 violations: Type I at index 1, II at 3, III at 6.
// Genes of the violating ones (0, 0), (1, 0), (0, 1); their cells overlap
// ((1,0,0) in I and II, (0,0,0) in I and III) and cover x = -1 .. 2: 4
// cells. A non-violating run visits (5,5,5), which must not count.
std::vector<ts::EvaluationRecord> hand_made_results() {
  const std::vector<ts::EvaluationRecord> written = {
      make(0, Violation::None, {0.5, 0.5}, {{0, 0, 0}}),
      make(1, Violation::TypeI, {0, 0}, {{0, 0, 0}, {1, 0, 0}}),
      make(2, Violation::None, {0.9, 0.9}, {{5, 5, 5}}),
      make(3, Violation::TypeII, {1, 0}, {{1, 0, 0}, {2, 0, 0}}),
      make(4, Violation::None, {0.2, 0.7}, {}),
      make(5, Violation::None, {0.3, 0.1}, {{0, 0, 0}}),
      make(6, Violation::TypeIII, {0, 1}, {{-1, 0, 0}, {0, 0, 0}}),
      make(7, Violation::None, {0.4, 0.4}, {{0, 0, 1}}),
  };
  // Through the file, as the app reads it; a directory of the calling
  // test's own (ctest runs the tests that call this in parallel: one fixed
  // /tmp name let one test remove the file another was reading).
  const touchdown::test::TempDir dir;
  const auto path = dir / "results.jsonl";
  {
    std::ofstream out(path, std::ios::binary);
    for (const auto& r : written) out << ts::record_line(r) << '\n';
  }
  return ts::load_records(path);
}

TEST(Metrics, HandMadeResultsFile) {
  const auto records = hand_made_results();
  ASSERT_EQ(records.size(), 8u);
  const ts::SearchMetrics m = ts::compute_metrics(records, 3);
  EXPECT_EQ(m.evaluated, 8);
  EXPECT_EQ(m.violations, 3);
  EXPECT_EQ(m.type_i, 1);
  EXPECT_EQ(m.type_ii, 1);
  EXPECT_EQ(m.type_iii, 1);
  EXPECT_DOUBLE_EQ(m.violation_percent, 37.5);
  ASSERT_TRUE(m.top_k.has_value());
  EXPECT_EQ(*m.top_k, 7);  // the 3rd violation is the 7th scenario
  ASSERT_TRUE(m.rounds_all_types.has_value());
  EXPECT_EQ(*m.rounds_all_types, 7);
  // eq. 7: pair distances 1, 1, sqrt(2); mean (2 + sqrt 2) / 3; over sqrt(2).
  EXPECT_NEAR(m.parameter_distance, (2 + std::sqrt(2.0)) / 3 / std::sqrt(2.0), 1e-15);
  EXPECT_EQ(m.coverage_cells, 4);

  EXPECT_EQ(*ts::compute_metrics(records, 1).top_k, 2);
  EXPECT_FALSE(ts::compute_metrics(records, 4).top_k.has_value());  // only 3 violations
  EXPECT_FALSE(ts::compute_metrics(records).top_k.has_value());     // K = 10
  EXPECT_EQ(ts::cumulative_violations(records), (std::vector<int>{0, 1, 1, 2, 2, 2, 3, 3}));
}

TEST(Metrics, NotFoundAndDegenerateCases) {
  auto records = hand_made_results();
  ASSERT_EQ(records.size(), 8u);
  records.resize(6);  // no Type III yet
  const ts::SearchMetrics m = ts::compute_metrics(records, 2);
  EXPECT_FALSE(m.rounds_all_types.has_value());
  EXPECT_EQ(*m.top_k, 4);
  EXPECT_NEAR(m.parameter_distance, 1 / std::sqrt(2.0), 1e-15);  // one pair, distance 1
  EXPECT_EQ(m.coverage_cells, 3);

  records.resize(2);  // one violation: no pair
  EXPECT_EQ(ts::compute_metrics(records).parameter_distance, 0.0);
  const ts::SearchMetrics none = ts::compute_metrics({});
  EXPECT_EQ(none.evaluated, 0);
  EXPECT_EQ(none.violation_percent, 0.0);
  EXPECT_FALSE(none.top_k.has_value());
  EXPECT_FALSE(none.rounds_all_types.has_value());
  EXPECT_TRUE(ts::cumulative_violations({}).empty());
}

TEST(Metrics, RefusesMisuse) {
  auto records = hand_made_results();
  ASSERT_EQ(records.size(), 8u);
  EXPECT_THROW((void)ts::compute_metrics(records, 0), touchdown::InvalidArgument);
  auto reordered = records;
  std::swap(reordered[0], reordered[1]);
  EXPECT_THROW((void)ts::compute_metrics(reordered), touchdown::InvalidArgument);
  records[6].genes.push_back(0.5);
  EXPECT_THROW((void)ts::compute_metrics(records), touchdown::InvalidArgument);
}

}  // namespace
