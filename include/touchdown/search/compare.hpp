#pragma once
/// \file
/// The comparison of search methods (RLaGA paper, Table 2 and its
/// cumulative-violation figure): each method's metrics on each map over
/// several seeds, as aligned text and as an SVG plot. Pure functions,
/// thread-safe.
#include <string>
#include <string_view>
#include <vector>

#include "touchdown/search/metrics.hpp"

namespace touchdown::search {

/// One method on one map, over seeds.
struct CompareCell {
  std::string method, map;
  std::vector<SearchMetrics> per_seed;       ///< Count::All (the source's)
  std::vector<SearchMetrics> per_seed_fair;  ///< Count::Fair; empty: not computed
  std::vector<int> fair_causes;              ///< per seed: distinct fair causes; -1: no facts recorded
  std::vector<std::vector<int>> cumulative;  ///< per seed: cumulative_violations
};

/// Mean and sample standard deviation (n - 1 in the denominator; sd 0 for
/// n = 1); all zero for an empty input.
struct MeanSd {
  double mean = 0, sd = 0;
  int n = 0;
};
MeanSd mean_sd(const std::vector<double>& v);

/// The source's Table 2 layout as aligned text, a header line and one row
/// per cell (method and map), in the order given; columns: violations [%],
/// Top-K, rounds to all types, parameter distance (eq. 7), 3-D coverage
/// [cells], Types I, II and III and off-marker landings (counts), then the
/// fair figures of issue 52: fair violations [%], fair Type II (count) and
/// distinct fair causes ("n/a" for results without facts). Each entry is "mean ± sd" over the
/// cell's seeds. Top-K and rounds to all types, which some seeds may not
/// reach: over the seeds that reached it, followed by "(2/3 found)" when
/// not all did, and "not found" when none did. Decimals: violations 1,
/// Top-K, rounds and coverage 0, parameter distance 3, type counts 1.
/// Columns are separated by two spaces and padded to their widest entry
/// (counted in characters: "±" is one); lines end with '\n' and have no
/// trailing spaces. `k`: the K in the Top-K header.
std::string compare_table(const std::vector<CompareCell>& cells, int k = 10);

/// Cumulative violations against scenarios evaluated: one panel per map
/// (side by side, in order of first appearance), in each one polyline per
/// method (the mean over its seeds, up to the shortest seed's length,
/// starting at (0, 0)), one colour per method across panels; axes, ticks,
/// a legend of methods and `title` (name the system and budget in it).
std::string compare_plot_svg(const std::vector<CompareCell>& cells, std::string_view title);

}  // namespace touchdown::search
