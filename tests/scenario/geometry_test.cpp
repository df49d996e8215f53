// Collision geometry against hand-computed cases (FCL distance and contact),
// with the drone as its real shape.
#include "touchdown/scenario/geometry.hpp"

#include <gtest/gtest.h>

#include <cmath>
#include <numbers>

#include "touchdown/core/error.hpp"
#include "touchdown/twin/airframe.hpp"

namespace touchdown::scenario {
namespace {

Solid geo_solid(Solid::Shape shape, const Eigen::Vector3d& centre, const Eigen::Vector3d& size) {
  Solid s;
  s.shape = shape;
  s.pose = Eigen::Translation3d(centre) * Eigen::Isometry3d::Identity();
  s.size = size;
  return s;
}

Eigen::Isometry3d geo_at(double x, double y, double z, double yaw_deg = 0) {
  return Eigen::Translation3d(x, y, z) * Eigen::AngleAxisd(yaw_deg * std::numbers::pi / 180, Eigen::Vector3d::UnitZ());
}

const Eigen::Isometry3d kIdentity = Eigen::Isometry3d::Identity();

TEST(CollisionChecker, SphereAgainstBoxDistanceAndPenetration) {
  CollisionChecker c({geo_solid(Solid::Shape::Sphere, Eigen::Vector3d::Zero(), Eigen::Vector3d::Constant(0.5))});
  const int box = c.add_object({geo_solid(Solid::Shape::Box, Eigen::Vector3d(0, 0, 0.5), Eigen::Vector3d(1, 1, 1))});
  // Sphere centre 2 m from the box centre along x: 2 - 0.5 - 0.5 = 1 m apart.
  const Proximity far = c.distance(box, geo_at(2, 0, 0.5), kIdentity);
  EXPECT_NEAR(far.distance, 1.0, 1e-6);
  EXPECT_NEAR(far.p_drone.x(), 1.5, 1e-4);
  EXPECT_NEAR(far.p_object.x(), 0.5, 1e-4);
  EXPECT_FALSE(c.collide(box, geo_at(2, 0, 0.5), kIdentity));
  // 0.9 m: 0.1 m deep.
  Proximity hit;
  ASSERT_TRUE(c.collide(box, geo_at(0.9, 0, 0.5), kIdentity, &hit));
  EXPECT_NEAR(hit.distance, -0.1, 1e-3);
  EXPECT_EQ(hit.object, box);
  // Diagonal: from (1.5, 1.5, 0.5) the nearest box point is the edge (0.5, 0.5).
  EXPECT_NEAR(c.distance(box, geo_at(1.5, 1.5, 0.5), kIdentity).distance, std::sqrt(2.0) - 0.5, 1e-6);
}

TEST(CollisionChecker, F450AgainstAPoleIsTheRotorDiskNotTheCentre) {
  const twin::Airframe f450;
  CollisionChecker c(drone_solids(f450));
  StaticObject pole;
  pole.kind = StaticKind::Pole;
  pole.position = {1.0, 0.0};
  pole.size = {0.2, 0.2, 5.0};
  const int i = c.add_object(object_solids(pole));
  // Yaw 0: motors at 45° + k·90° on radius 0.225; the nearest rotor disk
  // (radius 0.127) is centred at (r/√2, ±r/√2), the pole's axis at (1, 0).
  const double m = f450.motor_radius / std::sqrt(2.0);
  const double expected = std::hypot(1.0 - m, m) - f450.prop_radius - 0.1;
  EXPECT_NEAR(c.distance(i, geo_at(0, 0, 2), kIdentity).distance, expected, 1e-4);
  // Yaw 45°: a motor on the x axis, the disk's edge at 0.225 + 0.127.
  EXPECT_NEAR(c.distance(i, geo_at(0, 0, 2, 45), kIdentity).distance, 1.0 - f450.motor_radius - f450.prop_radius - 0.1,
              1e-4);
  // Move the drone until the disk's edge is 1 cm into the pole: a collision
  // although the body centre is 0.55 m away.
  const double x = 1.0 - 0.1 - f450.motor_radius - f450.prop_radius + 0.01;
  Proximity hit;
  ASSERT_TRUE(c.collide(i, geo_at(x, 0, 2, 45), kIdentity, &hit));
  EXPECT_NEAR(hit.distance, -0.01, 2e-3);
  EXPECT_NEAR(hit.p_drone.x(), 0.9, 0.02);
  EXPECT_FALSE(c.collide(i, geo_at(x - 0.02, 0, 2, 45), kIdentity));
}

TEST(CollisionChecker, LandingOnABoxTouchesWithTheFeet) {
  const twin::Airframe f450;
  CollisionChecker c(drone_solids(f450));
  StaticObject crate;
  crate.kind = StaticKind::Box;
  crate.size = {1.0, 1.0, 0.6};
  const int i = c.add_object(object_solids(crate));
  // Feet bottoms at body z + foot_z - foot_radius: 5 mm above the top, then 5 mm into it.
  const double z_touch = 0.6 - (f450.foot_z - f450.foot_radius);
  EXPECT_NEAR(c.distance(i, geo_at(0, 0, z_touch + 0.005), kIdentity).distance, 0.005, 1e-5);
  Proximity hit;
  ASSERT_TRUE(c.collide(i, geo_at(0, 0, z_touch - 0.005), kIdentity, &hit));
  EXPECT_NEAR(hit.p_drone.z(), 0.6, 0.01);
}

TEST(CollisionChecker, MovingObjectPoseAndFirstCollisionOrder) {
  const twin::Airframe f450;
  CollisionChecker c(drone_solids(f450));
  DynamicObject bird;
  bird.kind = DynamicKind::Bird;
  bird.size = {0.3, 0.6, 0.12};
  DynamicObject person;
  person.kind = DynamicKind::Person;
  person.size = {0.3, 0.5, 1.8};
  const int b = c.add_object(object_solids(bird));
  const int p = c.add_object(object_solids(person));
  const Eigen::Isometry3d drone = geo_at(0, 0, 5);
  // The bird's body capsule (radius 0.06) centred 1 m to the side at the
  // drone's height: the nearest drone part is a rotor disk.
  std::vector<Eigen::Isometry3d> poses{geo_at(0, 1.0, 5.0 + f450.prop_height + f450.motor_z), geo_at(10, 0, 0)};
  EXPECT_EQ(c.first_collision(drone, poses).object, -1);
  const double reach = f450.motor_radius / std::sqrt(2.0) + f450.prop_radius;
  poses[0] = geo_at(0, reach + 0.05, 5.0 + f450.prop_height + f450.motor_z);
  EXPECT_EQ(c.first_collision(drone, poses).object, b);
  // The person right under the drone: the head's top (1.8 m) meets the
  // body box's bottom (body centre − 0.03 m); the legs straddle the head.
  poses[0] = geo_at(10, 10, 5);
  poses[1] = geo_at(0, 0, 0);
  const double bottom = 0.5 * f450.body_size.z();
  EXPECT_EQ(c.first_collision(geo_at(0, 0, 1.8 + bottom + 0.01), poses).object, -1);
  EXPECT_EQ(c.first_collision(geo_at(0, 0, 1.8 + bottom - 0.01), poses).object, p);
  EXPECT_THROW(c.first_collision(drone, {drone}), InvalidArgument);
  EXPECT_THROW(c.distance(5, drone, drone), InvalidArgument);
}

TEST(ObjectSolids, HeightsAndFootprintsFollowTheSize) {
  for (StaticKind kind : {StaticKind::Box, StaticKind::Chair, StaticKind::Pole, StaticKind::Tree}) {
    StaticObject o;
    o.kind = kind;
    o.position = {3, -2};
    o.yaw_deg = 30;
    o.size = kind == StaticKind::Tree ? Eigen::Vector3d(3, 0.3, 6) : Eigen::Vector3d(0.5, 0.5, 1.2);
    CollisionChecker c({geo_solid(Solid::Shape::Sphere, Eigen::Vector3d::Zero(), Eigen::Vector3d::Constant(0.01))});
    const int i = c.add_object(object_solids(o));
    // A tiny probe just above the top misses, just below the top (over the centre) hits.
    const double top = o.size.z();
    EXPECT_FALSE(c.collide(i, geo_at(3, -2, top + 0.02), kIdentity)) << to_string(kind);
    const double inside = kind == StaticKind::Chair ? 0.45 * top - 0.02 : top - 0.05;  // the seat's top
    EXPECT_TRUE(c.collide(i, geo_at(3, -2, inside), kIdentity)) << to_string(kind);
  }
}

}  // namespace
}  // namespace touchdown::scenario
