// The landing world's flight model, moving objects, collisions and replay.
#include "touchdown/scenario/world.hpp"

#include <gtest/gtest.h>

#include <cmath>
#include <cstring>

#include "touchdown/core/error.hpp"

namespace touchdown::scenario {
namespace {

Scenario world_empty_scenario() {
  Scenario s;
  s.drone.position = {0, 0, 10};
  return s;
}

TEST(World, HoversInPlaceWithoutCommand) {
  World w(world_empty_scenario());
  for (int i = 0; i < 100; ++i) w.step({});
  EXPECT_EQ(w.drone().position, Eigen::Vector3d(0, 0, 10));
  EXPECT_NEAR(w.time(), 2.0, 1e-9);
  EXPECT_FALSE(w.drone().landed);
}

TEST(World, VelocityResponseRespectsTheAccelerationLimit) {
  FlightOptions f;
  World w(world_empty_scenario(), f);
  DroneCommand c;
  c.velocity_world = {5, 0, 0};
  double v_prev = 0;
  for (int i = 0; i < 25; ++i) {
    w.step(c);
    const double v = w.drone().velocity.x();
    EXPECT_LE(v - v_prev, f.max_accel_xy * w.dt() + 1e-12);
    EXPECT_GE(v, v_prev);
    v_prev = v;
    // The attitude the world reports is the thrust direction's: body z
    // along (3, 0, g) while accelerating at the 3 m/s² limit, yaw 0.
    const DroneState& s = w.drone();
    EXPECT_EQ(s.R_world_body, thrust_attitude(s));
    EXPECT_NEAR(s.R_world_body(0, 2), 3.0 / std::hypot(3.0, 9.80665), 1e-12);
    EXPECT_NEAR(s.R_world_body(1, 2), 0.0, 1e-15);
    EXPECT_NEAR(s.R_world_body(1, 1), 1.0, 1e-15);
  }
  // 0.5 s at the limit of 3 m/s².
  EXPECT_NEAR(v_prev, 1.5, 1e-9);
  for (int i = 0; i < 500; ++i) w.step(c);
  EXPECT_NEAR(w.drone().velocity.x(), 5.0, 1e-6);
  // Tilted forward while accelerating, level at constant speed.
  EXPECT_NEAR(w.drone().T_world_body().linear()(2, 2), 1.0, 1e-9);
  // Speeds above the limit are clipped.
  c.velocity_world = {30, 40, 0};
  for (int i = 0; i < 500; ++i) w.step(c);
  EXPECT_NEAR(w.drone().velocity.head<2>().norm(), f.max_speed_xy, 1e-6);
}

TEST(World, LandModeDescendsAtPx4SpeedsAndDetectsTheLanding) {
  FlightOptions f;
  World w(world_empty_scenario(), f);
  DroneCommand land;
  land.land = true;
  const double ground = -f.airframe.ground_z();
  double t_slow = -1;
  while (!w.drone().landed && w.time() < 60) {
    w.step(land);
    const double h = w.drone().position.z() - ground;
    if (h > f.land_slow_altitude + 0.5) {
      EXPECT_GE(w.drone().velocity.z(), -f.max_speed_down - 1e-9);
    }
    if (t_slow < 0 && h < f.land_slow_altitude - 0.3) t_slow = w.time();
    // τ = 0.3 s: 1.5 s after the switch the speed is land_speed to 1 %.
    if (t_slow > 0 && w.time() > t_slow + 1.5 && !w.drone().on_ground) {
      EXPECT_NEAR(w.drone().velocity.z(), -f.land_speed, 0.007);
    }
  }
  ASSERT_TRUE(w.drone().landed);
  EXPECT_DOUBLE_EQ(w.drone().position.z(), ground);
  // Descent (10 - 0.18 - 2) m at 1.5 m/s, 2 m at 0.7 m/s, plus the
  // acceleration ramps and the detector's 0.5 s.
  const double expected = (10 - ground - f.land_slow_altitude) / f.max_speed_down +
                          f.land_slow_altitude / f.land_speed + f.land_detect_time;
  EXPECT_NEAR(w.time(), expected, 1.2);
  // Landed: commands no longer move it.
  const Eigen::Vector3d p = w.drone().position;
  DroneCommand climb;
  climb.velocity_world = {1, 0, 2};
  w.step(climb);
  EXPECT_EQ(w.drone().position, p);
}

TEST(World, ScriptedObjectsFollowTheirPaths) {
  Scenario s = world_empty_scenario();
  DynamicObject walker;
  walker.motion = MotionKind::Line;
  walker.position = {2, 3};
  walker.heading_deg = 90;
  walker.speed = 1.0;
  walker.extent = 4.0;
  DynamicObject dog;
  dog.kind = DynamicKind::Dog;
  dog.size = {0.8, 0.3, 0.6};
  dog.motion = MotionKind::Circle;
  dog.position = {-5, 0};
  dog.heading_deg = 0;
  dog.speed = 2.0;
  dog.extent = 3.0;
  s.dynamic_objects = {walker, dog};
  World w(s);
  const int steps_4s = static_cast<int>(std::lround(4.0 / w.dt()));
  for (int i = 0; i < steps_4s; ++i) w.step({});
  // The walker is at the far end of its line, 4 m north.
  EXPECT_NEAR(w.dynamic_poses()[0].translation().x(), 2.0, 1e-9);
  EXPECT_NEAR(w.dynamic_poses()[0].translation().y(), 7.0, 1e-6);
  for (int i = 0; i < steps_4s; ++i) w.step({});
  EXPECT_NEAR(w.dynamic_poses()[0].translation().y(), 3.0, 1e-6);
  // The dog stays on its circle (centre 3 m to the left of its start heading).
  const Eigen::Vector2d centre(-5, 3);
  EXPECT_NEAR((w.dynamic_poses()[1].translation().head<2>() - centre).norm(), 3.0, 1e-9);
  EXPECT_NEAR(w.dynamic_velocities()[1].head<2>().norm(), 2.0, 0.01);
}

TEST(World, ExternalActionsMoveObjectsInWorldAxes) {
  Scenario s = world_empty_scenario();
  DynamicObject a;
  a.motion = MotionKind::External;
  a.position = {0, 5};
  a.speed = 1.0;
  DynamicObject still;
  still.motion = MotionKind::Still;
  still.position = {5, 5};
  s.dynamic_objects = {a, still, a};
  s.dynamic_objects[2].position = {0, -5};
  World w(s);
  ASSERT_EQ(w.external_count(), 2);
  const std::vector<ObjectAction> act{ObjectAction::Right, ObjectAction::Up};
  for (int i = 0; i < 50; ++i) w.step({}, act);
  EXPECT_NEAR(w.dynamic_poses()[0].translation().x(), 1.0, 1e-9);
  EXPECT_NEAR(w.dynamic_poses()[2].translation().y(), -4.0, 1e-9);
  EXPECT_EQ(w.dynamic_poses()[1].translation().head<2>(), Eigen::Vector2d(5, 5));
  const std::vector<ObjectAction> stay{ObjectAction::Stay, ObjectAction::Left};
  w.step({}, stay);
  EXPECT_NEAR(w.dynamic_poses()[0].translation().x(), 1.0, 1e-9);
  EXPECT_NEAR(w.dynamic_poses()[2].translation().x(), -0.02, 1e-9);
}

// The drone at (0, 0, 4), a box 6 m behind it, a 0.2 m pole 4 m ahead.
Scenario box_and_pole_scenario() {
  Scenario s = world_empty_scenario();
  s.drone.position = {0, 0, 4};
  StaticObject box;
  box.position = {-6, 0};
  StaticObject pole;
  pole.kind = StaticKind::Pole;
  pole.position = {4, 0};
  pole.size = {0.2, 0.2, 6};
  s.static_objects = {box, pole};
  return s;
}

TEST(World, FlyingIntoAPoleIsACollisionWithItsName) {
  const Scenario s = box_and_pole_scenario();
  World w(s);
  DroneCommand c;
  c.velocity_world = {2, 0, 0};
  while (!w.collision() && w.time() < 10) w.step(c);
  ASSERT_NE(w.collision(), nullptr);
  EXPECT_EQ(w.collision()->object, 1);
  EXPECT_EQ(w.collision()->what, "static_objects[1] (pole)");
  // At yaw 0 the rotor disks ahead are centred at (x + m, ±m), m = r/√2:
  // the first touches the pole (radius 0.1) when its centre is 0.1 + 0.127
  // from the pole's axis, with the body still ~0.3 m away; steps are 4 cm.
  const FlightOptions f;
  const double m = f.airframe.motor_radius / std::sqrt(2.0), reach = 0.1 + f.airframe.prop_radius;
  const double x_touch = 4.0 - m - std::sqrt(reach * reach - m * m);
  EXPECT_GE(w.drone().position.x(), x_touch);
  EXPECT_LE(w.drone().position.x(), x_touch + 2.0 * w.dt() + 1e-9);
  EXPECT_NEAR(w.collision()->point.x(), 3.9, 0.05);
  // After a collision the drone no longer moves.
  const Eigen::Vector3d p = w.drone().position;
  w.step(c);
  EXPECT_EQ(w.drone().position, p);
}

TEST(World, TheNearestObjectIsTheAnalyticClearance) {
  const Scenario s = world_empty_scenario();
  EXPECT_EQ(World(s).nearest_object().object, -1);
  EXPECT_TRUE(std::isinf(World(s).nearest_object().distance));
  const World w(box_and_pole_scenario());
  const NearestObject n = w.nearest_object();
  EXPECT_EQ(n.object, 1);
  EXPECT_EQ(n.what, "static_objects[1] (pole)");
  // At yaw 0 the rotor disks ahead are centred at (m, ±m), m = r/√2: the
  // nearest point is on a disk's rim, toward the pole's axis at (4, 0).
  const FlightOptions f;
  const double m = f.airframe.motor_radius / std::sqrt(2.0);
  const double expected = std::hypot(4.0 - m, m) - f.airframe.prop_radius - 0.1;
  EXPECT_NEAR(n.distance, expected, 1e-3);
}

TEST(World, SameScenarioAndCommandsReplayBitIdentically) {
  Scenario s = world_empty_scenario();
  DynamicObject wanderer;
  wanderer.motion = MotionKind::Wander;
  wanderer.extent = 3;
  s.dynamic_objects = {wanderer};
  s.seed = 42;
  World a(s), b(s);
  DroneCommand c;
  for (int i = 0; i < 1000; ++i) {
    c.velocity_world = {std::sin(0.01 * i), std::cos(0.02 * i), -0.1};
    c.yaw_rate_deg = 10;
    a.step(c);
    b.step(c);
  }
  EXPECT_EQ(std::memcmp(a.drone().position.data(), b.drone().position.data(), sizeof(double) * 3), 0);
  EXPECT_EQ(a.dynamic_poses()[0].matrix(), b.dynamic_poses()[0].matrix());
  s.seed = 43;
  World other(s);
  for (int i = 0; i < 1000; ++i) other.step(c);
  EXPECT_NE(other.dynamic_poses()[0].translation(), a.dynamic_poses()[0].translation());
}

TEST(FlightOptions, RejectsOutOfRangeValuesByName) {
  FlightOptions f;
  std::string why;
  f.max_accel_xy = -1;
  EXPECT_FALSE(f.validate(&why));
  EXPECT_NE(why.find("max_accel_xy"), std::string::npos);
  f = {};
  f.land_speed = 5;
  EXPECT_FALSE(f.validate(&why));
  EXPECT_NE(why.find("land_speed"), std::string::npos);
  f = {};
  f.rate_hz = std::nan("");
  EXPECT_THROW(World(world_empty_scenario(), f), InvalidArgument);
}

}  // namespace
}  // namespace touchdown::scenario
