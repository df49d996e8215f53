#pragma once
/// \file
/// The landing mission's state machine (the non-robocentric landing paper's
/// five states, plus the aborts and failsafes the paper's system lacks):
///
///     searching ──arrived──▶ rendezvous ──locked──▶ tracking ──stable──▶ landing ──touchdown zone──▶ shutdown
///         ▲                      │  ▲                  ▲  │                 │
///         └──rendezvous timeout──┘  └────pose lost─────┼──┘◀────────────────┤ pose lost
///                                                      └────────────────────┘ plan infeasible, vehicle
///                                                                             too agile, low without a plan
///
/// - searching: fly to the rendezvous point behind the vehicle on the
///   external position fix (GNSS or the vehicle's odometry);
/// - rendezvous: hold there while the LED tracker initialises; after
///   `lock_frames` Ok pose frames, none more than `lock_max_gap` after the
///   one before (frames without an Ok pose in between do not count) → tracking;
/// - tracking: follow the pad on the tracker's pose until the tracking
///   error and the relative speed have stayed small for `stable_time`;
/// - landing: the guidance plans and flies the trajectory in the pad frame;
///   near the pad centre and low enough → shutdown (motors off);
/// - every guard that aborts names its option; after `max_landing_attempts`
///   aborted landings the machine gives up (holds at the rendezvous point).
///
/// No I/O, no clock, no allocation: a flight stack or ground station calls
/// step() with what it measured at time t and acts on the output. Thread-
/// safety: one instance per mission.
#include <Eigen/Core>
#include <array>
#include <limits>
#include <string>
#include <string_view>

#include "touchdown/core/enum_names.hpp"

namespace touchdown::mission {

enum class MissionState { Searching, Rendezvous, Tracking, Landing, Shutdown };

/// Why a transition happened (each abort names the guard's option).
enum class TransitionReason {
  ArrivedAtRendezvous,  ///< within rendezvous_radius of the rendezvous point (fix)
  TrackerLocked,        ///< lock_frames Ok pose frames without a gap
  TrackingStable,       ///< tracking error and relative speed small for stable_time
  TouchdownZone,        ///< within shutdown_radius and shutdown_height (or contact felt): motors off
  RendezvousTimeout,    ///< no lock within rendezvous_timeout: approach again
  PoseLost,             ///< no Ok pose for pose_timeout
  PlanInfeasible,       ///< max_plan_failures consecutive replans failed
  VehicleAccelerating,  ///< the vehicle's acceleration above max_vehicle_acceleration
  VehicleTurning,       ///< the vehicle's yaw rate above max_vehicle_yaw_rate
  LowWithoutPlan,       ///< below min_height_without_plan with no valid plan
  LowOffCentre,         ///< down to shutdown_height but beyond shutdown_radius: climb back
  GaveUp,               ///< unused since 2026-12-07 (a give-up names the guard that aborted the last landing)
  WindTooStrong,        ///< slide_ratio above max_slide_ratio: the landed drone would be blown off or over
  NotStable,            ///< in tracking for max_tracking_time without becoming stable: gives up
};

/// The outcome of the guidance's replan at this step, if it replanned.
enum class ReplanOutcome { None, Ok, Failed };

}  // namespace touchdown::mission

template <>
struct touchdown::EnumNames<touchdown::mission::MissionState> {
  static constexpr std::array<std::string_view, 5> names{"searching", "rendezvous", "tracking", "landing", "shutdown"};
};
template <>
struct touchdown::EnumNames<touchdown::mission::TransitionReason> {
  static constexpr std::array<std::string_view, 14> names{
      "arrived_at_rendezvous", "tracker_locked",   "tracking_stable", "touchdown_zone",
      "rendezvous_timeout",    "pose_lost",        "plan_infeasible", "vehicle_accelerating",
      "vehicle_turning",       "low_without_plan", "low_off_centre",  "gave_up",
      "wind_too_strong",       "not_stable"};
};

