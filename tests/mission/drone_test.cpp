// The mission's quadrotor against analytic answers (free fall, motor lag,
// terminal velocity, the velocity loop's first-order response, the tilt and
// rate limits) and its touchdown on the moving pad (at rest it stays; with
// 1 m/s lateral speed it slides the Coulomb distance or tips, as the
// friction and the support say).
#include "touchdown/mission/drone.hpp"

#include <gtest/gtest.h>

#include <cmath>
#include <numbers>

#include "touchdown/core/error.hpp"
#include "touchdown/core/units.hpp"

namespace tdm = touchdown::mission;
namespace tw = touchdown::twin;

namespace {

tw::Airframe quad180() { return tw::load_airframe(std::string(TOUCHDOWN_SOURCE_DIR) + "/data/airframes/quad180.yaml"); }

tdm::DroneOptions options(double drag_linear = 0, double drag_quadratic = 0) {
  tdm::DroneOptions o;
  o.airframe = quad180();
  o.drag_linear = drag_linear;
  o.drag_quadratic = drag_quadratic;
  return o;
}

Eigen::Isometry3d at(const Eigen::Vector3d& p) {
  Eigen::Isometry3d T = Eigen::Isometry3d::Identity();
  T.translation() = p;
  return T;
}

// Steps `seconds` with the true state as the estimate.
void fly(tdm::DroneSimulation& d, const tw::Setpoint& sp, double seconds, bool armed = true,
         const Eigen::Vector3d& wind = Eigen::Vector3d::Zero()) {
  const int n = static_cast<int>(std::lround(seconds / d.options().step));
  for (int k = 0; k < n; ++k) {
    const touchdown::DroneState s = d.state();
    d.step(sp, s.position, s.velocity, armed, wind);
  }
}

// A pad far away (below the ground) when the test does not need one.
void pad_away(tdm::DroneSimulation& d) {
  d.set_pad(at({100, 100, -10}), Eigen::Vector3d::Zero(), Eigen::Vector3d::Zero());
}

}  // namespace

TEST(Drone, DisarmedFallsFreelyThenAtTheDragTerminalSpeed) {
  {
    tdm::DroneSimulation d(options(), {});
    pad_away(d);
    d.place(at({0, 0, 50}), Eigen::Vector3d::Zero(), false);
    const double z0 = d.state().position.z();
    fly(d, {}, 1.0, false);
    // z = z0 − g t²/2 (semi-implicit Euler: within g·dt·t).
    EXPECT_NEAR(d.state().position.z(), z0 - 0.5 * tw::kStandardGravity, tw::kStandardGravity * 0.002 + 1e-9);
    EXPECT_NEAR(d.state().velocity.z(), -tw::kStandardGravity, 1e-9);
  }
  // With drag: m g = (k1 + k2 v) v at the terminal speed.
  const double k1 = 0.1, k2 = 0.05;
  tdm::DroneSimulation d(options(k1, k2), {});
  pad_away(d);
  d.place(at({0, 0, 500}), Eigen::Vector3d::Zero(), false);
  fly(d, {}, 20.0, false);
  const double mg = quad180().total_mass() * tw::kStandardGravity;
  const double v_terminal = (-k1 + std::sqrt(k1 * k1 + 4 * k2 * mg)) / (2 * k2);
  EXPECT_NEAR(-d.state().velocity.z(), v_terminal, 1e-3 * v_terminal);
}

TEST(Drone, MotorsSpinDownWithTheirTimeConstant) {
  tdm::DroneOptions o = options();
  o.spool_down = 0;  // cut at once
  tdm::DroneSimulation d(o, {});
  pad_away(d);
  d.place(at({0, 0, 50}), Eigen::Vector3d::Zero(), true);
  const double hover = d.motor_thrusts()[0];
  const double tau = quad180().motor_time_constant;
  fly(d, {}, tau, false);
  // First order: exp(−t/τ) after t = τ (exactly, in the discrete lag's steps).
  EXPECT_NEAR(d.motor_thrusts()[0] / hover, std::exp(-1.0), 1e-9);
}

