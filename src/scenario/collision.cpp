// The drone's collisions with scenario objects, with FCL 0.7 (GJK/EPA on
// the primitive shapes, after the FCL documentation's collide/distance
// examples). FCL's template-heavy headers stay in this one file.
#include <fcl/geometry/shape/box.h>
#include <fcl/geometry/shape/capsule.h>
#include <fcl/geometry/shape/cone.h>
#include <fcl/geometry/shape/cylinder.h>
#include <fcl/geometry/shape/sphere.h>
#include <fcl/narrowphase/collision.h>
#include <fcl/narrowphase/collision_object.h>
#include <fcl/narrowphase/distance.h>

#include <limits>

#include "touchdown/core/error.hpp"
#include "touchdown/scenario/geometry.hpp"

namespace touchdown::scenario {

namespace {

std::shared_ptr<fcl::CollisionGeometryd> make_geometry(const Solid& s) {
  if (!s.size.allFinite() || (s.size.array() < 0).any())
    throw InvalidArgument("collision: a solid's size must be finite and not negative");
  switch (s.shape) {
    case Solid::Shape::Box:
      return std::make_shared<fcl::Boxd>(s.size.x(), s.size.y(), s.size.z());
    case Solid::Shape::Cylinder:
      return std::make_shared<fcl::Cylinderd>(s.size.x(), s.size.z());
    case Solid::Shape::Cone:
      return std::make_shared<fcl::Coned>(s.size.x(), s.size.z());
    case Solid::Shape::Sphere:
      return std::make_shared<fcl::Sphered>(s.size.x());
    case Solid::Shape::Capsule:
      return std::make_shared<fcl::Capsuled>(s.size.x(), s.size.z());
  }
  throw InvalidArgument("collision: unknown solid shape");
}

/// Radius of a sphere about the solid's centre that holds it.
double bounding_radius(const Solid& s) {
  switch (s.shape) {
    case Solid::Shape::Box:
      return 0.5 * s.size.norm();
    case Solid::Shape::Cylinder:
    case Solid::Shape::Cone:
      return std::hypot(s.size.x(), 0.5 * s.size.z());
    case Solid::Shape::Sphere:
      return s.size.x();
    case Solid::Shape::Capsule:
      return s.size.x() + 0.5 * s.size.z();
  }
  return 0;
}

struct Part {
  std::shared_ptr<fcl::CollisionGeometryd> geometry;
  Eigen::Isometry3d pose;  // in its owner's frame
  Eigen::Vector3d centre;  // bounding sphere, owner frame
  double radius;
};

struct Body {
  std::vector<Part> parts;
  Eigen::Vector3d centre = Eigen::Vector3d::Zero();  // of the whole body, owner frame
  double radius = 0;
};

Body make_body(const std::vector<Solid>& solids) {
  Body b;
  for (const auto& s : solids) b.parts.push_back({make_geometry(s), s.pose, s.pose.translation(), bounding_radius(s)});
  if (b.parts.empty()) return b;
  // A bounding sphere about the mean of the part centres: not the smallest,
  // but it holds every part.
  for (const auto& p : b.parts) b.centre += p.centre;
  b.centre /= static_cast<double>(b.parts.size());
  for (const auto& p : b.parts) b.radius = std::max(b.radius, (p.centre - b.centre).norm() + p.radius);
  return b;
}

fcl::Transform3d to_fcl(const Eigen::Isometry3d& T) {
  fcl::Transform3d t = fcl::Transform3d::Identity();
  t.linear() = T.linear();
  t.translation() = T.translation();
  return t;
}

bool spheres_apart(const Eigen::Vector3d& a, double ra, const Eigen::Vector3d& b, double rb, double margin = 0) {
  return (a - b).squaredNorm() > (ra + rb + margin) * (ra + rb + margin);
}

}  // namespace

struct CollisionChecker::Impl {
  Body drone;
  std::vector<Body> objects;

  void check_index(int i) const {
    if (i < 0 || i >= static_cast<int>(objects.size()))
      throw InvalidArgument("collision: no object " + std::to_string(i));
  }

