// The method comparison (compare.hpp): mean ± sd by hand, Table 2's text
// against a golden for a small hand-made input, and the cumulative
// violations plot as well-formed SVG with one polyline per method and map.
#include "touchdown/search/compare.hpp"

#include <gtest/gtest.h>

#include <cmath>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <string>
#include <vector>

namespace {

namespace ts = touchdown::search;

std::size_t count(const std::string& text, const std::string& what) {
  std::size_t n = 0;
  for (std::size_t at = text.find(what); at != std::string::npos; at = text.find(what, at + 1)) ++n;
  return n;
}

TEST(Compare, MeanSdByHand) {
  const ts::MeanSd s = ts::mean_sd({2, 4, 4, 4, 5, 5, 7, 9});
  EXPECT_EQ(s.n, 8);
  EXPECT_DOUBLE_EQ(s.mean, 5.0);
  EXPECT_DOUBLE_EQ(s.sd, std::sqrt(32.0 / 7.0));  // squared deviations sum to 32, n - 1 = 7
  const ts::MeanSd one = ts::mean_sd({3.5});
  EXPECT_EQ(one.n, 1);
  EXPECT_EQ(one.mean, 3.5);
  EXPECT_EQ(one.sd, 0.0);
  const ts::MeanSd none = ts::mean_sd({});
  EXPECT_EQ(none.n, 0);
  EXPECT_EQ(none.mean, 0.0);
}

ts::SearchMetrics metrics(double percent, std::optional<int> top, std::optional<int> rounds, double distance, int cells,
                          int i, int ii, int iii) {
  ts::SearchMetrics m;
  m.evaluated = 300;
  m.violation_percent = percent;
  m.top_k = top;
  m.rounds_all_types = rounds;
  m.parameter_distance = distance;
  m.coverage_cells = cells;
  m.type_i = i;
  m.type_ii = ii;
  m.type_iii = iii;
  m.violations = i + ii + iii;
  return m;
}

std::vector<ts::CompareCell> hand_made_cells() {
  ts::CompareCell a;
  a.method = "rlaga";
  a.map = "ground";
  a.per_seed = {metrics(10, 100, 200, 0.5, 10, 10, 10, 10), metrics(20, 50, std::nullopt, 0.6, 20, 20, 20, 20),
                metrics(30, 150, 260, 0.7, 30, 30, 30, 30)};
  // The fair figures (issue 52): 10/15/20 % and 5/10/15 fair Type II; 2, 3, 4 causes.
  a.per_seed_fair = {metrics(10, 100, 200, 0.5, 10, 10, 5, 10), metrics(15, 50, std::nullopt, 0.6, 20, 20, 10, 20),
                     metrics(20, 150, 260, 0.7, 30, 30, 15, 30)};
  a.fair_causes = {2, 3, 4};
  a.cumulative = {{0, 1, 1, 2, 3}, {1, 1, 2, 2, 2}, {0, 0, 1, 2, 4}};
  ts::CompareCell b;  // without facts: the fair columns say n/a
  b.method = "random";
  b.map = "lawn";
  b.per_seed = {metrics(5, std::nullopt, std::nullopt, 0.25, 3, 15, 0, 0)};
  b.cumulative = {{0, 0, 0, 1, 1}};
  return {a, b};
}

TEST(Compare, TableGolden) {
  // rlaga: violations 20 ± 10; Top-10 100 ± 50; rounds over the two seeds
  // that found all types: 230 ± sqrt(1800) = 42.4; distance 0.6 ± 0.1.
  // random: one seed, sd 0; Top-10 and rounds never reached.
  // The fair columns: 15 ± 5 %, 10 ± 5 fair Type II, 3 ± 1 causes; n/a for
  // the cell without facts.
  const std::string expected =
      "method  map     violations [%]  Top-10     rounds to all types   parameter distance  3-D coverage [cells]  "
      "Type I       Type II      Type III     off-marker  fair violations [%]  fair Type II  distinct fair causes\n"
      "rlaga   ground  20.0 ± 10.0     100 ± 50   230 ± 42 (2/3 found)  0.600 ± 0.100       20 ± 10               "
      "20.0 ± 10.0  20.0 ± 10.0  20.0 ± 10.0  0.0 ± 0.0   15.0 ± 5.0           10.0 ± 5.0    3.0 ± 1.0\n"
      "random  lawn    5.0 ± 0.0       not found  not found             0.250 ± 0.000       3 ± 0                 "
      "15.0 ± 0.0   0.0 ± 0.0    0.0 ± 0.0    0.0 ± 0.0   n/a                  n/a           n/a\n";
  EXPECT_EQ(ts::compare_table(hand_made_cells()), expected);
  EXPECT_EQ(
      ts::compare_table({}, 5),
      "method  map  violations [%]  Top-5  rounds to all types  parameter distance  3-D coverage [cells]  Type I  "
      "Type II  Type III  off-marker  fair violations [%]  fair Type II  distinct fair causes\n");
  // A seed whose results carry no facts makes the cell's fair figures n/a.
  auto cells = hand_made_cells();
  cells[0].per_seed_fair[1].facts_recorded = false;
  EXPECT_EQ(count(ts::compare_table(cells), "n/a"), 5u) << ts::compare_table(cells);
}

void expect_well_formed(const std::string& svg, const std::string& name) {
  EXPECT_EQ(svg.rfind("<svg", 0), 0u);
  EXPECT_EQ(svg.substr(svg.size() - 7), "</svg>\n");
  if (std::system("xmllint --version > /dev/null 2>&1") != 0) GTEST_SKIP() << "xmllint not installed";
  const auto path = std::filesystem::temp_directory_path() / name;
  std::ofstream(path) << svg;
  EXPECT_EQ(std::system(("xmllint --noout " + path.string()).c_str()), 0);
  std::filesystem::remove(path);
}

TEST(Compare, PlotHasOnePolylinePerMethodAndMap) {
  auto cells = hand_made_cells();
  cells[1].map = "ground";  // one panel, two methods
  const std::string one = ts::compare_plot_svg(cells, "opencv-mls, budget 5");
  EXPECT_EQ(count(one, "<polyline"), 2u);
  EXPECT_EQ(count(one, "map: ground"), 1u);
  EXPECT_NE(one.find("opencv-mls, budget 5"), std::string::npos);
  EXPECT_NE(one.find(">rlaga<"), std::string::npos);
  EXPECT_NE(one.find(">random<"), std::string::npos);
  expect_well_formed(one, "touchdown_compare_one.svg");

  cells = hand_made_cells();
  ts::CompareCell c = cells[0];
  c.map = "lawn";
  cells.push_back(c);
  ts::CompareCell d = cells[1];
  d.map = "ground";
  cells.push_back(d);
  const std::string two = ts::compare_plot_svg(cells, "mm-mls & friends <budget 5>");
  EXPECT_EQ(count(two, "<polyline"), 4u);
  EXPECT_EQ(count(two, "map: ground"), 1u);
  EXPECT_EQ(count(two, "map: lawn"), 1u);
  // Each method keeps its colour in both panels.
  EXPECT_EQ(count(two, "<polyline fill='none' stroke='#1f77b4'"), 2u);  // rlaga, both panels
  EXPECT_EQ(count(two, "stroke='#1f77b4' stroke-width='1.8'"), 3u);     // 2 lines + legend swatch
  EXPECT_EQ(count(two, "stroke='#d62728' stroke-width='1.8'"), 3u);
  expect_well_formed(two, "touchdown_compare_two.svg");
  if (const char* out = std::getenv("TOUCHDOWN_COMPARE_SVG")) std::ofstream(out) << two;
}

}  // namespace
