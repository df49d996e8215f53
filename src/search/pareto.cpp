// NSGA-II ranking for the many-objective GA baseline (pareto.hpp). The only
// file of the module that includes pagmo.
#include "touchdown/search/pareto.hpp"

#include <algorithm>
#include <cmath>
#include <limits>
#include <numeric>
#include <pagmo/utils/multi_objective.hpp>

#include "touchdown/core/error.hpp"

namespace touchdown::search {

namespace {

constexpr double kInfinity = std::numeric_limits<double>::infinity();

// Crowding distances of one front (indices into points, ascending). pagmo's
// crowding_distance needs >= 2 points and divides by each objective's
// range, so it gets the front's DISTINCT points only (in a 2-objective
// front distinct points have distinct values in each objective: the range
// is positive from 3 points on and its sorting has no ties to break). A
// repeated point's later copies get 0.
void front_crowding(const std::vector<pagmo::vector_double>& points, const std::vector<std::size_t>& front,
                    std::vector<double>& crowding) {
  std::vector<std::size_t> distinct;
  for (const std::size_t i : front) {
    const bool repeated =
        std::any_of(distinct.begin(), distinct.end(), [&](std::size_t j) { return points[j] == points[i]; });
    if (repeated) {
      crowding[i] = 0;
    } else {
      distinct.push_back(i);
    }
  }
  if (distinct.size() <= 2) {
    for (const std::size_t i : distinct) crowding[i] = kInfinity;
    return;
  }
  std::vector<pagmo::vector_double> sub;
  sub.reserve(distinct.size());
  for (const std::size_t i : distinct) sub.push_back(points[i]);
  const pagmo::vector_double d = pagmo::crowding_distance(sub);
  for (std::size_t k = 0; k < distinct.size(); ++k) crowding[distinct[k]] = d[k];
}

}  // namespace

ParetoRanking pareto_ranking(const std::vector<std::array<double, 2>>& objectives) {
  ParetoRanking r;
  if (objectives.empty()) return r;
  // pagmo minimises: negate the objectives to maximise.
  std::vector<pagmo::vector_double> points;
  points.reserve(objectives.size());
  for (std::size_t i = 0; i < objectives.size(); ++i) {
    if (std::isnan(objectives[i][0]) || std::isnan(objectives[i][1])) {
      throw InvalidArgument("pareto_ranking: objective of point " + std::to_string(i) + " is NaN");
    }
    points.push_back({-objectives[i][0], -objectives[i][1]});
  }
  r.rank.assign(objectives.size(), 0);
  r.crowding.assign(objectives.size(), 0.0);
  if (objectives.size() == 1) {
    r.crowding[0] = kInfinity;
    return r;
  }
  const auto sorted = pagmo::fast_non_dominated_sorting(points);
  for (std::size_t f = 0; f < std::get<0>(sorted).size(); ++f) {
    std::vector<std::size_t> front(std::get<0>(sorted)[f].begin(), std::get<0>(sorted)[f].end());
    std::sort(front.begin(), front.end());
    for (const std::size_t i : front) r.rank[i] = static_cast<int>(f);
    front_crowding(points, front, r.crowding);
  }
  return r;
}

std::vector<std::size_t> nsga2_survivors(const std::vector<std::array<double, 2>>& objectives, std::size_t n) {
  const ParetoRanking r = pareto_ranking(objectives);
  std::vector<std::size_t> order(objectives.size());
  std::iota(order.begin(), order.end(), std::size_t{0});
  // Deb et al. 2002's crowded-comparison order (what pagmo::select_best_N_mo
  // selects by), with the index as the last key so ties are reproducible.
  std::stable_sort(order.begin(), order.end(), [&](std::size_t a, std::size_t b) {
    if (r.rank[a] != r.rank[b]) return r.rank[a] < r.rank[b];
    return r.crowding[a] > r.crowding[b];
  });
  order.resize(std::min(n, order.size()));
  return order;
}

std::vector<std::size_t> crowded_tournament(const ParetoRanking& ranking, std::size_t count, Rng& rng) {
  const std::size_t n = ranking.rank.size();
  if (n == 0 && count > 0) throw InvalidArgument("crowded_tournament: empty ranking");
  if (ranking.crowding.size() != n) throw InvalidArgument("crowded_tournament: rank and crowding sizes differ");
  std::vector<std::size_t> chosen;
  chosen.reserve(count);
  for (std::size_t k = 0; k < count; ++k) {
    const std::size_t i = static_cast<std::size_t>(rng.next() % n);
    const std::size_t j = static_cast<std::size_t>(rng.next() % n);
    const std::size_t lo = std::min(i, j), hi = std::max(i, j);
    const bool hi_wins = ranking.rank[hi] < ranking.rank[lo] ||
                         (ranking.rank[hi] == ranking.rank[lo] && ranking.crowding[hi] > ranking.crowding[lo]);
    chosen.push_back(hi_wins ? hi : lo);
  }
  return chosen;
}

}  // namespace touchdown::search
