// The twin's flight control without a physics engine: mixer, land detector
// and land-mode controller, each against what it must do by construction.
#include "touchdown/twin/flight_control.hpp"

#include <gtest/gtest.h>

#include <cmath>

#include "touchdown/core/rotation.hpp"
#include "touchdown/core/units.hpp"
#include "touchdown/twin/airframe.hpp"
#include "touchdown/twin/landing.hpp"

namespace tw = touchdown::twin;

TEST(Mixer, UnsaturatedCommandsAreReproducedExactly) {
  const auto af = tw::Airframe::f450();
  const tw::Mixer mixer(af, af.centre_of_mass());
  ASSERT_EQ(mixer.motors(), 4u);
  // Pure collective thrust: equal motors.
  const Eigen::VectorXd hover = mixer.mix(12.0, Eigen::Vector3d::Zero());
  for (Eigen::Index i = 0; i < 4; ++i) EXPECT_NEAR(hover[i], 3.0, 1e-12);
  // Small torques: A f reproduces [T; tau] (the allocation is exact).
  const Eigen::Vector3d tau(0.05, -0.03, 0.01);
  const Eigen::VectorXd f = mixer.mix(12.0, tau);
  const Eigen::Vector4d w = mixer.wrench(f);
  EXPECT_NEAR(w[0], 12.0, 1e-9);
  EXPECT_TRUE(w.tail<3>().isApprox(tau, 1e-9)) << w.transpose();
}

TEST(Mixer, SaturationKeepsThrustAndScalesTorque) {
  const auto af = tw::Airframe::f450();
  const tw::Mixer mixer(af, af.centre_of_mass());
  // A roll torque far beyond what 4 N of thrust can give: every motor stays
  // in [0, max], the collective is kept, the torque keeps its direction.
  const Eigen::Vector3d tau(5.0, 0, 0);
  const Eigen::VectorXd f = mixer.mix(4.0, tau);
  for (Eigen::Index i = 0; i < 4; ++i) {
    EXPECT_GE(f[i], 0.0);
    EXPECT_LE(f[i], af.max_thrust);
  }
  const Eigen::Vector4d w = mixer.wrench(f);
  EXPECT_NEAR(w[0], 4.0, 1e-9);
  EXPECT_GT(w[1], 0.0);
  EXPECT_LT(w[1], 5.0);
  EXPECT_NEAR(w[2], 0.0, 1e-9);
  // Zero thrust: no torque authority at all (non-airmode).
  const Eigen::VectorXd idle = mixer.mix(0.0, tau);
  EXPECT_NEAR(idle.norm(), 0.0, 1e-12);
  // Thrust beyond all motors is capped at their sum.
  EXPECT_NEAR(mixer.wrench(mixer.mix(100.0, Eigen::Vector3d::Zero()))[0], 4 * af.max_thrust, 1e-9);
}

TEST(LandDetector, ThreeStagesEachHeldAThirdOfTheTriggerTime) {
  tw::ControllerParams p;
  const double hover = 15.0, dt = 0.002;
  tw::LandDetector d(p, hover, dt);
  const int stage_steps = static_cast<int>(std::ceil(p.land_trigger_time / 3.0 / dt - 1e-9));
  // Descending fast: never ground contact.
  for (int k = 0; k < 1000; ++k) EXPECT_FALSE(d.update(hover, -0.7, -0.7, 0.0));
  EXPECT_EQ(d.stage(), tw::LandDetector::Flying);
  EXPECT_EQ(d.limit_thrust(hover), hover);
  // Slow vertical speed while descending: contact after a third of LNDMC_TRIG_TIME.
  int contact_step = -1;
  for (int k = 0; k < 2 * stage_steps && contact_step < 0; ++k) {
    if (d.update(hover, -0.1, -0.7, 0.0)) contact_step = k;
  }
  EXPECT_NEAR(contact_step + 1, stage_steps, 1);
  EXPECT_EQ(d.stage(), tw::LandDetector::GroundContact);
  // The thrust ramps to zero over thrust_ramp_time.
  const int ramp_steps = static_cast<int>(std::ceil(p.thrust_ramp_time / dt));
  for (int k = 0; k < ramp_steps / 2; ++k) d.update(hover, 0.0, -0.7, 0.0);
  EXPECT_NEAR(d.limit_thrust(hover), 0.5 * hover, 0.02 * hover);
  // Spinning fast holds the detector in its stage.
  const int stage_now = d.stage();
  for (int k = 0; k < 3 * stage_steps; ++k) d.update(0.0, 0.0, -0.7, 1.0);
  EXPECT_EQ(d.stage(), stage_now);
  // Still, slow and at low thrust: maybe landed, then landed.
  for (int k = 0; k < 3 * stage_steps; ++k) d.update(0.0, 0.0, -0.7, 0.0);
  EXPECT_TRUE(d.landed());
  EXPECT_EQ(d.limit_thrust(hover), 0.0);
  // A disarmed detector starts landed.
  EXPECT_TRUE(tw::LandDetector(p, hover, dt, false).landed());
}

TEST(LandController, HoverOverThePadCommandsDescentWithoutTorque) {
  tw::ControllerParams p;
  const auto af = tw::Airframe::f450();
  const double m = af.total_mass(), dt = 0.002;
  tw::LandController c(p, m, af.inertia_about_com(), dt);
  touchdown::DroneState s;
  s.position = {1.0, 2.0, 3.0};
  const auto u = c.update(s, {1.0, 2.0}, 0.0, 0.7, false);
  // a_z = Kp e + Ki ∫e with e = −0.7 m/s over one step.
  const double a_z = p.z_vel_p * -0.7 + p.z_vel_i * (-0.7 * dt);
  EXPECT_NEAR(u.thrust, m * (a_z + tw::kStandardGravity), 1e-9);
  EXPECT_NEAR(u.vz_setpoint, -0.7, 0);
  EXPECT_LT(u.torque.norm(), 1e-12);
}

