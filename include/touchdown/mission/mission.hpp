#pragma once
/// \file
/// One landing mission, closed loop, in simulation: the ground vehicle
/// drives its path with the pad and the camera; the perception measures the
/// drone from the camera's frames; the ground station runs the state
/// machine and the guidance at `ground_rate_hz` and sends setpoints over a
/// link with latency and drop-outs; the drone's flight controller fuses its
/// IMU with the position fixes and pose measurements that reach it (a Kalman
/// filter per axis with delayed measurements) and flies the setpoints; ODE
/// decides how it touches down on the moving pad.
///
/// Outcomes: `landed` (at rest on the pad, standing on its feet, inside the
/// pad, nothing else touched), `crashed` (touched the ground, struck the pad
/// with a propeller, arm or the body, tipped over or came to rest off the
/// pad), `aborted` (the state machine gave up), `timeout`.
///
/// Determinism: every random stream is drawn from (seed, run index); the
/// results of run_missions() are the same for any thread count (only the
/// replans' wall times differ).
#include <Eigen/Core>
#include <array>
#include <cstdint>
#include <functional>
#include <memory>
#include <string>
#include <utility>
#include <vector>

#include "touchdown/core/batch.hpp"
#include "touchdown/core/registry.hpp"
#include "touchdown/mission/drone.hpp"
#include "touchdown/mission/guidance.hpp"
#include "touchdown/mission/perception.hpp"
#include "touchdown/mission/perception_render.hpp"
#include "touchdown/mission/state_machine.hpp"
#include "touchdown/mission/vehicle.hpp"
#include "touchdown/mission/wind.hpp"

namespace touchdown::mission {

/// The radio link between the ground station and the drone (both ways).
struct LinkOptions {
  double latency = 0.03;  ///< [s], ≥ 0
  double dropout = 0.02;  ///< probability a message is lost, [0, 1)
  /// The drone holds its last setpoint this long without a new one, then
  /// stops moving relative to the world (PX4's offboard-loss hold) [s].
  double setpoint_timeout = 0.5;
};

/// The external position fix before the tracker locks (RTK-less GNSS on
/// both, or the vehicle's odometry and the drone's flow sensor): the
/// drone's position relative to the pad with a slowly wandering error.
struct FixOptions {
  double rate_hz = 5;            ///< > 0
  double sigma = 0.3;            ///< per horizontal axis [m] (vertical the same)
  double correlation_time = 20;  ///< of the error [s], > 0
};

struct MissionOptions {
  VehicleOptions vehicle;
  DroneOptions drone;
  PadGeometry pad;
  StateMachineOptions machine;
  GuidanceOptions guidance;
  /// The perception in the loop: a name in perception_registry() — the
  /// built-in `model` or `render`, or one registered by the user.
  std::string perception = "model";
  PerceptionModelOptions perception_model;  ///< its camera is the guidance corridor's
  /// The `render` mode's camera intrinsics, constellation, renderer and
  /// tracker (its pose in the pad frame, rate and latency are the model's).
  RenderPerceptionOptions render;
  WindOptions wind;
  LinkOptions link;
  FixOptions fix;
  /// The drone's start: hovering here relative to the vehicle's start
  /// (vehicle frame = world at t = 0) [m].
  Eigen::Vector3d drone_start{-6.0, -3.0, 3.0};
  double ground_rate_hz = 50;    ///< state machine, guidance and setpoints [Hz]
  double imu_accel_sigma = 0.1;  ///< accelerometer noise per sample [m/s²]
  double timeout = 90;           ///< mission time limit [s]
  /// False (with "key: problem", the key as in MISSION.yaml) for an invalid
  /// value, including a vehicle the drone's limits cannot follow and a
  /// camera that cannot see the rendezvous or tracking point.
  [[nodiscard]] bool validate(std::string* why) const;
  /// The options with the perception model's camera set from the corridor.
  [[nodiscard]] PerceptionModelOptions perception_options() const;
};

enum class MissionOutcome { Landed, Aborted, Crashed, Timeout };

}  // namespace touchdown::mission

template <>
struct touchdown::EnumNames<touchdown::mission::MissionOutcome> {
  static constexpr std::array<std::string_view, 4> names{"landed", "aborted", "crashed", "timeout"};
};

