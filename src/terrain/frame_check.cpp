#include "touchdown/terrain/frame_check.hpp"

#include <Eigen/Geometry>
#include <algorithm>
#include <cmath>
#include <cstdint>
#include <vector>

#include "core/format.hpp"
#include "touchdown/core/error.hpp"
#include "touchdown/core/random.hpp"
#include "touchdown/core/statistics.hpp"
#include "touchdown/core/units.hpp"

namespace touchdown::terrain {
namespace {

constexpr std::size_t kMaxSamples = 20'000;
constexpr int kRansacIterations = 256;

struct Plane {
  Eigen::Vector3d normal = Eigen::Vector3d::UnitZ();
  Eigen::Vector3d point = Eigen::Vector3d::Zero();
  std::size_t inliers = 0;
};

std::size_t count_inliers(const std::vector<Eigen::Vector3d>& pts, const Eigen::Vector3d& n, const Eigen::Vector3d& a,
                          double tol) {
  std::size_t count = 0;
  for (const auto& p : pts) count += std::abs(n.dot(p - a)) < tol ? 1 : 0;
  return count;
}

// Least-squares refinement on the inliers of `plane`: in the plane's own
// frame (u, v, n) the offsets h = n·(p - c) are fitted as h = α u + β v
// (two unknowns, solved in closed form: no decomposition), which stays well
// conditioned for vertical planes too.
Plane refine(const std::vector<Eigen::Vector3d>& pts, Plane plane, double tol) {
  for (int pass = 0; pass < 2; ++pass) {
    const Eigen::Vector3d n = plane.normal;
    Eigen::Vector3d c = Eigen::Vector3d::Zero();
    std::size_t m = 0;
    for (const auto& p : pts) {
      if (std::abs(n.dot(p - plane.point)) < tol) {
        c += p;
        ++m;
      }
    }
    if (m < 3) return plane;
    c /= static_cast<double>(m);
    const Eigen::Vector3d u = n.unitOrthogonal(), v = n.cross(u);
    double saa = 0, sab = 0, sbb = 0, sah = 0, sbh = 0;
    for (const auto& p : pts) {
      if (std::abs(n.dot(p - plane.point)) >= tol) continue;
      const Eigen::Vector3d d = p - c;
      const double a = u.dot(d), b = v.dot(d), h = n.dot(d);
      saa += a * a;
      sab += a * b;
      sbb += b * b;
      sah += a * h;
      sbh += b * h;
    }
    const double det = saa * sbb - sab * sab;
    if (!(std::abs(det) > 1e-12 * (saa * sbb + 1e-300))) return plane;
    const double alpha = (sah * sbb - sbh * sab) / det, beta = (saa * sbh - sab * sah) / det;
    plane.normal = (n - alpha * u - beta * v).normalized();
    plane.point = c;
  }
  plane.inliers = count_inliers(pts, plane.normal, plane.point, tol);
  return plane;
}

double span(std::vector<double> values) {
  const std::size_t n = values.size();
  const std::size_t lo = n / 100, hi = n - 1 - n / 100;
  const double a = nth_smallest(std::span(values), lo);
  return nth_smallest(std::span(values), hi) - a;
}

}  // namespace

bool FrameCheckOptions::validate(std::string* why) const {
  if (!(max_tilt_deg > 0 && max_tilt_deg <= 90)) return invalid(why, "max_tilt_deg: must be in (0, 90]");
  if (!(max_height_ratio > 0) || !std::isfinite(max_height_ratio))
    return invalid(why, "max_height_ratio: must be positive");
  if (!(min_positive_fraction > 0 && min_positive_fraction <= 1))
    return invalid(why, "min_positive_fraction: must be in (0, 1]");
  if (min_points < 3) return invalid(why, "min_points: must be >= 3");
  return true;
}

FrameEvidence camera_frame_evidence(const PointCloud& cloud, const FrameCheckOptions& o) {
  std::string why;
  if (!o.validate(&why)) throw InvalidArgument("frame check options: " + why);
  FrameEvidence e;
  if (cloud.is_organized()) {
    e.rule = FrameRule::Organized;
    e.reason = "it is organized (" + std::to_string(cloud.width) + " x " + std::to_string(cloud.height) +
               " pixels), as a depth camera writes its frames";
    return e;
  }
  if (cloud.has_viewpoint()) {
    std::string viewpoint;
    for (std::size_t i = 0; i < cloud.viewpoint.size(); ++i) {
      viewpoint += (i ? " " : "") + detail::format_general(cloud.viewpoint[i]);
    }
    e.rule = FrameRule::Viewpoint;
    e.reason = "its PCD VIEWPOINT (" + viewpoint + ") is not the identity: a sensor pose recorded with the points";
    return e;
  }

  // Every stride-th finite point, at most kMaxSamples of them.
  std::size_t finite = 0;
  for (const auto& p : cloud.points) finite += p.allFinite() ? 1 : 0;
  if (finite < o.min_points) return e;
  const std::size_t stride = (finite + kMaxSamples - 1) / kMaxSamples;
  std::vector<Eigen::Vector3d> pts;
  pts.reserve(finite / stride + 1);
  std::size_t k = 0;
  for (const auto& p : cloud.points) {
    if (!p.allFinite()) continue;
    if (k++ % stride == 0) pts.push_back(p.cast<double>());
  }
  const std::size_t n = pts.size();
  Eigen::AlignedBox3d box;
  for (const auto& p : pts) box.extend(p);
  const double diagonal = box.diagonal().norm();
  if (!(diagonal > 0) || !std::isfinite(diagonal)) return e;
  const double tol = 0.01 * diagonal;

  // RANSAC for the dominant plane; a fixed stream: the same cloud always
  // gets the same answer.
  Rng rng(0x6672616d65ull);
  Plane best;
  auto pick = [&] { return std::min(n - 1, static_cast<std::size_t>(rng.uniform() * static_cast<double>(n))); };
  for (int it = 0; it < kRansacIterations; ++it) {
    const Eigen::Vector3d& a = pts[pick()];
    const Eigen::Vector3d& b = pts[pick()];
    const Eigen::Vector3d& c = pts[pick()];
    const Eigen::Vector3d cross = (b - a).cross(c - a);
    const double norm = cross.norm();
    if (!(norm > 1e-6 * diagonal * diagonal)) continue;  // (nearly) collinear sample
    const Eigen::Vector3d normal = cross / norm;
    const std::size_t inliers = count_inliers(pts, normal, a, tol);
    if (inliers > best.inliers) best = Plane{normal, a, inliers};
  }
  if (best.inliers < 3) return e;
  best = refine(pts, best, tol);
  if (best.normal.z() < 0) best.normal = -best.normal;

  e.plane_tilt_deg = rad_to_deg(std::acos(std::clamp(best.normal.z(), -1.0, 1.0)));
  e.plane_fraction = static_cast<double>(best.inliers) / static_cast<double>(n);
  e.plane_height = best.normal.z() > 1e-9 ? best.normal.dot(best.point) / best.normal.z() : FrameEvidence::kNaN;
  std::vector<double> xs(n), ys(n);
  std::size_t positive = 0;
  for (std::size_t i = 0; i < n; ++i) {
    xs[i] = pts[i].x();
    ys[i] = pts[i].y();
    positive += pts[i].z() > 0 ? 1 : 0;
  }
  e.extent = std::max(span(std::move(xs)), span(std::move(ys)));
  e.positive_fraction = static_cast<double>(positive) / static_cast<double>(n);

  const std::string share = detail::format_fixed(100 * e.plane_fraction, 0) + "% of the points";
  if (e.plane_tilt_deg > o.max_tilt_deg) {
    e.rule = FrameRule::TiltedPlane;
    e.reason = "its dominant plane (" + share + ") is tilted " + detail::format_fixed(e.plane_tilt_deg, 0) +
               " deg from horizontal, as the ground is in a forward-looking camera's optical frame (y down, z "
               "forward)";
  } else if (e.positive_fraction >= o.min_positive_fraction && e.plane_height > o.max_height_ratio * e.extent) {
    e.rule = FrameRule::DepthLike;
    e.reason = "z looks like depth: " + detail::format_fixed(100 * e.positive_fraction, 0) +
               "% of the points have z > 0 and the dominant plane (" + share + ") lies " +
               detail::format_fixed(e.plane_height, 2) + " m above the origin, " +
               detail::format_fixed(e.plane_height / std::max(e.extent, 1e-12), 2) + " x the cloud's " +
               detail::format_fixed(e.extent, 2) + " m width, as in a depth camera's optical frame (z forward)";
  }
  return e;
}

}  // namespace touchdown::terrain
