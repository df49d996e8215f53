#include "convex_hull.hpp"

#include <algorithm>

namespace touchdown::detail {
namespace {

// A turn this close to straight counts as straight: collinear points drop.
constexpr double kStraight = 1e-12;

}  // namespace

std::vector<std::size_t> convex_hull_indices(const std::vector<Eigen::Vector2d>& p) {
  // Sorted by (x, y), ties by index, equal points after the first dropped.
  std::vector<std::size_t> idx(p.size());
  for (std::size_t i = 0; i < p.size(); ++i) idx[i] = i;
  std::sort(idx.begin(), idx.end(), [&](std::size_t a, std::size_t b) {
    if (p[a].x() != p[b].x()) return p[a].x() < p[b].x();
    if (p[a].y() != p[b].y()) return p[a].y() < p[b].y();
    return a < b;
  });
  idx.erase(std::unique(idx.begin(), idx.end(), [&](std::size_t a, std::size_t b) { return p[a] == p[b]; }), idx.end());
  if (idx.size() < 2) return idx;

  // Lower chain left to right, then upper chain right to left; a point that
  // does not turn the chain counter-clockwise leaves it.
  std::vector<std::size_t> h(2 * idx.size());
  std::size_t k = 0;
  for (const std::size_t i : idx) {
    while (k >= 2 && cross(p[h[k - 2]], p[h[k - 1]], p[i]) <= kStraight) --k;
    h[k++] = i;
  }
  for (std::size_t j = idx.size() - 1, lower = k + 1; j-- > 0;) {
    while (k >= lower && cross(p[h[k - 2]], p[h[k - 1]], p[idx[j]]) <= kStraight) --k;
    h[k++] = idx[j];
  }
  h.resize(k - 1);  // the last point is the first again
  return h;
}

std::vector<Eigen::Vector2d> convex_hull(const std::vector<Eigen::Vector2d>& points) {
  std::vector<Eigen::Vector2d> out;
  for (const std::size_t i : convex_hull_indices(points)) out.push_back(points[i]);
  return out;
}

}  // namespace touchdown::detail
