#pragma once
/// \file
/// The landing mission's guidance: turns the state machine's state, the
/// pad's motion (the vehicle's odometry) and the drone's estimated state
/// into trajectory setpoints for the drone's position controller
/// (twin::Setpoint: position, velocity and acceleration feed-forward, yaw).
///
/// - searching, rendezvous: hold the rendezvous point, moving with the pad;
/// - tracking: hold the tracking point, moving with the pad;
/// - landing: the minimum-jerk Bézier plan in the pad frame
///   (plan/planner.hpp) from the tracking point to the terminal point
///   above the pad centre, inside the visual safe flight corridor of the
///   vehicle's camera, replanned every `replan_period` from the plan's own
///   reference (from the estimate when the two drift apart by more than
///   `replan_reset_distance`): the corridor is built once per landing and
///   reused, the segment durations are the remaining ones of the last plan
///   (the time allocation runs again only when they fail); below the
///   terminal point the terminal rule takes over: straight down over the
///   pad centre at `terminal_speed` relative to the pad, where the corridor
///   has degenerated to a column (the paper's plan and landing_plan_replan
///   both show it thinning to nothing at the pad); the plan ends moving down
///   at that speed, and the rule holds the height while the drone is off
///   the centre by more than `terminal_centre_tolerance`;
/// - shutdown: no setpoint (motors off).
///
/// The pad frame is x forward, y left, z up, origin at the pad centre on its
/// surface; it moves with the vehicle, turning about the world z. Thread-
/// safety: one instance per mission. Allocation: the landing's first plan
/// (corridor, time allocation) allocates; the replans at the remaining
/// durations do not (plan::Replanner keeps its work space).
#include <Eigen/Core>
#include <Eigen/Geometry>
#include <limits>
#include <memory>
#include <string>
#include <vector>

#include "touchdown/mission/state_machine.hpp"
#include "touchdown/plan/planner.hpp"
#include "touchdown/twin/flight_control.hpp"

namespace touchdown::mission {

/// The pad's motion now (world frame).
struct PadState {
  Eigen::Isometry3d T_world_pad = Eigen::Isometry3d::Identity();
  Eigen::Vector3d velocity = Eigen::Vector3d::Zero();      ///< of the pad origin [m/s]
  Eigen::Vector3d acceleration = Eigen::Vector3d::Zero();  ///< of the pad origin [m/s²]
  double yaw_rate = 0;                                     ///< [rad/s]
  /// [rad/s²]: a vehicle changing its turn (a figure-eight's lobe switch,
  /// 1.6 rad/s² at 4 m/s) swings a point 1.2 m behind the pad sideways at
  /// ω̇ × p, 2 m/s², which the setpoint must carry.
  double yaw_acceleration = 0;
};

/// A pad-frame state (position, velocity, acceleration relative to the
/// moving pad) in the world, and back (rigid-body kinematics of a frame
/// turning about z: v = v_pad + R(v_rel + ω × p), a = a_pad + R(a_rel + 2ω ×
/// v_rel + ω × (ω × p) + ω̇ × p)).
plan::KinematicState pad_to_world(const PadState& pad, const plan::KinematicState& relative);
plan::KinematicState world_to_pad(const PadState& pad, const plan::KinematicState& world);

struct GuidanceOptions {
  /// The planner: order, segments, world-frame limits, time allocation and
  /// the corridor (with the camera's field of view, pad frame).
  plan::PlannerOptions planner = default_planner();
  Eigen::Vector3d tracking_point{-1.2, 0.0, 1.0};  ///< pad frame [m] (centre of mass)
  double replan_period = 0.1;                      ///< [s], (0, 1]: 10 Hz
  double replan_stop = 0.5;                        ///< [s] no replans once the plan has less than this left
  double replan_reset_distance = 0.15;  ///< [m] estimate vs reference beyond which a replan starts from the estimate
  /// The terminal point: this far above the landed centre-of-mass height
  /// [m], > 0; the plan's goal (at rest relative to the pad).
  double terminal_height = 0.25;
  double terminal_speed = 0.35;  ///< [m/s] descent relative to the pad below the terminal point, > 0
  /// [m] the terminal rule descends only while the estimate is this close
  /// to the pad centre horizontally (else it holds the height).
  double terminal_centre_tolerance = 0.05;
  double terminal_acceleration = 1.0;  ///< [m/s²] of the terminal descent rate's changes
  /// The pad-frame integral on the horizontal position (every flying
  /// state): gain [1/s] and limit [m] of the offset it adds to the setpoint.
  double pad_integral_gain = 0.6;
  double pad_integral_limit = 0.5;
  double pad_integral_window = 0.6;  ///< [m] integrates only while the error is below this

