#pragma once
/// \file
/// The twin's flight control, as three small units that need no physics
/// engine (src/twin/landing.cpp drives them inside ODE; tests drive them
/// alone): PX4's land-mode controller cascade, PX4's three-stage land
/// detector, and the motor mixer with PX4's non-airmode saturation. Gains
/// and thresholds are ControllerParams (landing.hpp), named after the PX4
/// parameters they mirror.
///
/// Thread-safety: one instance per run. No allocation in update().
#include <Eigen/Core>
#include <Eigen/Geometry>
#include <limits>
#include <vector>

#include "touchdown/core/drone_state.hpp"

namespace touchdown::twin {

struct ControllerParams;
struct Airframe;

/// Standard gravity [m/s²], as the twin's ODE world uses.
inline constexpr double kStandardGravity = 9.80665;

/// A trajectory setpoint, as PX4's `trajectory_setpoint` message: a NaN
/// position axis is not position-controlled (its velocity is then the
/// setpoint of that axis); velocity and acceleration are feed-forward terms
/// added to the position and velocity loops' outputs.
struct Setpoint {
  /// World [m]; NaN per axis: that axis follows `velocity` only.
  Eigen::Vector3d position = Eigen::Vector3d::Constant(std::numeric_limits<double>::quiet_NaN());
  Eigen::Vector3d velocity = Eigen::Vector3d::Zero();      ///< [m/s]
  Eigen::Vector3d acceleration = Eigen::Vector3d::Zero();  ///< [m/s²]
  double yaw = 0;                                          ///< heading [rad]
  /// Land mode: MPC_TILTMAX_LND and no velocity or rate limits (the twin's
  /// landings); otherwise MPC_TILTMAX_AIR, MPC_XY_VEL_MAX, MPC_Z_VEL_MAX_UP/DN
  /// and MC_*RATE_MAX apply.
  bool land = false;
};

/// PX4's multicopter position control: position → velocity (mc_pos_control
/// PositionControl), velocity → acceleration (PID, derivative low-passed at
/// MPC_VELD_LP) plus feed-forward → thrust vector with the tilt limit,
/// attitude (geometric error, Lee, Leok & McClamroch 2010) → rates → body
/// torque. Land mode (the twin's landings) is the setpoint with the
/// landing point's x, y, no z position and the land speed down. After
/// ground contact (`level`) the attitude setpoint is level at the commanded
/// heading, as PX4's limit_thrust_during_landing.
class LandController {
 public:
  LandController(const ControllerParams& params, double mass, const Eigen::Matrix3d& inertia_about_com, double dt);

  struct Output {
    double thrust = 0;                                        ///< collective thrust along body z [N], ≥ 0
    Eigen::Vector3d torque = Eigen::Vector3d::Zero();         ///< body torque [N m]
    Eigen::Vector3d thrust_vector = Eigen::Vector3d::Zero();  ///< desired thrust vector (world) [N]
    double vz_setpoint = 0;                                   ///< [m/s]
  };

  /// One control step towards `landing_point` at `heading` [rad],
  /// descending at `land_speed` [m/s].
  Output update(const DroneState& s, const Eigen::Vector2d& landing_point, double heading, double land_speed,
                bool level);
  /// One control step towards a trajectory setpoint.
  Output update(const DroneState& s, const Setpoint& setpoint, bool level);
  /// The attitude loop alone: the body torque [N m] that turns attitude R
  /// (body rates w) towards Rd (geometric error → rates, with the rate
  /// limits when `rate_limited`, → torque).
  [[nodiscard]] Eigen::Vector3d attitude_torque(const Eigen::Matrix3d& R, const Eigen::Vector3d& w,
                                                const Eigen::Matrix3d& Rd, bool rate_limited) const;
  /// Restarts the integrators and the derivative's history (a new flight).
  void reset() {
    vel_int_.setZero();
    vz_int_ = 0;
    v_prev_.setZero();
    accel_lp_.setZero();
  }
  /// A step without control (disarmed): keeps the velocity history.
  void idle(const Eigen::Vector3d& v_world) { v_prev_ = v_world; }
  /// Ground contact: the horizontal velocity integrator restarts.
  void reset_velocity_integrator() { vel_int_.setZero(); }

 private:
  const ControllerParams& p_;
  double mass_, dt_, hover_thrust_;
  Eigen::Matrix3d inertia_;
  Eigen::Vector2d vel_int_ = Eigen::Vector2d::Zero();
  double vz_int_ = 0;
  Eigen::Vector3d v_prev_ = Eigen::Vector3d::Zero(), accel_lp_ = Eigen::Vector3d::Zero();
};

/// PX4's MulticopterLandDetector: ground contact (slow vertical speed while
/// descending) → maybe landed → landed (also low thrust and low rotation),
/// each stage held a third of LNDMC_TRIG_TIME; from ground contact on, the
/// collective thrust ramps to zero over thrust_ramp_time; landed = disarm.
class LandDetector {
 public:
  enum Stage : int { Flying = 0, GroundContact = 1, MaybeLanded = 2, Landed = 3 };

  LandDetector(const ControllerParams& params, double hover_thrust, double dt, bool armed = true);

  /// One step with the controller's commanded thrust [N], vertical speed
  /// and setpoint [m/s] and body rate magnitude [rad/s]. True on the step
  /// that detects ground contact.
  bool update(double thrust, double vz, double vz_setpoint, double rate_norm);
  /// The thrust after the ramp-down: min(thrust, ramp · thrust at contact)
  /// from ground contact on.
  [[nodiscard]] double limit_thrust(double thrust) const;

  [[nodiscard]] int stage() const { return stage_; }
  [[nodiscard]] bool landed() const { return stage_ >= Landed; }
  [[nodiscard]] double ramp() const { return ramp_; }

 private:
  const ControllerParams& p_;
  double hover_thrust_, dt_, stage_time_;
  int stage_;
  double timer_ = 0, ramp_ = 1.0, thrust_at_contact_;
};

/// Control allocation: [T; τx; τy; τz] = A f for motor thrusts f, with the
/// pseudo-inverse of A, and PX4's mixer without airmode: the collective
/// thrust is kept and the torques are scaled down until every motor is in
/// [0, max_thrust] (torque authority fades with thrust).
class Mixer {
 public:
  Mixer(const Airframe& airframe, const Eigen::Vector3d& centre_of_mass);
  /// Motor thrusts [N] for `thrust` [N] and `torque` [N m].
  [[nodiscard]] Eigen::VectorXd mix(double thrust, const Eigen::Vector3d& torque) const;
  /// The same thrusts in the mixer's own buffer, valid until the next call:
  /// no heap allocation after the first call (the twin's step loops). Not
  /// for one mixer shared between threads.
  const Eigen::VectorXd& mix_in_place(double thrust, const Eigen::Vector3d& torque);
  /// [T; τ] of motor thrusts `f` (the allocation A f).
  [[nodiscard]] Eigen::Vector4d wrench(const Eigen::VectorXd& f) const { return allocation_ * f; }
  [[nodiscard]] std::size_t motors() const { return static_cast<std::size_t>(allocation_.cols()); }

 private:
  // mix() into caller-owned vectors.
  void mix(double thrust, const Eigen::Vector3d& torque, Eigen::VectorXd& f_thrust, Eigen::VectorXd& f_torque,
           Eigen::VectorXd& f) const;

  Eigen::MatrixXd allocation_, pseudo_inverse_;
  double max_thrust_;
  Eigen::VectorXd f_thrust_, f_torque_, f_;  // mix_in_place's buffers
};

}  // namespace touchdown::twin
