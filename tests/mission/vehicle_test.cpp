// The ground vehicle against analytic answers: a circle's radius and yaw
// rate, a straight line, the figure-eight's lobes, the acceleration and
// wheel limits, the random drive's determinism and bounds.
#include "touchdown/mission/vehicle.hpp"

#include <gtest/gtest.h>

#include <cmath>
#include <numbers>

#include "touchdown/core/error.hpp"

namespace tdm = touchdown::mission;

namespace {

constexpr double kDt = 0.01;

}  // namespace

TEST(GroundVehicle, CircleAtSpeedKeepsItsRadiusAndYawRate) {
  tdm::VehicleOptions o;
  o.path = tdm::VehiclePath::Circle;
  o.radius = 6;
  o.speed = 2;
  tdm::GroundVehicle v(o, 1);
  const Eigen::Vector2d centre(0, o.radius);
  double worst = 0;
  for (int k = 0; k < 4000; ++k) {  // 40 s: two laps
    v.step(kDt);
    worst = std::max(worst, std::abs((v.state().position - centre).norm() - o.radius));
  }
  // Pure pursuit cuts a circle slightly inside (lookahead 2 m on a 6 m
  // circle: a few centimetres); the yaw rate is v / R.
  EXPECT_LT(worst, 0.1);
  EXPECT_NEAR(v.state().speed, o.speed, 1e-3);
  EXPECT_NEAR(v.state().yaw_rate, o.speed / o.radius, 0.01);
  // Centripetal acceleration v²/R, towards the centre.
  const Eigen::Vector2d a = v.state().world_acceleration();
  EXPECT_NEAR(a.norm(), o.speed * o.speed / o.radius, 0.02);
  EXPECT_GT(a.dot(centre - v.state().position), 0);
  // The pad moves with the vehicle: its velocity is the rigid motion's.
  const Eigen::Vector3d p0 = v.T_world_pad().translation(), vel = v.pad_velocity();
  v.step(kDt);
  EXPECT_LT(((v.T_world_pad().translation() - p0) / kDt - vel).norm(), 0.01);
  EXPECT_NEAR(v.T_world_pad().translation().z(), o.pad_position.z(), 1e-12);
}

TEST(GroundVehicle, ClockwiseCircleTurnsRight) {
  tdm::VehicleOptions o;
  o.counter_clockwise = false;
  tdm::GroundVehicle v(o, 1);
  for (int k = 0; k < 300; ++k) v.step(kDt);
  EXPECT_LT(v.state().position.y(), -0.5);
  EXPECT_LT(v.state().yaw_rate, 0);
}

TEST(GroundVehicle, LineFromRestRampsAtTheAccelerationLimit) {
  tdm::VehicleOptions o;
  o.path = tdm::VehiclePath::Line;
  o.start_at_speed = false;
  o.speed = 3;
  o.max_acceleration = 1;
  tdm::GroundVehicle v(o, 1);
  double max_accel = 0;
  for (int k = 0; k < 200; ++k) {
    v.step(kDt);
    max_accel = std::max(max_accel, v.state().acceleration);
  }
  // After 2 s of a 1 m/s² ramp through a 0.15 s first-order drive: the
  // ramp's speed minus its lag, 2 − 0.15 m/s (to within the transient).
  EXPECT_NEAR(v.state().speed, 2.0 - o.drive_time_constant, 0.02);
  EXPECT_LE(max_accel, o.max_acceleration + 1e-9);
  for (int k = 0; k < 500; ++k) v.step(kDt);
  EXPECT_NEAR(v.state().speed, 3, 1e-3);
  EXPECT_NEAR(v.state().position.y(), 0, 1e-9);
  EXPECT_NEAR(v.state().yaw, 0, 1e-12);
}

TEST(GroundVehicle, FigureEightCrossesItselfAtTheStart) {
  tdm::VehicleOptions o;
  o.path = tdm::VehiclePath::FigureEight;
  o.radius = 5;
  tdm::GroundVehicle v(o, 1);
  const double lobe = 2 * std::numbers::pi * o.radius / o.speed;  // s per lobe
  bool left = false, right = false;
  for (int k = 0; k * kDt < 2 * lobe; ++k) {
    v.step(kDt);
    left = left || v.state().position.y() > 0.9 * 2 * o.radius;
    right = right || v.state().position.y() < -0.9 * 2 * o.radius;
  }
  EXPECT_TRUE(left);
  EXPECT_TRUE(right);
  // Back near the start after both lobes.
  EXPECT_LT(v.state().position.norm(), 0.5);
  EXPECT_NEAR(v.path_curvature(1.0), 1 / o.radius, 1e-12);
  EXPECT_NEAR(v.path_curvature(2 * std::numbers::pi * o.radius + 1.0), -1 / o.radius, 1e-12);
}

TEST(GroundVehicle, RandomDriveIsSeededAndBounded) {
  tdm::VehicleOptions o;
  o.path = tdm::VehiclePath::Random;
  o.radius = 5;
  tdm::GroundVehicle a(o, 7), b(o, 7), c(o, 8);
  double max_rate = 0, max_speed = 0;
  for (int k = 0; k < 3000; ++k) {
    a.step(kDt);
    b.step(kDt);
    c.step(kDt);
    max_rate = std::max(max_rate, std::abs(a.state().yaw_rate));
    max_speed = std::max(max_speed, a.state().speed);
  }
  EXPECT_EQ(a.state().position, b.state().position);
  EXPECT_NE(a.state().position, c.state().position);
  EXPECT_LE(max_speed, o.speed + 2 * o.random_speed_sigma + 1e-9);
  EXPECT_LE(max_rate, max_speed / o.radius + 1e-6);
}

TEST(GroundVehicle, WheelLimitKeepsTheCurvature) {
  tdm::VehicleOptions o;
  o.path = tdm::VehiclePath::Line;
  o.speed = 1;
  tdm::GroundVehicle v(o, 1);
  for (int k = 0; k < 100; ++k) v.step(kDt);
  EXPECT_LE(std::max(std::abs(v.state().wheel_left), std::abs(v.state().wheel_right)), o.max_wheel_speed);
}

TEST(GroundVehicle, InvalidOptionsNameTheKey) {
  const auto refused = [](auto edit, const std::string& key) {
    tdm::VehicleOptions o;
    edit(o);
    std::string why;
    EXPECT_FALSE(o.validate(&why)) << key;
    EXPECT_NE(why.find(key), std::string::npos) << why;
    EXPECT_THROW(tdm::GroundVehicle(o, 1), touchdown::InvalidArgument);
  };
  refused([](auto& o) { o.radius = -1; }, "vehicle.radius");
  refused([](auto& o) { o.speed = std::nan(""); }, "vehicle.speed");
  refused([](auto& o) { o.speed = 10; }, "vehicle.speed");  // beyond the wheels
  refused([](auto& o) { o.pad_position.z() = 0; }, "vehicle.pad_position");
  refused([](auto& o) { o.lookahead = 0; }, "vehicle.lookahead");
}
