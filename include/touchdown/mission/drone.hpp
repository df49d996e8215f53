#pragma once
/// \file
/// The quadrotor of the landing mission and its touchdown on the moving pad:
/// ODE rigid-body dynamics of the airframe (twin/airframe.hpp) under the
/// twin's PX4-like controller cascade (twin/flight_control.hpp: the same
/// LandController, tracking a trajectory Setpoint), with the mixer's thrust
/// limits, first-order motor lag, body-rate limits, linear + quadratic drag
/// against the wind; the pad is a kinematic ODE box moved with the vehicle,
/// and the ground a plane at z = 0. ODE stays behind a pimpl.
///
/// Frames: world z up; the drone's body frame as in the airframe YAML; its
/// state is reported at the centre of mass. Thread-safety: one instance per
/// mission (each owns its ODE world). Allocation: step() mixes into the
/// mixer's own buffer (twin::Mixer::mix_in_place, as the twin's landings
/// do); ODE creates its contact joints in its joint group.
#include <Eigen/Core>
#include <Eigen/Geometry>
#include <memory>
#include <string>

#include "touchdown/core/drone_state.hpp"
#include "touchdown/twin/airframe.hpp"
#include "touchdown/twin/flight_control.hpp"
#include "touchdown/twin/landing.hpp"

namespace touchdown::mission {

struct DroneOptions {
  twin::Airframe airframe = twin::Airframe::quad180();
  twin::ControllerParams controller{};
  double step = 0.002;               ///< physics and control step [s], (0, 0.01]
  double drag_linear = 0.05;         ///< N per m/s of airspeed
  double drag_quadratic = 0.01;      ///< N per (m/s)² of airspeed
  double contact_stiffness = 1.0e4;  ///< N/m per contact
  double contact_damping = 150.0;    ///< N s/m per contact
  double pad_friction = 0.8;         ///< Coulomb μ on the pad
  double ground_friction = 0.8;      ///< on the ground
  /// The wind observer's time constant (wind.hpp: WindObserver) [s], ≥ 0; 0 = no
  /// wind estimate (the integrators alone).
  double wind_observer_time = 0.05;
  /// Fly the airframe's whole drag at the setpoint's velocity relative to
  /// the estimated air, −D(v_sp − ŵ) / m, as acceleration feed-forward
  /// (instead of the wind's share only): what a fast chase needs, where
  /// the drag at 14 m/s (4 m/s² on the racing preset) is beyond the
  /// velocity integrator's limit. The setpoint's velocity, not the
  /// measured one: the airframe's own damping stays.
  bool drag_feed_forward = false;
  /// Add back what the velocity loop's derivative takes from the setpoint's
  /// horizontal acceleration: that term acts on the measured acceleration
  /// (PX4's MPC_XY_VEL_D_ACC, low-passed at MPC_VELD_LP), so in a steady
  /// turn it brakes the centripetal acceleration the setpoint asks for and
  /// the drone flies outside the turn (0.27 m at 4 m/s on the 8 m circle,
  /// which the world-frame integrator cannot hold as it turns with the
  /// pad). The setpoint's acceleration through the same low-pass, times the
  /// gain, is added to the feed-forward: the derivative then damps the
  /// acceleration error.
  bool turn_feed_forward = true;
  /// After the motors-off command the collective thrust ramps from what it
  /// was to zero over this time [s], in [0, 5] (0 = cut at once; the motors
  /// spin down with their time constant), as PX4's land detector's ramp;
  /// the attitude is held where it was at the command, so the lean keeps
  /// the share of the side force that friction cannot take yet. The drone
  /// meets the pad at its descent speed instead of dropping the last
  /// centimetres unpowered.
  double spool_down = 0.25;
  /// False (with "drone.key: problem" in *why) for an invalid value.
  [[nodiscard]] bool validate(std::string* why) const;
};

/// The pad: a box whose top face is the pad frame's z = 0 plane, centred on
/// its origin.
struct PadGeometry {
  Eigen::Vector2d size{0.43, 0.43};  ///< [m]
  double thickness = 0.02;           ///< [m]
  /// Magnets that hold the landed drone (as MBZIRC's truck-landing teams'
  /// electro-permanent magnets): once the motors are off, each support
  /// point touching the pad is pulled into it with hold_force / (number of
  /// support points) [N], ≥ 0; 0 = none, the drone stays by friction alone.
  double hold_force = 0;
};

/// Which parts touched what in the last step.
struct ContactState {
  bool support_on_pad = false;  ///< a foot (or, without gear, the body's bottom) on the pad
  bool strike_on_pad = false;   ///< a propeller, an arm or (with gear) the body on the pad
  bool on_ground = false;       ///< any part on the ground
  int contacts = 0;
};

class DroneSimulation {
 public:
  /// Throws InvalidArgument for invalid options.
  DroneSimulation(DroneOptions options, PadGeometry pad);
  ~DroneSimulation();
  DroneSimulation(const DroneSimulation&) = delete;
  DroneSimulation& operator=(const DroneSimulation&) = delete;

  /// Puts the airframe's body frame at `T_world_body`, moving at `v`, motors
  /// at hover thrust (armed) or stopped.
  void place(const Eigen::Isometry3d& T_world_body, const Eigen::Vector3d& v, bool armed);
  /// The pad's pose and motion for the next step.
  void set_pad(const Eigen::Isometry3d& T_world_pad, const Eigen::Vector3d& v, const Eigen::Vector3d& w);
  /// One step: the controller tracks `setpoint` from the position and
  /// velocity the drone estimates (`p_estimate`, `v_estimate`: the flight
  /// controller's state estimate; attitude and rates are its IMU's, taken
  /// as true), motors (lag) unless disarmed, drag in `wind` [m/s], contacts.
  void step(const twin::Setpoint& setpoint, const Eigen::Vector3d& p_estimate, const Eigen::Vector3d& v_estimate,
            bool armed, const Eigen::Vector3d& wind);

  [[nodiscard]] DroneState state() const;
  [[nodiscard]] const ContactState& contacts() const;
  /// The lowest support point's height above the pad surface, along the
  /// pad's z [m] (negative: below it).
  [[nodiscard]] double support_height_above_pad() const;
  /// The airframe body origin's pose in the world.
  [[nodiscard]] Eigen::Isometry3d T_world_body() const;
  [[nodiscard]] const DroneOptions& options() const;
  /// Motor thrusts now [N].
  [[nodiscard]] const Eigen::VectorXd& motor_thrusts() const;

 private:
  struct Impl;
  std::unique_ptr<Impl> impl_;
};

}  // namespace touchdown::mission
