#pragma once
/// \file
/// NSGA-II's ranking for the many-objective GA baseline of the RLaGA paper
/// (§4.2): non-dominated sorting and crowding distance on (DTL, TTL), both
/// maximised. pagmo2 computes the fronts and the crowding distances (it is
/// linked privately: no pagmo type appears here); ties are broken by index
/// so that results are the same on every platform.
///
/// Thread-safety: free functions without shared state. They allocate.
#include <array>
#include <cstddef>
#include <vector>

#include "touchdown/core/random.hpp"

namespace touchdown::search {

/// Per point: its front (rank 0 = the non-dominated front) and its crowding
/// distance within that front (infinity at a front's two ends and for every
/// point of a front of 1 or 2 distinct points; a repeated point's later
/// copies get 0, they add no spread).
struct ParetoRanking {
  std::vector<int> rank;
  std::vector<double> crowding;
};

/// Fronts and crowding of `objectives` (to MAXIMISE, e.g. DTL and TTL).
/// Throws InvalidArgument for a NaN objective.
ParetoRanking pareto_ranking(const std::vector<std::array<double, 2>>& objectives);
/// NSGA-II survivor selection (Deb et al. 2002; pagmo::select_best_N_mo):
/// whole fronts in rank order, the front that does not fit by decreasing
/// crowding distance, ties the lower index. Returned in that order; n larger
/// than the list gives every index.
std::vector<std::size_t> nsga2_survivors(const std::vector<std::array<double, 2>>& objectives, std::size_t n);
/// `count` binary tournaments with the crowded-comparison operator: two
/// indices drawn uniformly (with replacement); the lower rank wins, then the
/// larger crowding distance, then the lower index. Throws InvalidArgument
/// for an empty ranking when count > 0.
std::vector<std::size_t> crowded_tournament(const ParetoRanking& ranking, std::size_t count, Rng& rng);

}  // namespace touchdown::search
