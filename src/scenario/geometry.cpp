// Solids of the drone and of the scenario objects (geometry.hpp). Objects
// are a few primitives each: enough for collisions and a recognisable
// silhouette in the camera, cheap for both.
#include "touchdown/scenario/geometry.hpp"

#include <algorithm>
#include <cmath>

#include "touchdown/core/units.hpp"
#include "touchdown/twin/airframe.hpp"

namespace touchdown::scenario {

namespace {

using Bgr = std::array<std::uint8_t, 3>;

Solid box(const Eigen::Vector3d& centre, const Eigen::Vector3d& extents, Bgr bgr) {
  Solid s;
  s.shape = Solid::Shape::Box;
  s.pose = Eigen::Translation3d(centre) * Eigen::Isometry3d::Identity();
  s.size = extents;
  s.bgr = bgr;
  return s;
}

/// A solid of revolution (cylinder, cone, capsule) between two points.
Solid along(Solid::Shape shape, const Eigen::Vector3d& a, const Eigen::Vector3d& b, double radius, Bgr bgr) {
  Solid s;
  s.shape = shape;
  const Eigen::Vector3d axis = b - a;
  const double length = axis.norm();
  const Eigen::Quaterniond q = length > 0 ? Eigen::Quaterniond::FromTwoVectors(Eigen::Vector3d::UnitZ(), axis / length)
                                          : Eigen::Quaterniond::Identity();
  s.pose = Eigen::Translation3d(0.5 * (a + b)) * q;
  s.size = Eigen::Vector3d(radius, radius, length);
  s.bgr = bgr;
  return s;
}

Solid sphere(const Eigen::Vector3d& centre, double radius, Bgr bgr) {
  Solid s;
  s.shape = Solid::Shape::Sphere;
  s.pose = Eigen::Translation3d(centre) * Eigen::Isometry3d::Identity();
  s.size = Eigen::Vector3d::Constant(radius);
  s.bgr = bgr;
  return s;
}

Eigen::Vector3d up(double z) { return Eigen::Vector3d(0, 0, z); }

}  // namespace

std::vector<Solid> drone_solids(const twin::Airframe& a) {
  std::vector<Solid> out;
  out.push_back(box(Eigen::Vector3d::Zero(), a.body_size, {40, 40, 40}));
  for (std::size_t i = 0; i < a.motor_count(); ++i) {
    const twin::Capsule arm = a.arm(i);
    out.push_back(along(Solid::Shape::Capsule, arm.a, arm.b, arm.radius, {40, 40, 40}));
    const twin::Disk prop = a.propeller(i);
    out.push_back(along(Solid::Shape::Cylinder, prop.centre - prop.half_thickness * prop.axis,
                        prop.centre + prop.half_thickness * prop.axis, prop.radius, {20, 20, 20}));
  }
  for (std::size_t i = 0; i < a.legs.size(); ++i) {
    const twin::Capsule leg = a.leg(i);
    out.push_back(along(Solid::Shape::Capsule, leg.a, leg.b, leg.radius, {40, 40, 40}));
    const twin::Sphere foot = a.foot(i);
    out.push_back(sphere(foot.centre, foot.radius, {40, 40, 40}));
  }
  return out;
}

std::vector<Solid> object_solids(const StaticObject& o) {
  std::vector<Solid> local;  // in the object's frame: origin on the ground at its middle
  const Eigen::Vector3d& s = o.size;
  switch (o.kind) {
    case StaticKind::Box:
      local.push_back(box(up(0.5 * s.z()), s, {70, 120, 170}));  // cardboard
      break;
    case StaticKind::Chair: {
      // size = seat width, seat depth, back height; seat at 45 % of the back.
      const double seat = 0.45 * s.z(), t = std::min(0.05, 0.2 * seat), leg = std::min(0.04, 0.2 * s.x());
      const Bgr wood{40, 60, 90};
      local.push_back(box(up(seat - 0.5 * t), Eigen::Vector3d(s.y(), s.x(), t), wood));
      for (int i = 0; i < 4; ++i) {
        const double x = (i < 2 ? 0.5 : -0.5) * (s.y() - leg), y = (i % 2 ? 0.5 : -0.5) * (s.x() - leg);
        local.push_back(box(Eigen::Vector3d(x, y, 0.5 * (seat - t)), Eigen::Vector3d(leg, leg, seat - t), wood));
      }
      local.push_back(box(Eigen::Vector3d(-0.5 * (s.y() - t), 0, seat + 0.5 * (s.z() - seat)),
                          Eigen::Vector3d(t, s.x(), s.z() - seat), wood));
      break;
    }
    case StaticKind::Pole:
      local.push_back(along(Solid::Shape::Cylinder, up(0), up(s.z()), 0.5 * s.x(), {150, 150, 150}));
      break;
    case StaticKind::Tree: {
      // size = crown diameter, trunk diameter, height.
      const double crown = std::min(0.5 * s.x(), 0.45 * s.z());
      const double trunk_top = s.z() - crown;
      local.push_back(along(Solid::Shape::Cylinder, up(0), up(trunk_top + 0.25 * crown), 0.5 * s.y(), {30, 60, 90}));
      local.push_back(sphere(up(trunk_top), crown, {40, 120, 50}));
      break;
    }
  }
  const Eigen::Isometry3d T_world_object = Eigen::Translation3d(o.position.x(), o.position.y(), 0) *
                                           Eigen::AngleAxisd(deg_to_rad(o.yaw_deg), Eigen::Vector3d::UnitZ());
  for (auto& solid : local) solid.pose = T_world_object * solid.pose;
  return local;
}

std::vector<Solid> object_solids(const DynamicObject& o) {
  std::vector<Solid> out;
  const Eigen::Vector3d& s = o.size;  // length, width, height
  switch (o.kind) {
    case DynamicKind::Person: {
      // Legs and torso as one cylinder to the shoulders, head on top.
      const double head = 0.065 * s.z();
      const double shoulders = s.z() - 2 * head;
      out.push_back(along(Solid::Shape::Cylinder, up(0), up(shoulders), 0.5 * std::min(s.x(), s.y()), {120, 70, 40}));
      out.push_back(box(up(0.75 * shoulders), Eigen::Vector3d(0.8 * s.x(), s.y(), 0.45 * shoulders), {120, 70, 40}));
      out.push_back(sphere(up(shoulders + head), head, {130, 160, 205}));
      break;
    }
    case DynamicKind::Dog: {
      const double leg = 0.5 * s.z(), body = 0.3 * s.z();
      const Bgr fur{50, 95, 145};
      out.push_back(box(up(leg + 0.5 * body), Eigen::Vector3d(0.75 * s.x(), s.y(), body), fur));
      const double r = std::min(0.04, 0.15 * s.y());
      for (int i = 0; i < 4; ++i) {
        const double x = (i < 2 ? 0.3 : -0.3) * s.x(), y = (i % 2 ? 0.35 : -0.35) * s.y();
        out.push_back(along(Solid::Shape::Cylinder, Eigen::Vector3d(x, y, 0), Eigen::Vector3d(x, y, leg), r, fur));
      }
      const double head = std::min(0.125 * s.x(), 0.2 * s.z());
      out.push_back(sphere(Eigen::Vector3d(0.5 * s.x() - head, 0, s.z() - head), head, fur));
      break;
    }
    case DynamicKind::Bird: {
      // Body along x, wings spanning y; the origin is the bird's centre.
      const double r = 0.5 * s.z();
      const double body = std::max(0.0, s.x() - 2 * r);
      out.push_back(along(Solid::Shape::Capsule, Eigen::Vector3d(-0.5 * body, 0, 0), Eigen::Vector3d(0.5 * body, 0, 0),
                          r, {70, 70, 70}));
      out.push_back(box(Eigen::Vector3d::Zero(), Eigen::Vector3d(0.4 * s.x(), s.y(), std::min(0.02, r)), {60, 60, 60}));
      break;
    }
  }
  return out;
}

}  // namespace touchdown::scenario