TEST(LandController, TiltLimitAndRestoringTorques) {
  tw::ControllerParams p;
  const auto af = tw::Airframe::f450();
  tw::LandController c(p, af.total_mass(), af.inertia_about_com(), 0.002);
  touchdown::DroneState s;
  // Far from the pad: the thrust vector leans towards it, but no more than
  // MPC_TILTMAX_LND.
  const auto u = c.update(s, {50.0, 0.0}, 0.0, 0.7, false);
  const double tilt = std::atan2(u.thrust_vector.head<2>().norm(), u.thrust_vector.z());
  EXPECT_NEAR(tilt, touchdown::deg_to_rad(p.tilt_max_deg), 1e-9);
  EXPECT_GT(u.thrust_vector.x(), 0.0);
  // Rolled right over the pad: the torque rolls it back (negative about x);
  // yawed left of the heading: the torque yaws it back.
  tw::LandController level(p, af.total_mass(), af.inertia_about_com(), 0.002);
  touchdown::DroneState rolled;
  rolled.R_world_body = touchdown::rotation_from_rpy(0.2, 0.0, 0.0);
  EXPECT_LT(level.update(rolled, {0.0, 0.0}, 0.0, 0.7, true).torque.x(), 0.0);
  touchdown::DroneState yawed;
  yawed.R_world_body = touchdown::rotation_from_rpy(0.0, 0.0, 0.3);
  EXPECT_LT(level.update(yawed, {0.0, 0.0}, 0.0, 0.7, true).torque.z(), 0.0);
}

TEST(LandController, LandModeIsTheSetpointCaseOfOneCascade) {
  // The twin's land mode and a Setpoint with the landing point's x, y, no z
  // and the land speed down are the same arithmetic (one implementation):
  // bit-identical outputs over a run of states.
  tw::ControllerParams p;
  const auto af = tw::Airframe::f450();
  tw::LandController a(p, af.total_mass(), af.inertia_about_com(), 0.002);
  tw::LandController b(p, af.total_mass(), af.inertia_about_com(), 0.002);
  tw::Setpoint sp;
  sp.position = Eigen::Vector3d(0.3, -0.2, std::nan(""));
  sp.velocity = Eigen::Vector3d(0, 0, -0.7);
  sp.yaw = 0.4;
  sp.land = true;
  for (int k = 0; k < 50; ++k) {
    touchdown::DroneState s;
    s.position = {0.01 * k, -0.02 * k, 1 - 0.01 * k};
    s.velocity = {0.1, -0.05 * std::sin(k), -0.6};
    s.R_world_body = touchdown::rotation_from_rpy(0.01 * k, -0.02, 0.3);
    s.w_body = {0.1, 0.0, -0.05};
    const auto u = a.update(s, {0.3, -0.2}, 0.4, 0.7, k > 40);
    const auto v = b.update(s, sp, k > 40);
    EXPECT_EQ(u.thrust, v.thrust);
    EXPECT_EQ(u.torque, v.torque);
    EXPECT_EQ(u.thrust_vector, v.thrust_vector);
  }
}

TEST(LandController, PositionModeAddsTheFeedForwardAndKeepsItsLimits) {
  tw::ControllerParams p;
  const auto af = tw::Airframe::f450();
  const double m = af.total_mass();
  // At the setpoint, at rest: the thrust vector is m (a_ff + g).
  tw::LandController c(p, m, af.inertia_about_com(), 0.002);
  touchdown::DroneState s;
  s.position = {1, 2, 3};
  tw::Setpoint sp;
  sp.position = s.position;
  sp.acceleration = {1.0, -0.5, 0.2};
  const auto u = c.update(s, sp, false);
  EXPECT_TRUE(u.thrust_vector.isApprox(m * (sp.acceleration + Eigen::Vector3d(0, 0, tw::kStandardGravity)), 1e-12))
      << u.thrust_vector.transpose();
  // A feed-forward beyond MPC_XY_VEL_MAX: the velocity setpoint is capped
  // (the acceleration asks for at most xy_vel_p · xy_vel_max), and the tilt
  // for MPC_TILTMAX_AIR, not the land mode's.
  tw::LandController d(p, m, af.inertia_about_com(), 0.002);
  tw::Setpoint fast;
  fast.position = s.position;
  fast.velocity = {50, 0, 0};
  const auto f = d.update(s, fast, false);
  const double tilt = std::atan2(f.thrust_vector.head<2>().norm(), f.thrust_vector.z());
  EXPECT_NEAR(tilt, touchdown::deg_to_rad(p.tilt_max_air_deg), 1e-9);
  tw::LandController e(p, m, af.inertia_about_com(), 0.002);
  tw::Setpoint slow = fast;
  slow.velocity = {0.5, 0, 0};  // within every limit: a_x = xy_vel_p · 0.5 (+ the first step's integral)
  const auto g = e.update(s, slow, false);
  EXPECT_NEAR(g.thrust_vector.x() / m, p.xy_vel_p * 0.5 + p.xy_vel_i * 0.5 * 0.002, 1e-9);
  // A climb beyond MPC_Z_VEL_MAX_UP is capped there.
  tw::LandController h(p, m, af.inertia_about_com(), 0.002);
  tw::Setpoint up;
  up.position = Eigen::Vector3d(1, 2, 100);
  const auto v = h.update(s, up, false);
  EXPECT_NEAR(v.vz_setpoint, p.z_vel_max_up, 1e-12);
}