TEST(Drone, SpoolDownRampsTheThrustThroughTheMotorLag) {
  // After the motors-off command the collective command ramps from the
  // hover thrust T0 to 0 over T; through the motors' first-order lag τ the
  // thrust is T0 − (T0 / T) (t − τ (1 − e^{−t/τ})) for t ≤ T (the ramp's
  // response), and e^{−(t − T)/τ}-small after it.
  tdm::DroneOptions o = options();
  o.spool_down = 0.25;
  tdm::DroneSimulation d(o, {});
  pad_away(d);
  d.place(at({0, 0, 50}), Eigen::Vector3d::Zero(), true);
  tw::Setpoint sp;
  sp.position = d.state().position;
  fly(d, sp, 0.5);  // settle the controller at hover
  const double T0 = d.motor_thrusts().sum(), T = o.spool_down, tau = quad180().motor_time_constant;
  ASSERT_NEAR(T0, quad180().total_mass() * tw::kStandardGravity, 1e-3);
  const double t = 0.5 * T;
  fly(d, sp, t, false);
  const double ramp = T0 - (T0 / T) * (t - tau * (1 - std::exp(-t / tau)));
  EXPECT_NEAR(d.motor_thrusts().sum(), ramp, 0.02 * T0);
  EXPECT_GT(d.motor_thrusts().sum(), 0.4 * T0);  // not the cut's e^{−t/τ} (1.5e-2)
  fly(d, sp, 0.5 * T + 10 * tau, false);
  EXPECT_LT(d.motor_thrusts().sum(), 1e-3 * T0);
}

TEST(Drone, HoversAtItsSetpointWithHoverThrust) {
  tdm::DroneSimulation d(options(), {});
  pad_away(d);
  d.place(at({1, 2, 3}), Eigen::Vector3d::Zero(), true);
  tw::Setpoint sp;
  sp.position = d.state().position;
  fly(d, sp, 3.0);
  EXPECT_LT((d.state().position - sp.position).norm(), 1e-3);
  EXPECT_NEAR(d.motor_thrusts().sum(), quad180().total_mass() * tw::kStandardGravity, 1e-3);
}

TEST(Drone, VelocityStepFollowsThePiLoopsSecondOrderResponse) {
  // A climb-rate step with no position setpoint: the z velocity loop is PI
  // on an integrator (the thrust sets the acceleration), so
  // v(s)/v_sp(s) = (Kp s + Ki) / (s² + Kp s + Ki): with the poles p1, p2,
  // v(t) = 1 + A e^(p1 t) + B e^(p2 t), A = (Kp p1 + Ki) / (p1 (p1 − p2)),
  // B = (Kp p2 + Ki) / (p2 (p2 − p1)) — it overshoots (the zero). The motor
  // lag and the attitude loop add a little delay.
  tdm::DroneSimulation d(options(), {});
  pad_away(d);
  d.place(at({0, 0, 10}), Eigen::Vector3d::Zero(), true);
  tw::Setpoint sp;
  sp.velocity = {0, 0, 1.0};
  const double kp = d.options().controller.z_vel_p, ki = d.options().controller.z_vel_i;
  const double root = std::sqrt(kp * kp - 4 * ki);
  ASSERT_TRUE(std::isfinite(root));
  const double p1 = 0.5 * (-kp + root), p2 = 0.5 * (-kp - root);
  const double A = (kp * p1 + ki) / (p1 * (p1 - p2)), B = (kp * p2 + ki) / (p2 * (p2 - p1));
  double t = 0, peak = 0;
  for (const double until : {0.25, 0.5, 1.0, 1.5, 3.0, 6.0}) {
    fly(d, sp, until - t);
    t = until;
    const double expected = 1 + A * std::exp(p1 * t) + B * std::exp(p2 * t);
    EXPECT_NEAR(d.state().velocity.z(), expected, 0.03) << "t = " << t;
    peak = std::max(peak, d.state().velocity.z());
  }
  EXPECT_GT(peak, 1.05);  // the overshoot a first-order model would not have
}

TEST(Drone, TiltAndRateLimitsHoldOnAFarSetpoint) {
  tdm::DroneSimulation d(options(), {});
  pad_away(d);
  d.place(at({0, 0, 20}), Eigen::Vector3d::Zero(), true);
  tw::Setpoint sp;
  sp.position = Eigen::Vector3d(100, 0, 20);
  const auto& cp = d.options().controller;
  double max_tilt = 0, max_rate = 0, max_speed = 0;
  const int n = static_cast<int>(10 / d.options().step);
  for (int k = 0; k < n; ++k) {
    const touchdown::DroneState s = d.state();
    max_tilt = std::max(max_tilt, std::acos(std::clamp(s.R_world_body(2, 2), -1.0, 1.0)));
    max_rate = std::max(max_rate, s.w_body.head<2>().cwiseAbs().maxCoeff());
    max_speed = std::max(max_speed, s.velocity.head<2>().norm());
    d.step(sp, s.position, s.velocity, true, Eigen::Vector3d::Zero());
  }
  // The attitude loop lags its setpoint a little: within 10 % of the limits.
  EXPECT_LT(max_tilt, 1.1 * touchdown::deg_to_rad(cp.tilt_max_air_deg));
  EXPECT_GT(max_tilt, 0.5 * touchdown::deg_to_rad(cp.tilt_max_air_deg));
  EXPECT_LT(max_rate, 1.1 * touchdown::deg_to_rad(cp.roll_pitch_rate_max_deg));
  EXPECT_LT(max_speed, 1.05 * cp.xy_vel_max);
}

