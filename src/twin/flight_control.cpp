// PX4 land-mode control, land detector and mixer of the twin (see
// flight_control.hpp). The arithmetic is kept in the order of the original
// single loop in landing.cpp, so sweeps are bit-identical.
#include "touchdown/twin/flight_control.hpp"

#include <Eigen/LU>
#include <algorithm>
#include <cmath>
#include <numbers>

#include "touchdown/core/units.hpp"
#include "touchdown/twin/airframe.hpp"
#include "touchdown/twin/landing.hpp"

namespace touchdown::twin {
namespace {

Eigen::Vector3d vee(const Eigen::Matrix3d& S) { return {S(2, 1), S(0, 2), S(1, 0)}; }

// PX4's ControlMath::constrainXY: v0 + v1 limited to `max`, giving way on
// the feed-forward v1 first (the position error's v0 keeps its priority).
Eigen::Vector2d constrain_xy(const Eigen::Vector2d& v0, const Eigen::Vector2d& v1, double max) {
  if ((v0 + v1).norm() <= max) return v0 + v1;
  if (v0.norm() >= max) return v0 * (max / v0.norm());
  // |v0 + s v1| = max for s in [0, 1): the positive root of a quadratic.
  const double a = v1.squaredNorm(), b = 2 * v0.dot(v1), c = v0.squaredNorm() - max * max;
  const double root = (-b + std::sqrt(std::max(0.0, b * b - 4 * a * c))) / (2 * a);
  return v0 + root * v1;
}

}  // namespace

LandController::LandController(const ControllerParams& params, double mass, const Eigen::Matrix3d& inertia_about_com,
                               double dt)
    : p_(params), mass_(mass), dt_(dt), hover_thrust_(mass * kStandardGravity), inertia_(inertia_about_com) {}

LandController::Output LandController::update(const DroneState& s, const Eigen::Vector2d& landing_point, double heading,
                                              double land_speed, bool level) {
  Setpoint sp;
  sp.position.head<2>() = landing_point;
  sp.velocity.z() = -land_speed;
  sp.yaw = heading;
  sp.land = true;
  return update(s, sp, level);
}

LandController::Output LandController::update(const DroneState& s, const Setpoint& sp, bool level) {
  const auto& cp = p_;
  const double dt = dt_;
  const Eigen::Vector3d& p = s.position;
  const Eigen::Vector3d& v = s.velocity;
  const Eigen::Matrix3d& R = s.R_world_body;
  const Eigen::Vector3d& w = s.w_body;
  const double heading = sp.yaw;
  Output out;
  // Position → velocity (PX4 PositionControl::_positionControl). Land mode
  // (the twin): x, y from the position only, z the land speed, neither
  // limited but by MPC_XY_VEL_MAX; the arithmetic is the original loop's.
  Eigen::Vector2d v_sp = Eigen::Vector2d::Zero();
  if (sp.position.head<2>().allFinite()) v_sp = cp.xy_p * (sp.position.head<2>() - p.head<2>());
  double vz_sp = sp.velocity.z();
  if (sp.land) {
    if (v_sp.norm() > cp.xy_vel_max) v_sp *= cp.xy_vel_max / v_sp.norm();
  } else {
    v_sp = constrain_xy(v_sp, sp.velocity.head<2>(), cp.xy_vel_max);
    if (std::isfinite(sp.position.z())) vz_sp += cp.z_p * (sp.position.z() - p.z());
    vz_sp = std::clamp(vz_sp, -cp.z_vel_max_down, cp.z_vel_max_up);
  }
  // Velocity → acceleration (PositionControl::_velocityControl), PID with
  // the derivative low-passed at MPC_VELD_LP (touchdown shocks must not
  // become tilt commands), plus the feed-forward acceleration.
  const double lp = 1.0 - std::exp(-2.0 * std::numbers::pi * cp.vel_deriv_lp_hz * dt);
  accel_lp_ += lp * ((v - v_prev_) / dt - accel_lp_);
  const Eigen::Vector3d& accel = accel_lp_;
  const Eigen::Vector2d e_xy = v_sp - v.head<2>();
  vel_int_ += e_xy * dt;
  // The integral's clamp: ±2 m/s·s in land mode (the twin's landings); the
  // acceleration it may hold outside it is xy_vel_int_max_acc (a steady
  // wind's drag must fit).
  const double int_max = sp.land ? 2.0 : cp.xy_vel_int_max_acc / std::max(cp.xy_vel_i, 1e-9);
  vel_int_ = vel_int_.cwiseMax(-int_max).cwiseMin(int_max);
  Eigen::Vector2d a_xy = cp.xy_vel_p * e_xy + cp.xy_vel_i * vel_int_ - cp.xy_vel_d * accel.head<2>();
  const double e_z = vz_sp - v.z();
  vz_int_ = std::clamp(vz_int_ + e_z * dt, -3.0, 3.0);
  double a_z = cp.z_vel_p * e_z + cp.z_vel_i * vz_int_;
  if (!sp.land) {
    a_xy += sp.acceleration.head<2>();
    a_z += sp.acceleration.z();
  }
  // Thrust vector with the tilt limit (MPC_TILTMAX_LND in land mode, else
  // MPC_TILTMAX_AIR).
  Eigen::Vector3d F(a_xy.x(), a_xy.y(), a_z + kStandardGravity);
  F *= mass_;
  F.z() = std::max(F.z(), 0.1 * hover_thrust_);
  const double max_h = F.z() * std::tan(deg_to_rad(sp.land ? cp.tilt_max_deg : cp.tilt_max_air_deg));
  if (F.head<2>().norm() > max_h) F.head<2>() *= max_h / F.head<2>().norm();
  // Desired attitude: body z along F, heading ψ.
  const Eigen::Vector3d zb = F.normalized();
  const Eigen::Vector3d xc(std::cos(heading), std::sin(heading), 0.0);
  const Eigen::Vector3d yb = zb.cross(xc).normalized();
  Eigen::Matrix3d Rd;
  Rd.col(0) = yb.cross(zb);
  Rd.col(1) = yb;
  Rd.col(2) = zb;
  if (level) {
    // After ground contact PX4 (mc_pos_control limit_thrust_during_landing)
    // takes the collective thrust to zero, commands a level attitude at the
    // current heading and resets the integrators.
    const Eigen::Vector3d xc2(std::cos(heading), std::sin(heading), 0.0);
    Rd.col(2) = Eigen::Vector3d::UnitZ();
    Rd.col(1) = Eigen::Vector3d::UnitZ().cross(xc2).normalized();
    Rd.col(0) = Rd.col(1).cross(Rd.col(2));
  }
  out.torque = attitude_torque(R, w, Rd, !sp.land);
  out.thrust = std::max(0.0, F.dot(R.col(2)));
  out.thrust_vector = F;
  out.vz_setpoint = vz_sp;
  v_prev_ = v;
  return out;
}

// Attitude → rates (geometric error), rates → torque.
Eigen::Vector3d LandController::attitude_torque(const Eigen::Matrix3d& R, const Eigen::Vector3d& w,
                                                const Eigen::Matrix3d& Rd, bool rate_limited) const {
  const auto& cp = p_;
  const Eigen::Vector3d e_R = 0.5 * vee(Rd.transpose() * R - R.transpose() * Rd);
  Eigen::Vector3d w_sp(-cp.roll_p * e_R.x(), -cp.pitch_p * e_R.y(), -cp.yaw_p * e_R.z());
  const double yaw_rate_max = deg_to_rad(cp.yaw_rate_max_deg);
  w_sp.z() = std::clamp(w_sp.z(), -yaw_rate_max, yaw_rate_max);
  if (rate_limited) {
    const double rate_max = deg_to_rad(cp.roll_pitch_rate_max_deg);
    w_sp.head<2>() = w_sp.head<2>().cwiseMax(-rate_max).cwiseMin(rate_max);
  }
  const Eigen::Vector3d alpha(cp.rate_p_roll_pitch * (w_sp.x() - w.x()), cp.rate_p_roll_pitch * (w_sp.y() - w.y()),
                              cp.rate_p_yaw * (w_sp.z() - w.z()));
  const Eigen::Matrix3d& J = inertia_;
  return J * alpha + w.cross(J * w);
}

LandDetector::LandDetector(const ControllerParams& params, double hover_thrust, double dt, bool armed)
    : p_(params),
      hover_thrust_(hover_thrust),
      dt_(dt),
      stage_time_(params.land_trigger_time / 3.0),
      stage_(armed ? Flying : Landed),
      thrust_at_contact_(hover_thrust) {}

bool LandDetector::update(double thrust, double vz, double vz_setpoint, double rate_norm) {
  const auto& cp = p_;
  const double dt = dt_;
  const bool slow_vertical = std::abs(vz) < cp.land_z_vel_max;
  const bool low_thrust = thrust * ramp_ < cp.low_thrust_fraction * hover_thrust_;
  const bool low_rotation = rate_norm < deg_to_rad(cp.land_rot_max_deg);
  if (stage_ >= Landed) return false;
  if (stage_ == Flying) {
    timer_ = slow_vertical && vz_setpoint < 0 ? timer_ + dt : 0.0;
    if (timer_ >= stage_time_) {
      stage_ = GroundContact;  // start the thrust ramp-down
      timer_ = 0;
      thrust_at_contact_ = thrust;
      return true;
    }
    return false;
  }
  ramp_ = std::max(0.0, ramp_ - dt / cp.thrust_ramp_time);
  const bool ok = slow_vertical && low_thrust && low_rotation;
  timer_ = ok ? timer_ + dt : 0.0;
  if (timer_ >= stage_time_) {
    ++stage_;  // maybe landed → landed
    timer_ = 0;
  }
  return false;
}

double LandDetector::limit_thrust(double thrust) const {
  return stage_ >= GroundContact ? std::min(thrust, ramp_ * thrust_at_contact_) : thrust;
}

Mixer::Mixer(const Airframe& af, const Eigen::Vector3d& com)
    : allocation_(af.control_allocation(com)), max_thrust_(af.max_thrust) {
  pseudo_inverse_ = allocation_.transpose() * (allocation_ * allocation_.transpose()).inverse();
}

Eigen::VectorXd Mixer::mix(double thrust, const Eigen::Vector3d& torque) const {
  Eigen::VectorXd f_thrust, f_torque, f;
  mix(thrust, torque, f_thrust, f_torque, f);
  return f;
}

const Eigen::VectorXd& Mixer::mix_in_place(double thrust, const Eigen::Vector3d& torque) {
  mix(thrust, torque, f_thrust_, f_torque_, f_);
  return f_;
}

void Mixer::mix(double thrust, const Eigen::Vector3d& torque, Eigen::VectorXd& f_thrust, Eigen::VectorXd& f_torque,
                Eigen::VectorXd& f) const {
  thrust = std::min(thrust, max_thrust_ * static_cast<double>(motors()));
  f_thrust.noalias() = pseudo_inverse_ * Eigen::Vector4d(thrust, 0, 0, 0);
  f_torque.noalias() = pseudo_inverse_ * Eigen::Vector4d(0, torque.x(), torque.y(), torque.z());
  double scale = 1.0;
  for (Eigen::Index i = 0; i < f_thrust.size(); ++i) {
    const double ft = f_thrust[i], fq = f_torque[i];
    if (fq < 0 && ft + scale * fq < 0) scale = std::max(0.0, -ft / fq);
    if (fq > 0 && ft + scale * fq > max_thrust_) scale = std::max(0.0, (max_thrust_ - ft) / fq);
  }
  f.noalias() = f_thrust + scale * f_torque;
  for (Eigen::Index i = 0; i < f.size(); ++i) f[i] = std::clamp(f[i], 0.0, max_thrust_);
}

}  // namespace touchdown::twin
