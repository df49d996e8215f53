#pragma once
// The convex hull of points in the plane, private to the library and its
// apps (not installed): the one hull that the airframe check (are the feet a
// convex support polygon?) and the landing_plan figure (corridor outlines)
// use.
#include <Eigen/Core>
#include <cstddef>
#include <vector>

namespace touchdown::detail {

/// Indices into `points` of the vertices of their convex hull (Andrew's
/// monotone chain, O(n log n)):
/// - counter-clockwise (x right, y up), starting at the vertex of least x
///   (least y among equal x);
/// - only corners: a point on an edge between two others is dropped, and so
///   is a point within |cross| <= 1e-12 of an edge's line (absolute: the
///   coordinates' unit, metres or pixels, is the caller's);
/// - each point once: of equal points the one with the least index stands
///   for them all;
/// - degenerate sets give what they span: no points → {}; one distinct point
///   → {it}; points on one line → {its two ends}. A polygon has 3 or more.
/// Non-finite coordinates are the caller's to leave out.
std::vector<std::size_t> convex_hull_indices(const std::vector<Eigen::Vector2d>& points);

/// The hull's vertices themselves, in the order of convex_hull_indices().
std::vector<Eigen::Vector2d> convex_hull(const std::vector<Eigen::Vector2d>& points);

/// Twice the signed area of the triangle (o, a, b): > 0 when o → a → b turns
/// counter-clockwise, 0 when the three are on one line.
inline double cross(const Eigen::Vector2d& o, const Eigen::Vector2d& a, const Eigen::Vector2d& b) {
  return (a.x() - o.x()) * (b.y() - o.y()) - (a.y() - o.y()) * (b.x() - o.x());
}

}  // namespace touchdown::detail