TEST(Drone, AtRestOnAMovingPadItStaysOnIt) {
  tdm::DroneSimulation d(options(), {});
  const Eigen::Vector3d v_pad(2, 0, 0);
  Eigen::Isometry3d pad = at({0, 0, 0.4});
  d.set_pad(pad, v_pad, Eigen::Vector3d::Zero());
  const double lift = -quad180().ground_z();
  d.place(at({0, 0, 0.4 + lift + 0.0005}), v_pad, false);
  const double dt = d.options().step;
  for (int k = 0; k < static_cast<int>(3 / dt); ++k) {
    pad.translation() += v_pad * dt;
    d.set_pad(pad, v_pad, Eigen::Vector3d::Zero());
    const touchdown::DroneState s = d.state();
    d.step({}, s.position, s.velocity, false, Eigen::Vector3d::Zero());
  }
  const Eigen::Vector3d rel = pad.inverse() * d.T_world_body().translation();
  EXPECT_LT(rel.head<2>().norm(), 0.005);
  EXPECT_NEAR(d.support_height_above_pad(), 0, 0.002);
  EXPECT_TRUE(d.contacts().support_on_pad);
  EXPECT_FALSE(d.contacts().strike_on_pad);
  EXPECT_FALSE(d.contacts().on_ground);
}

TEST(Drone, SlidesTheCoulombDistanceOrTipsAsTheSupportSays) {
  // Set down with 1 m/s lateral speed relative to a pad moving at 2 m/s.
  // Tipping needs μ above (half the support width) / (height of the centre
  // of mass above the feet); below that it slides v²/(2 μ g).
  const tw::Airframe af = quad180();
  const double half_base = 0.05;
  const double com_height = af.centre_of_mass().z() - af.ground_z();
  const double mu_tip = half_base / com_height;
  ASSERT_GT(mu_tip, 0.5);
  for (const double mu : {0.3, 2.5 * mu_tip}) {
    SCOPED_TRACE(mu);
    tdm::DroneOptions o = options();
    o.pad_friction = mu;
    tdm::DroneSimulation d(o, {Eigen::Vector2d(3.0, 3.0), 0.02});
    const Eigen::Vector3d v_pad(2, 0, 0);
    Eigen::Isometry3d pad = at({0, 0, 0.4});
    d.set_pad(pad, v_pad, Eigen::Vector3d::Zero());
    d.place(at({0, 0, 0.4 - af.ground_z() + 0.0005}), v_pad + Eigen::Vector3d(0, 1, 0), false);
    const double dt = d.options().step;
    double max_tilt = 0;
    for (int k = 0; k < static_cast<int>(2 / dt); ++k) {
      pad.translation() += v_pad * dt;
      d.set_pad(pad, v_pad, Eigen::Vector3d::Zero());
      const touchdown::DroneState s = d.state();
      d.step({}, s.position, s.velocity, false, Eigen::Vector3d::Zero());
      max_tilt = std::max(max_tilt, std::acos(std::clamp(d.state().R_world_body(2, 2), -1.0, 1.0)));
    }
    const Eigen::Vector3d rel = pad.inverse() * d.T_world_body().translation();
    if (mu < mu_tip) {
      EXPECT_NEAR(rel.y(), 1.0 / (2 * mu * tw::kStandardGravity), 0.02);
      EXPECT_LT(max_tilt, 0.1);
    } else {
      EXPECT_GT(max_tilt, 0.5);  // tips over its downstream feet
    }
  }
}

TEST(Drone, InvalidOptionsNameTheKey) {
  tdm::DroneOptions o = options();
  o.step = 0;
  std::string why;
  EXPECT_FALSE(o.validate(&why));
  EXPECT_NE(why.find("drone.step"), std::string::npos) << why;
  EXPECT_THROW(tdm::DroneSimulation(o, {}), touchdown::InvalidArgument);
  o = options();
  o.pad_friction = -1;
  EXPECT_FALSE(o.validate(&why));
  EXPECT_NE(why.find("drone.pad_friction"), std::string::npos) << why;
  o = options();
  o.spool_down = -0.1;
  EXPECT_FALSE(o.validate(&why));
  EXPECT_NE(why.find("drone.spool_down"), std::string::npos) << why;
}