  bool collide(int i, const Eigen::Isometry3d& T_wb, const Eigen::Isometry3d& T_wo, Proximity* contact) const {
    const Body& o = objects[static_cast<std::size_t>(i)];
    if (spheres_apart(T_wb * drone.centre, drone.radius, T_wo * o.centre, o.radius)) return false;
    bool hit = false;
    double deepest = 0;
    for (const auto& dp : drone.parts) {
      const Eigen::Isometry3d T_d = T_wb * dp.pose;
      for (const auto& op : o.parts) {
        const Eigen::Isometry3d T_o = T_wo * op.pose;
        if (spheres_apart(T_d.translation(), dp.radius, T_o.translation(), op.radius)) continue;
        const fcl::CollisionObjectd a(dp.geometry, to_fcl(T_d)), b(op.geometry, to_fcl(T_o));
        fcl::CollisionRequestd request(1, contact != nullptr);
        fcl::CollisionResultd result;
        if (fcl::collide(&a, &b, request, result) == 0) continue;
        if (!contact) return true;
        const auto& c = result.getContact(0);
        if (!hit || c.penetration_depth > deepest) {
          deepest = c.penetration_depth;
          contact->object = i;
          contact->distance = -std::max(0.0, c.penetration_depth);
          contact->p_drone = c.pos;
          contact->p_object = c.pos;
        }
        hit = true;
      }
    }
    return hit;
  }

  Proximity distance(int i, const Eigen::Isometry3d& T_wb, const Eigen::Isometry3d& T_wo) const {
    const Body& o = objects[static_cast<std::size_t>(i)];
    Proximity best;
    best.object = i;
    best.distance = std::numeric_limits<double>::infinity();
    for (const auto& dp : drone.parts) {
      const Eigen::Isometry3d T_d = T_wb * dp.pose;
      for (const auto& op : o.parts) {
        const Eigen::Isometry3d T_o = T_wo * op.pose;
        const fcl::CollisionObjectd a(dp.geometry, to_fcl(T_d)), b(op.geometry, to_fcl(T_o));
        fcl::DistanceRequestd request(true);
        fcl::DistanceResultd result;
        fcl::distance(&a, &b, request, result);
        const double d = std::max(0.0, result.min_distance);
        if (d < best.distance) {
          best.distance = d;
          best.p_drone = result.nearest_points[0];
          best.p_object = result.nearest_points[1];
        }
      }
    }
    return best;
  }
};

CollisionChecker::CollisionChecker(const std::vector<Solid>& drone_in_body) : impl_(std::make_unique<Impl>()) {
  if (drone_in_body.empty()) throw InvalidArgument("collision: the drone has no solids");
  impl_->drone = make_body(drone_in_body);
}
CollisionChecker::~CollisionChecker() = default;
CollisionChecker::CollisionChecker(CollisionChecker&&) noexcept = default;
CollisionChecker& CollisionChecker::operator=(CollisionChecker&&) noexcept = default;

int CollisionChecker::add_object(const std::vector<Solid>& solids) {
  if (solids.empty()) throw InvalidArgument("collision: an object has no solids");
  impl_->objects.push_back(make_body(solids));
  return static_cast<int>(impl_->objects.size()) - 1;
}

int CollisionChecker::object_count() const { return static_cast<int>(impl_->objects.size()); }

bool CollisionChecker::collide(int object, const Eigen::Isometry3d& T_world_body,
                               const Eigen::Isometry3d& T_world_object, Proximity* contact) const {
  impl_->check_index(object);
  return impl_->collide(object, T_world_body, T_world_object, contact);
}

Proximity CollisionChecker::distance(int object, const Eigen::Isometry3d& T_world_body,
                                     const Eigen::Isometry3d& T_world_object) const {
  impl_->check_index(object);
  return impl_->distance(object, T_world_body, T_world_object);
}

Proximity CollisionChecker::first_collision(const Eigen::Isometry3d& T_world_body,
                                            const std::vector<Eigen::Isometry3d>& T_world_objects) const {
  if (T_world_objects.size() != impl_->objects.size())
    throw InvalidArgument("collision: " + std::to_string(T_world_objects.size()) + " poses for " +
                          std::to_string(impl_->objects.size()) + " objects");
  Proximity contact;
  for (int i = 0; i < object_count(); ++i) {
    if (impl_->collide(i, T_world_body, T_world_objects[static_cast<std::size_t>(i)], &contact)) return contact;
  }
  contact.object = -1;
  return contact;
}

}  // namespace touchdown::scenario