  /// The bundled planner set-up: order 7, 2 segments, 3 m/s and 4 m/s²
  /// per world axis, and the corridor of a camera 0.5 m ahead of the pad
  /// centre looking back and 20° up (87° × 58°, 0.2–6 m).
  static plan::PlannerOptions default_planner();
  /// False (with "guidance.key: problem" in *why) for an invalid value.
  [[nodiscard]] bool validate(std::string* why) const;
};

struct GuidanceOutput {
  twin::Setpoint setpoint;         ///< world frame
  plan::KinematicState reference;  ///< the same, relative to the pad
  ReplanOutcome replan = ReplanOutcome::None;
  bool have_plan = false;  ///< landing: a plan (or the terminal rule) is being flown
  bool terminal = false;   ///< the terminal rule is flying
  double replan_ms = 0;    ///< wall time of this step's replan
};

class Guidance {
 public:
  /// `landed_com_height`: the drone's centre of mass above the pad surface
  /// when it stands on it [m]. Throws InvalidArgument for invalid options.
  Guidance(GuidanceOptions options, double landed_com_height);

  /// The setpoint at time t [s] for `state` (`entered`: the state began at
  /// this step), from the pad's motion and the drone's estimated state
  /// relative to the pad (`estimate`) or, before the tracker locks, the
  /// external fix's (`fix`).
  GuidanceOutput update(double t, MissionState state, bool entered, const PadState& pad,
                        const plan::KinematicState& estimate, const Eigen::Vector3d& fix,
                        const StateMachineOptions& machine);

  [[nodiscard]] const GuidanceOptions& options() const { return options_; }
  /// The plan being flown (pad frame, from plan_start()); valid when
  /// has_plan().
  [[nodiscard]] const plan::PiecewiseBezier& trajectory() const { return trajectory_; }
  [[nodiscard]] bool has_plan() const { return have_plan_; }
  [[nodiscard]] double plan_start() const { return plan_t0_; }
  /// Why the last replan that failed failed.
  [[nodiscard]] const std::string& message() const { return message_; }
  /// The terminal point, pad frame.
  [[nodiscard]] Eigen::Vector3d terminal_point() const;
  /// Where the terminal rule puts the centre of mass down (pad frame, x y):
  /// the pad centre, or ahead of it by what the drone will move when it
  /// levels after touching down tilted (the mission sets it each step).
  void set_touchdown_point(const Eigen::Vector2d& p) { touchdown_point_ = p; }
  /// The wind in the prediction: the acceleration [m/s²] the airframe has
  /// beyond what the estimated wind's drag takes at the pad's speed (its
  /// tilt limit's g tan θ less |D(v_pad − ŵ)| / m). The next new corridor
  /// plans within min(planner.a_max, this), floored at half of a_max (a
  /// wind that leaves less is the upset guard's to refuse).
  void set_acceleration_capacity(double a) { capacity_ = a; }

 private:
  GuidanceOutput compute(double t, MissionState state, bool entered, const PadState& pad,
                         const plan::KinematicState& estimate, const Eigen::Vector3d& fix,
                         const StateMachineOptions& machine);
  ReplanOutcome replan(double t, const PadState& pad, const plan::KinematicState& from, bool fresh);
  GuidanceOutput hold(const PadState& pad, const Eigen::Vector3d& point) const;

  GuidanceOptions options_;
  double landed_com_height_;
  Eigen::Vector2d touchdown_point_ = Eigen::Vector2d::Zero();
  double capacity_ = std::numeric_limits<double>::infinity();  ///< set_acceleration_capacity
  plan::PiecewiseBezier trajectory_;
  bool have_plan_ = false;
  double plan_t0_ = 0;
  std::vector<plan::Polytope> polytopes_;  ///< the landing's corridor, one polytope per segment
  /// Replans at the remaining durations, in the corridor and with both
  /// segments in its touchdown part (the start past the rear part).
  std::unique_ptr<plan::Replanner> replanner_, replanner_low_;
  std::vector<double> durations_;
  std::string message_;
  double next_replan_ = 0;
  bool terminal_ = false;
  double terminal_last_t_ = 0, terminal_z_ = 0, terminal_rate_ = 0;
  double last_update_ = 0;
  Eigen::Vector2d offset_ = Eigen::Vector2d::Zero();  ///< the pad-frame integral's offset
};

}  // namespace touchdown::mission
