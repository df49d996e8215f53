// The landed drone's stance (stance.hpp).
#include "mission/stance.hpp"

#include <algorithm>
#include <cmath>
#include <limits>
#include <numbers>
#include <vector>

#include "core/convex_hull.hpp"
#include "touchdown/twin/flight_control.hpp"

namespace touchdown::mission::detail {
namespace {

constexpr double kPi = std::numbers::pi;

// A point with the radius of the sphere around it (a foot, a capsule's
// end, a disk's rim at its half thickness).
struct Ball {
  Eigen::Vector3d p;
  double r;
};

// How far the lowest strike part is above the support's plane, tilted by
// `tilt` about the horizontal axis at angle `phi` [m]: ≤ 0 strikes.
double clearance(const std::vector<Ball>& support, const std::vector<Ball>& parts, double phi, double tilt) {
  const Eigen::Matrix3d R =
      Eigen::AngleAxisd(tilt, Eigen::Vector3d(std::cos(phi), std::sin(phi), 0)).toRotationMatrix();
  const Eigen::RowVector3d z = R.row(2);
  double feet = std::numeric_limits<double>::infinity(), rest = feet;
  for (const Ball& b : support) feet = std::min(feet, z.dot(b.p) - b.r);
  for (const Ball& b : parts) rest = std::min(rest, z.dot(b.p) - b.r);
  return rest - feet;
}

}  // namespace

Stance stance_of(const twin::Airframe& af) {
  Stance s;
  std::vector<Ball> support, parts;
  for (const Eigen::Vector3d& q : af.support_points()) support.push_back({q, af.support_radius()});
  for (std::size_t i = 0; i < af.motor_count(); ++i) {
    const twin::Disk d = af.propeller(i);
    // The rim, 24 points, each with the disk's half thickness.
    const Eigen::Vector3d u = d.axis.unitOrthogonal(), v = d.axis.cross(u);
    for (int k = 0; k < 24; ++k) {
      const double a = 2 * kPi * k / 24;
      parts.push_back({d.centre + d.radius * (std::cos(a) * u + std::sin(a) * v), d.half_thickness});
    }
    const twin::Capsule arm = af.arm(i);
    parts.push_back({arm.a, arm.radius});
    parts.push_back({arm.b, arm.radius});
  }
  if (af.has_landing_gear()) {
    const twin::Box b = af.body_box();
    for (int k = 0; k < 8; ++k) {
      const Eigen::Vector3d c((k & 1) ? 1 : -1, (k & 2) ? 1 : -1, (k & 4) ? 1 : -1);
      parts.push_back({b.centre + b.half_extents.cwiseProduct(c), 0.0});
    }
  }
  // The support polygon seen from above and the centre of mass's distance
  // to its nearest edge.
  std::vector<Eigen::Vector2d> feet;
  for (const Ball& b : support) feet.emplace_back(b.p.head<2>());
  const std::vector<Eigen::Vector2d> hull = touchdown::detail::convex_hull(feet);  // counter-clockwise
  const Eigen::Vector3d com = af.centre_of_mass();
  double nearest = std::numeric_limits<double>::infinity();
  for (std::size_t i = 0; i < hull.size(); ++i) {
    const Eigen::Vector2d &a = hull[i], &b = hull[(i + 1) % hull.size()];
    nearest = std::min(nearest,
                       touchdown::detail::cross(a, b, com.head<2>()) / std::max((b - a).norm(), 1e-12));  // > 0 inside
  }
  // A round foot touches the pad below its centre: the drone starts to tip
  // about the line through the feet's centres, not their rims.
  s.inradius = hull.size() >= 3 && nearest > 0 ? nearest : 1e-3;
  s.com_height = com.z() - af.ground_z();
  for (const Ball& b : support) s.support.push_back(b.p - com);
  s.support_radius = af.support_radius();
  // The strike tilt: per direction the first tilt (0.25° steps) that
  // strikes, refined by bisection; the smallest over directions.
  double best = 0.5 * kPi;
  for (int k = 0; k < 72; ++k) {
    const double phi = 2 * kPi * k / 72;
    double lo = 0, hi = -1;
    for (double t = 0.25 * kPi / 180; t < best; t += 0.25 * kPi / 180) {
      if (clearance(support, parts, phi, t) <= 0) {
        hi = t;
        break;
      }
      lo = t;
    }
    if (hi < 0) continue;
    while (hi - lo > 1e-4) {
      const double mid = 0.5 * (lo + hi);
      (clearance(support, parts, phi, mid) <= 0 ? hi : lo) = mid;
    }
    best = std::min(best, hi);
  }
  s.strike_tilt = best;
  return s;
}

double upset_ratio(const Stance& s, double side, double mass, double friction, double hold_force) {
  const double weight = mass * twin::kStandardGravity, down = weight + hold_force;
  return std::max(
      {side / (friction * down), side * s.com_height / (down * s.inradius), side / (weight * std::tan(s.strike_tilt))});
}

double lowest_support(const Stance& s, const Eigen::Matrix3d& R) {
  double lowest = 0;
  for (const Eigen::Vector3d& q : s.support) lowest = std::min(lowest, R.row(2).dot(q));
  return lowest - s.support_radius;
}

double levelling_shift(const Stance& s, double tilt) {
  return s.inradius * (1 - std::cos(tilt)) + s.com_height * std::sin(tilt);
}

}  // namespace touchdown::mission::detail
