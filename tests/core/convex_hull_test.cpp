// The convex hull of src/core/convex_hull.hpp against a brute-force
// reference (a point is a hull vertex iff it does not lie inside or on the
// hull of the other points) over random point sets, with the degenerate
// cases spelled out: duplicates, collinear points, fewer than 3 points.
#include "core/convex_hull.hpp"

#include <gtest/gtest.h>

#include <algorithm>
#include <random>
#include <set>
#include <utility>

namespace {

using touchdown::detail::convex_hull;
using touchdown::detail::convex_hull_indices;
using touchdown::detail::cross;
using V = Eigen::Vector2d;

// p within the closed triangle (a, b, c), any orientation, degenerate ones
// included (exact: the tests use integer coordinates).
bool in_triangle(const V& p, const V& a, const V& b, const V& c) {
  const double d1 = cross(a, b, p), d2 = cross(b, c, p), d3 = cross(c, a, p);
  const bool has_neg = d1 < 0 || d2 < 0 || d3<0, has_pos = d1> 0 || d2 > 0 || d3 > 0;
  if (has_neg && has_pos) return false;
  if (cross(a, b, c) != 0) return true;
  // Degenerate triangle: p must lie on one of its segments.
  auto on_segment = [&](const V& u, const V& w) {
    return cross(u, w, p) == 0 && std::min(u.x(), w.x()) <= p.x() && p.x() <= std::max(u.x(), w.x()) &&
           std::min(u.y(), w.y()) <= p.y() && p.y() <= std::max(u.y(), w.y());
  };
  return on_segment(a, b) || on_segment(b, c) || on_segment(c, a);
}

// Brute force: the distinct points that are not in the convex hull of the
// other distinct points (Carathéodory: inside the hull means inside a
// triangle of three of them, or on a segment of two, or equal to one).
std::set<std::pair<double, double>> reference_vertices(const std::vector<V>& pts) {
  std::vector<V> distinct;
  for (const V& p : pts) {
    if (std::none_of(distinct.begin(), distinct.end(), [&](const V& q) { return q == p; })) distinct.push_back(p);
  }
  std::set<std::pair<double, double>> out;
  const std::size_t n = distinct.size();
  for (std::size_t i = 0; i < n; ++i) {
    bool inside = false;
    for (std::size_t a = 0; a < n && !inside; ++a) {
      for (std::size_t b = a; b < n && !inside; ++b) {
        for (std::size_t c = b; c < n && !inside; ++c) {
          if (a == i || b == i || c == i) continue;
          inside = in_triangle(distinct[i], distinct[a], distinct[b], distinct[c]);
        }
      }
    }
    if (!inside) out.insert({distinct[i].x(), distinct[i].y()});
  }
  return out;
}

TEST(ConvexHull, MatchesBruteForceOnRandomIntegerPoints) {
  std::mt19937 rng(11);
  for (int trial = 0; trial < 400; ++trial) {
    // Small grids make duplicates and collinear triples common.
    const int grid = trial % 3 == 0 ? 3 : trial % 3 == 1 ? 6 : 50;
    std::uniform_int_distribution<int> coord(-grid, grid);
    std::uniform_int_distribution<int> count(0, 14);
    std::vector<V> pts(static_cast<std::size_t>(count(rng)));
    for (auto& p : pts) {
      const double y = coord(rng);  // one draw per statement: y first, as recorded
      p = V(coord(rng), y);
    }

    const auto idx = convex_hull_indices(pts);
    const auto ref = reference_vertices(pts);
    std::set<std::pair<double, double>> got;
    for (const std::size_t i : idx) got.insert({pts[i].x(), pts[i].y()});
    ASSERT_EQ(got.size(), idx.size()) << "a vertex twice, trial " << trial;
    // Degenerate sets give their extreme points (one, or the two ends of a
    // segment): the reference's vertices of a segment are its two ends too.
    ASSERT_EQ(got, ref) << "trial " << trial;

    // Each point once, the least index of equal points.
    for (const std::size_t i : idx) {
      for (std::size_t j = 0; j < i; ++j) ASSERT_NE(pts[j], pts[i]) << "trial " << trial;
    }
    if (idx.size() >= 3) {
      // Counter-clockwise and strictly convex: every turn is to the left.
      for (std::size_t k = 0; k < idx.size(); ++k) {
        const V& a = pts[idx[k]];
        const V& b = pts[idx[(k + 1) % idx.size()]];
        const V& c = pts[idx[(k + 2) % idx.size()]];
        ASSERT_GT(cross(a, b, c), 0) << "trial " << trial;
      }
    }
    if (!idx.empty()) {
      // Starts at the least (x, y).
      for (const V& p : pts) {
        const V& s = pts[idx.front()];
        ASSERT_TRUE(s.x() < p.x() || (s.x() == p.x() && s.y() <= p.y())) << "trial " << trial;
      }
    }
  }
}

TEST(ConvexHull, RandomRealPointsAreConvexAndContainEveryPoint) {
  std::mt19937 rng(5);
  std::normal_distribution<double> g(0, 1);
  for (int trial = 0; trial < 100; ++trial) {
    std::vector<V> pts(50);
    for (auto& p : pts) {
      const double y = g(rng);
      p = V(g(rng), y);
    }
    const auto hull = convex_hull(pts);
    ASSERT_GE(hull.size(), 3u);
    for (std::size_t k = 0; k < hull.size(); ++k) {
      const V& a = hull[k];
      const V& b = hull[(k + 1) % hull.size()];
      ASSERT_GT(cross(a, b, hull[(k + 2) % hull.size()]), 0);
      for (const V& p : pts) ASSERT_GE(cross(a, b, p), -1e-12);  // every point left of or on each edge
    }
  }
}

TEST(ConvexHull, Square) {
  const std::vector<V> pts = {{1, 1}, {0, 0}, {0.5, 0.5}, {1, 0}, {0, 1}, {0.5, 0}};
  // Counter-clockwise from the least (x, y); the centre and the edge's
  // midpoint (0.5, 0) are dropped.
  EXPECT_EQ(convex_hull_indices(pts), (std::vector<std::size_t>{1, 3, 0, 4}));
}

TEST(ConvexHull, DuplicatesStandOnceByTheirFirstIndex) {
  const std::vector<V> pts = {{0, 0}, {2, 0}, {0, 2}, {2, 0}, {0, 0}};
  EXPECT_EQ(convex_hull_indices(pts), (std::vector<std::size_t>{0, 1, 2}));
}

TEST(ConvexHull, DegenerateSets) {
  EXPECT_TRUE(convex_hull_indices({}).empty());
  EXPECT_EQ(convex_hull_indices({V(1, 2)}), (std::vector<std::size_t>{0}));
  EXPECT_EQ(convex_hull_indices({V(1, 2), V(1, 2)}), (std::vector<std::size_t>{0}));
  EXPECT_EQ(convex_hull_indices({V(3, 0), V(1, 2)}), (std::vector<std::size_t>{1, 0}));
  // Collinear: the two ends.
  EXPECT_EQ(convex_hull_indices({V(1, 1), V(0, 0), V(3, 3), V(2, 2)}), (std::vector<std::size_t>{1, 2}));
  // Within 1e-12 of a line counts as on it.
  EXPECT_EQ(convex_hull_indices({V(0, 0), V(1, 1e-13), V(2, 0)}), (std::vector<std::size_t>{0, 2}));
}

}  // namespace
