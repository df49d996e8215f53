#include "touchdown/twin/threshold.hpp"

#include <algorithm>
#include <cmath>
#include <limits>
#include <numbers>

namespace touchdown::twin {
namespace {

// Outward unit normal (in x, y) of the support-polygon edge a → b, given a
// point inside.
Eigen::Vector2d outward_normal(const Eigen::Vector2d& a, const Eigen::Vector2d& b, const Eigen::Vector2d& inside) {
  const Eigen::Vector2d e = (b - a).normalized();
  Eigen::Vector2d n(e.y(), -e.x());
  if (n.dot(inside - a) > 0) n = -n;
  return n;
}

// Lowest z of a disk.
double disk_lowest_z(const Eigen::Vector3d& c, const Eigen::Vector3d& n, double radius, double half_t) {
  const double nz = std::clamp(n.z(), -1.0, 1.0);
  return c.z() - radius * std::sqrt(std::max(0.0, 1.0 - nz * nz)) - half_t * std::abs(nz);
}

// Support polygon: indices of the support points on the convex hull in order.
std::vector<std::size_t> support_polygon(const Airframe& af, const std::vector<Eigen::Vector3d>& p) {
  const Eigen::Vector2d c = af.centre_of_mass().head<2>();
  std::vector<std::size_t> idx(p.size());
  for (std::size_t i = 0; i < p.size(); ++i) idx[i] = i;
  std::sort(idx.begin(), idx.end(), [&](std::size_t a, std::size_t b) {
    return std::atan2(p[a].y() - c.y(), p[a].x() - c.x()) < std::atan2(p[b].y() - c.y(), p[b].x() - c.x());
  });
  return idx;  // validate() guarantees every support point is a hull vertex and c is inside
}

}  // namespace

Eigen::Isometry3d pose_tilted_about_edge(const Airframe& af, std::size_t a, std::size_t b, double angle) {
  const auto support = af.support_points();
  const Eigen::Vector3d fa = support.at(a), fb = support.at(b);
  const Eigen::Vector2d n = outward_normal(fa.head<2>(), fb.head<2>(), af.centre_of_mass().head<2>());
  const Eigen::Vector3d u(n.x(), n.y(), 0.0);
  const Eigen::Vector3d axis = Eigen::Vector3d::UnitZ().cross(u);  // rotates +u downwards
  // Level pose: feet bottoms on z = 0.
  Eigen::Isometry3d level = Eigen::Isometry3d::Identity();
  level.translation() = Eigen::Vector3d(0, 0, -af.ground_z());
  const Eigen::Vector3d pivot = level * fa;
  Eigen::Isometry3d tilt = Eigen::Isometry3d::Identity();
  tilt.translate(pivot).rotate(Eigen::AngleAxisd(angle, axis)).translate(-pivot);
  return tilt * level;
}

Eigen::Isometry3d pose_standing(const Airframe& af, double x, double y, double ground_z, double yaw) {
  Eigen::Isometry3d T = Eigen::Isometry3d::Identity();
  T.linear() = Eigen::AngleAxisd(yaw, Eigen::Vector3d::UnitZ()).toRotationMatrix();
  T.translation() = Eigen::Vector3d(x, y, ground_z - af.ground_z());
  return T;
}

SafetyThreshold compute_safety_threshold(const Airframe& af) {
  SafetyThreshold t;
  const Eigen::Vector3d com = af.centre_of_mass();
  const auto support = af.support_points();
  const auto poly = support_polygon(af, support);
  const std::size_t n = poly.size();

  // (a) tip-over about each support edge.
  t.tip_rad = std::numeric_limits<double>::infinity();
  for (std::size_t k = 0; k < n; ++k) {
    const std::size_t a = poly[k], b = poly[(k + 1) % n];
    const Eigen::Vector3d& fa = support[a];
    const Eigen::Vector2d nrm = outward_normal(fa.head<2>(), support[b].head<2>(), com.head<2>());
    const double d = -(com.head<2>() - fa.head<2>()).dot(nrm);  // > 0: inside
    const double h = com.z() - fa.z();
    const double angle = std::atan2(d, h);
    if (angle < t.tip_rad) {
      t.tip_rad = angle;
      t.tip_foot_a = a;
      t.tip_foot_b = b;
    }
  }

  // (b) propeller (or arm) strike, pivoting about each foot in every outward
  // direction between the normals of its two edges (edges included).
  t.prop_strike_rad = std::numbers::pi / 2;
  for (std::size_t k = 0; k < n; ++k) {
    const std::size_t prev = poly[(k + n - 1) % n], cur = poly[k], next = poly[(k + 1) % n];
    const Eigen::Vector3d& pivot = support[cur];
    const Eigen::Vector2d n1 = outward_normal(support[prev].head<2>(), pivot.head<2>(), com.head<2>());
    const Eigen::Vector2d n2 = outward_normal(pivot.head<2>(), support[next].head<2>(), com.head<2>());
    const double a1 = std::atan2(n1.y(), n1.x());
    double a2 = std::atan2(n2.y(), n2.x());
    while (a2 < a1) a2 += 2 * std::numbers::pi;
    constexpr int kSamples = 90;
    for (int s = 0; s <= kSamples; ++s) {
      const double phi = a1 + (a2 - a1) * s / kSamples;
      const Eigen::Vector3d u(std::cos(phi), std::sin(phi), 0.0);
      const Eigen::Vector3d axis = Eigen::Vector3d::UnitZ().cross(u);
      // Clearance of the lowest propeller point above the ground plane.
      auto clearance = [&](double angle) {
        const Eigen::Matrix3d R = Eigen::AngleAxisd(angle, axis).toRotationMatrix();
        double lowest = std::numeric_limits<double>::infinity();
        for (std::size_t i = 0; i < af.motor_count(); ++i) {
          const Disk d = af.propeller(i);
          lowest =
              std::min(lowest, disk_lowest_z(pivot + R * (d.centre - pivot), R * d.axis, d.radius, d.half_thickness));
          // The arm (it reaches the ground first on a low-slung frame
          // without landing gear).
          const Capsule a = af.arm(i);
          lowest =
              std::min(lowest, std::min((pivot + R * (a.a - pivot)).z(), (pivot + R * (a.b - pivot)).z()) - a.radius);
        }
        return lowest - af.ground_z();
      };
      if (clearance(t.prop_strike_rad) > 0) continue;  // no strike before the best so far
      double lo = 0, hi = t.prop_strike_rad;
      for (int it = 0; it < 60; ++it) {
        const double mid = 0.5 * (lo + hi);
        (clearance(mid) > 0 ? lo : hi) = mid;
      }
      t.prop_strike_rad = hi;
    }
  }
  return t;
}

}  // namespace touchdown::twin