namespace touchdown::mission {

inline std::string_view to_string(MissionOutcome o) { return enum_name(o); }

/// A sample of a recorded mission (50 Hz), world frame unless named.
struct MissionSample {
  double t = 0;
  MissionState state = MissionState::Searching;
  Eigen::Vector3d drone = Eigen::Vector3d::Zero(), drone_v = Eigen::Vector3d::Zero();        ///< true centre of mass
  Eigen::Vector3d estimate = Eigen::Vector3d::Zero(), estimate_v = Eigen::Vector3d::Zero();  ///< the drone's own
  Eigen::Vector3d setpoint = Eigen::Vector3d::Zero(), setpoint_v = Eigen::Vector3d::Zero();  ///< as the drone flies it
  Eigen::Vector3d pad = Eigen::Vector3d::Zero(), pad_v = Eigen::Vector3d::Zero();
  double pad_yaw = 0;
  Eigen::Vector3d relative = Eigen::Vector3d::Zero();  ///< the drone in the pad frame (truth)
  double pose_error = -1;                              ///< the last Ok measurement's error [m]; < 0: none yet
  double tracking_error = 0;                           ///< |the guidance's reference − true position| (pad frame) [m]
  double tilt = 0;                                     ///< the body's z axis from the vertical [rad]
  double thrust = 0;                                   ///< of all motors [N]
  /// The wind at the drone (truth: mean, gusts, turbulence) and the flight
  /// controller's estimate of it (drone.wind_observer_time; 0 without) [m/s].
  Eigen::Vector3d wind = Eigen::Vector3d::Zero(), wind_estimate = Eigen::Vector3d::Zero();
};

/// One Ok pose measurement of a recorded mission: the drone's centre of
/// mass in the pad frame as measured against the truth at its capture.
struct PoseSample {
  double t_capture = 0;                                ///< [s]
  Eigen::Vector3d truth = Eigen::Vector3d::Zero();     ///< pad frame [m]
  Eigen::Vector3d measured = Eigen::Vector3d::Zero();  ///< pad frame [m]
};

struct MissionResult {
  MissionOutcome outcome = MissionOutcome::Timeout;
  std::string message;  ///< why (crash cause, abort reason)
  double duration = 0;  ///< simulated [s]
  /// At rest on the pad: the airframe's body origin from the pad centre,
  /// horizontally [m] (landed and crashed-on-the-pad runs; else NaN).
  double touchdown_error = std::numeric_limits<double>::quiet_NaN();
  /// Relative to the pad at the first foot contact [m/s] (NaN: none).
  Eigen::Vector3d touchdown_velocity = Eigen::Vector3d::Constant(std::numeric_limits<double>::quiet_NaN());
  std::array<double, 5> time_in_state{};  ///< [s] per MissionState
  /// |reference − true position| (the guidance's pad-frame reference) in
  /// landing before touchdown [m].
  double max_tracking_error = 0;
  /// The largest per-axis world speed and acceleration in landing before
  /// touchdown, and the planner's limits they are held to.
  double max_axis_speed = 0, max_axis_acceleration = 0, v_limit = 0, a_limit = 0;
  int replans = 0, replan_failures = 0;
  double replan_median_ms = 0;
  int pose_frames = 0, pose_ok = 0;                  ///< camera frames with the drone in view, of them with a pose
  double pose_error_median = 0, pose_error_max = 0;  ///< [m] of the Ok ones
  int landing_attempts = 0;
  std::vector<Transition> transitions;
  std::vector<MissionSample> trace;  ///< when recorded
  std::vector<PoseSample> poses;     ///< every Ok pose measurement, when recorded (a perception's error by range)
  [[nodiscard]] bool landed() const { return outcome == MissionOutcome::Landed; }
  [[nodiscard]] double touchdown_speed() const { return touchdown_velocity.norm(); }
};

/// Makes a mission's perception, seeded; called concurrently from worker
/// threads (one perception per mission).
using PerceptionFactory = std::function<std::unique_ptr<Perception>(const MissionOptions&, std::uint64_t seed)>;

/// The registry of mission perceptions (core/registry.hpp, the idiom of the
/// test world's systems): `model` (PerceptionModel) and `render`
/// (RenderPerception) built in. Register your own and name it in
/// `MissionOptions::perception` (the mission file's `perception.mode`, the
/// app's `--perception`), or pass a factory to run_mission directly.
Registry<PerceptionFactory>& perception_registry();

/// The perception `options.perception` names, seeded (InvalidArgument for
/// a name not registered).
std::unique_ptr<Perception> make_default_perception(const MissionOptions& options, std::uint64_t seed);

/// One mission. Throws InvalidArgument for invalid options.
MissionResult run_mission(const MissionOptions& options, std::uint64_t seed, std::uint64_t run = 0, bool record = false,
                          const PerceptionFactory& perception = {});

/// `runs` missions (run i seeded by (seed, i)) on `threads` threads (0:
/// every core; core/batch.hpp's runner and rule); `progress` (any thread,
/// serialised) after each.
std::vector<MissionResult> run_missions(const MissionOptions& options, int runs, std::uint64_t seed, int threads,
                                        const PerceptionFactory& perception = {},
                                        const ProgressCallback& progress = {});

/// Why a mission did not land, in words a summary can count (empty for a
/// landing): a crash's cause ("crashed: touched the ground"); an abort's last guard
/// ("gave up: low_off_centre", the guard that aborted the last landing);
/// a timeout's state and the last guard that sent it there ("timeout in
/// rendezvous after rendezvous_timeout", "timeout in searching").
[[nodiscard]] std::string failure_reason(const MissionResult& r);

/// The failure reasons of `results` with their counts, the most frequent
/// first (ties by name): the summary's "why not landed".
using FailureCounts = std::vector<std::pair<std::string, int>>;
[[nodiscard]] FailureCounts count_failure_reasons(const std::vector<MissionResult>& results);

/// `a` and `b` added up, in the same order (an envelope's cells together).
[[nodiscard]] FailureCounts merge_failure_reasons(const FailureCounts& a, const FailureCounts& b);

}  // namespace touchdown::mission