namespace touchdown::mission {

inline std::string_view to_string(MissionState s) { return enum_name(s); }
inline std::string_view to_string(TransitionReason r) { return enum_name(r); }

/// Guards and thresholds; pad frame: x forward, y left, z up, origin at the
/// pad centre on its surface.
struct StateMachineOptions {
  Eigen::Vector3d rendezvous_point{-2.5, 0.0, 1.5};  ///< pad frame [m], behind and above the pad
  double rendezvous_radius = 0.5;                    ///< [m] "arrived" on the fix
  int lock_frames = 10;                              ///< Ok pose frames that lock the tracker, ≥ 1
  double lock_max_gap = 0.2;                         ///< [s] Ok frames further apart restart the count
  double rendezvous_timeout = 20;                    ///< [s] in rendezvous without a lock → searching
  double stable_error = 0.15;             ///< [m] tracking error (setpoint − estimate) that counts as stable
  double stable_speed = 0.4;              ///< [m/s] relative speed to the tracking point that counts as stable
  double stable_time = 1.5;               ///< [s] both stable this long → landing
  double pose_timeout = 0.5;              ///< [s] no Ok pose this long in tracking or landing → rendezvous
  int max_plan_failures = 5;              ///< consecutive failed replans in landing → tracking, ≥ 1
  double max_vehicle_acceleration = 4.0;  ///< [m/s²] above it in landing → tracking
  double max_vehicle_yaw_rate = 1.2;      ///< [rad/s] above it in landing → tracking
  double min_height_without_plan = 0.6;   ///< [m] above the pad: lower in landing needs a valid plan
  double shutdown_radius = 0.10;          ///< [m] horizontal distance from the pad centre
  double shutdown_height = 0.02;          ///< [m] of the drone's lowest point above the pad surface
  /// Touchdown felt (as PX4's land detector feels ground contact): below
  /// contact_height [m] the relative vertical speed has stayed under
  /// contact_speed [m/s] for contact_time [s] — the feet are on the pad even
  /// if the estimate's height has a bias.
  double contact_height = 0.05;
  double contact_speed = 0.1;
  double contact_time = 0.2;
  int max_landing_attempts = 3;  ///< aborted landings before giving up, ≥ 1
  /// Land only while the side force on the landed, unpowered drone (the
  /// drag of the wind relative to the pad plus its mass times the pad's
  /// acceleration) stays below this share of what holds it: the pad's
  /// friction (μ (m g + the pad's hold force)) and, against tipping, the
  /// weight's and hold force's moment about the support polygon's nearest
  /// edge over the centre of mass's height; above it: no landing from
  /// tracking, and in landing → tracking. In (0, 1]; the rest is the
  /// margin for gusts.
  double max_slide_ratio = 0.7;
  /// In tracking this long [s] without becoming stable: give up, named by
  /// what held it most often — its own error or speed (not_stable), the
  /// vehicle accelerating or turning, the wind (wind_too_strong)
  /// rather than follow the vehicle until the mission's timeout; > 0.
  double max_tracking_time = 30;
  /// False (with "key: problem" in *why) for an invalid value.
  [[nodiscard]] bool validate(std::string* why) const;
};

/// What the ground station knows at time t. Positions and velocities are
/// the drone's relative to the pad, in the pad frame.
struct StateMachineInputs {
  double t = 0;  ///< [s], non-decreasing
  /// The external fix's relative position (searching, rendezvous).
  Eigen::Vector3d p_fix = Eigen::Vector3d::Zero();
  /// A pose frame was processed this step, and whether it was Ok.
  bool new_pose = false, pose_ok = false;
  /// The tracker-based estimate (valid while Ok frames keep coming).
  Eigen::Vector3d p_estimate = Eigen::Vector3d::Zero();
  Eigen::Vector3d v_estimate = Eigen::Vector3d::Zero();
  /// The drone's lowest point above the pad surface, from the estimate [m].
  double height = 0;
  double tracking_error = 0;  ///< [m] |setpoint − estimate|
  ReplanOutcome replan = ReplanOutcome::None;
  bool have_plan = false;  ///< the guidance holds a valid plan
  /// The descent the guidance commands relative to the pad [m/s]: contact
  /// is felt only while it is at least contact_speed (a stop where the
  /// guidance holds the height, or is only starting down, is not a
  /// touchdown); infinite: not known.
  double commanded_descent = std::numeric_limits<double>::infinity();
  double vehicle_acceleration = 0;                           ///< [m/s²] magnitude, from the vehicle's odometry
  double vehicle_yaw_rate = 0;                               ///< [rad/s]
  Eigen::Vector3d tracking_point = Eigen::Vector3d::Zero();  ///< where tracking holds the drone (pad frame)
  /// Where the terminal rule puts the drone down (pad frame, x y): the
  /// shutdown radius is counted from it.
  Eigen::Vector2d touchdown_point = Eigen::Vector2d::Zero();
  /// The landed drone's side force over what friction holds (see
  /// StateMachineOptions::max_slide_ratio), from the wind estimate.
  double slide_ratio = 0;
};

struct Transition {
  double t = 0;
  MissionState from = MissionState::Searching, to = MissionState::Searching;
  TransitionReason reason = TransitionReason::ArrivedAtRendezvous;
};

struct StateMachineOutput {
  MissionState state = MissionState::Searching;
  bool transitioned = false;  ///< `transition` happened at this step
  Transition transition;
  bool motors_off = false;  ///< shutdown: cut the motors
  bool gave_up = false;     ///< max_landing_attempts reached; holding at the rendezvous point
};

class StateMachine {
 public:
  /// Throws InvalidArgument for invalid options.
  explicit StateMachine(StateMachineOptions options);

  StateMachineOutput step(const StateMachineInputs& in);

  [[nodiscard]] MissionState state() const { return state_; }
  [[nodiscard]] int landing_attempts() const { return attempts_; }
  [[nodiscard]] const StateMachineOptions& options() const { return options_; }

 private:
  StateMachineOutput go(MissionState to, TransitionReason why, double t);

  StateMachineOptions options_;
  MissionState state_ = MissionState::Searching;
  double entered_ = 0;        ///< time the state was entered
  bool started_ = false;      ///< entered_ set from the first step
  int ok_run_ = 0;            ///< Ok frames since the last gap
  double last_ok_ = -1e300;   ///< time of the last Ok frame
  double stable_since_ = -1;  ///< < 0: not stable
  /// Tracking steps each clearance failed since the state was entered: the
  /// drone's own error or speed, the vehicle accelerating, turning, the
  /// wind (the upset guard); the most frequent names a give-up.
  std::array<long, 4> blocked_{};
  double stalled_since_ = -1;  ///< < 0: no contact felt
  int plan_failures_ = 0;
  int attempts_ = 0;
  bool gave_up_ = false;
};

}  // namespace touchdown::mission
