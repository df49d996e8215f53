#pragma once
/// \file
/// One scenario run, closed loop: world → camera → landing system → world,
/// and its outcome with the RLaGA paper's violation semantics:
/// violation = a collision with any object, or a final landing position more
/// than 1.5 m from the marker centre (including no landing within the time
/// limit). Classified automatically from the world's truth (the paper did it
/// by hand from videos; issue 52 made the types what the paper defines):
///   Type I      landed off the marker because the descent was committed on
///               a detection that was not the target (a look-alike, a wrong
///               id, a pattern, an object, the ground): the mask under the
///               detection that triggered it says so;
///   off-marker  landed off the marker after a true detection (drift, a
///               blind descent, the estimate off), or without any detection:
///               a violation, not a false positive;
///   Type II     no landing within the time limit; fair or not by the
///               observability oracle (oracle.hpp): was the target
///               observable long enough for any system to have landed?
///   Type III    collision.
/// Not a violation, and never a landing: the system under test failed (its
/// reset() or update() threw, or it answered a non-finite command): the
/// run ends there with status SystemFailed and the reason and the step in
/// `failure` (a plug-in's or a process's fault is a result, not a crash).
/// Every run records what its class rests on: the detection that triggered
/// the descent and what it was really on, the descent target, the objects
/// that hid the target and when, the object collided with and the phase.
#include <Eigen/Core>
#include <array>
#include <chrono>
#include <functional>
#include <memory>
#include <string>
#include <string_view>
#include <utility>
#include <vector>

#include "touchdown/core/enum_names.hpp"
#include "touchdown/scenario/camera.hpp"
#include "touchdown/scenario/landing_system.hpp"
#include "touchdown/scenario/oracle.hpp"
#include "touchdown/scenario/world.hpp"

namespace touchdown::scenario {

enum class Violation {
  None,
  TypeI,         ///< landed > radius from the marker: a false detection led it there
  TypeII,        ///< did not land in time
  TypeIII,       ///< collision
  OffMarker,     ///< landed > radius from the marker after a true detection (or none)
  SystemFailed,  ///< the system under test failed (threw, or a non-finite command): not a violation
};

/// Types I, II, III and off-marker (not None, not SystemFailed).
constexpr bool is_violation(Violation v) { return v != Violation::None && v != Violation::SystemFailed; }

}  // namespace touchdown::scenario

// As the outputs print a type (JSON "type", the campaign CSV, "Type II" in
// messages): the paper's roman numerals.
template <>
struct touchdown::EnumNames<touchdown::scenario::Violation> {
  static constexpr std::array<std::string_view, 6> names{"none", "I", "II", "III", "off-marker", "system-failed"};
};

namespace touchdown::scenario {

inline std::string_view to_string(Violation v) { return enum_name(v); }

struct RunOptions {
  CameraOptions camera;
  FlightOptions flight;
  double violation_radius = 1.5;  ///< [m]
  /// The observability oracle's thresholds and probe (oracle.hpp);
  /// sighting_time should be the system's own (the reference systems':
  /// MlsOptions::seen_time).
  OracleOptions oracle;
  /// Called for every camera frame after the system has seen it (video,
  /// inspection). May be empty.
  std::function<void(const CameraFrame&, const SystemOutput&, const DroneState&)> on_frame;
  /// Drives the dynamic objects with motion `external`: fills one action per
  /// such object each physics step. May be empty (they stay).
  std::function<void(const World&, std::vector<ObjectAction>&)> external;

  [[nodiscard]] bool validate(std::string* why) const;
};

struct TrajectorySample {
  double t = 0;
  Eigen::Vector3d position = Eigen::Vector3d::Zero();
  Eigen::Vector3d velocity = Eigen::Vector3d::Zero();
  double yaw_deg = 0;
  std::string phase;  ///< the landing system's phase at this step
};

/// Per camera frame: the eq. 5 reward inputs, what the system detected and
/// the oracle's view of the target.
struct FrameRecord {
  double t = 0;
  double marker_area_visible_px = 0;
  double marker_area_truth_px = 0;
  int detections = 0;      ///< markers the system reported
  int accepted = 0;        ///< of which counted as the target
  int false_accepted = 0;  ///< accepted, but not on the true marker (mask)
  TargetView view;         ///< the oracle's (Sight::OutOfView when it is off)
};

/// What a detection really was: the label of the mask under its centre, and
/// the scenario object there ("distractors[1] (lookalike)", "static_objects[0]
/// (box)", "marker", "ground", "sky").
struct DetectionTruth {
  double t = 0;
  Label label = Label::Ground;
  std::string object;
  int id = -1;                                       ///< the id the system read
  Eigen::Vector2d ground = Eigen::Vector2d::Zero();  ///< the world point under its centre [m]
  [[nodiscard]] bool on_target() const { return label == Label::Marker; }
};

/// An object that hid part of the target from the run's camera: frames in
/// which the target was in view but partly hidden and the object stood on a
/// line of sight to it.
struct OccluderRecord {
  std::string object;  ///< "static_objects[2] (tree)", "dynamic_objects[0] (person)"
  double first_t = 0, last_t = 0;
  int frames = 0;
  int frames_descending = 0;  ///< of them, after the descent started
};

struct Timing {
  double render_s = 0;
  double system_s = 0;   ///< detection and decision
  double physics_s = 0;  ///< flight, objects, collisions
  double oracle_s = 0;   ///< the observability oracle: its probe frames, the frames' views, the records
  double total_s = 0;
};

/// A run's outcome without its per-step records: what a campaign keeps of
/// each scenario. `status` is the violation type (None: no violation); the
/// violation flag is derived from it.
struct ScenarioOutcome {
  Violation status = Violation::None;
  std::string message;  ///< one line: what happened
  bool landed = false;
  bool collided = false;
  CollisionEvent collision;
  double dtl = 0;  ///< distance from the final (landing) position to the marker centre, horizontal [m]
  double ttl = 0;  ///< time to landing [s]; the run's time limit when it did not land
  Eigen::Vector3d final_position = Eigen::Vector3d::Zero();
  bool descent_started = false;
  double descent_time = 0;
  Eigen::Vector2d descent_target = Eigen::Vector2d::Zero();
  bool false_detection = false;  ///< some accepted detection was not on the true marker
  /// The accepted detection of the last frame before the descent started
  /// (the one the system committed on; the largest when several); none
  /// when no descent started or nothing was accepted before it.
  bool has_trigger = false;
  DetectionTruth trigger;
  /// The last accepted detection of the run (what a landing without a
  /// reported descent followed).
  bool has_last_accepted = false;
  DetectionTruth last_accepted;
  std::vector<OccluderRecord> occluders;
  std::string collision_phase;  ///< the system's phase when it collided
  /// The nearest any object came to the drone in flight, checked at every
  /// camera frame (0 at a collision): what, how near, when and in which of
  /// the system's phases. None (has_nearest false) in a scene without
  /// objects.
  bool has_nearest = false;
  NearestObject nearest;
  double nearest_t = 0;
  std::string nearest_phase;
  Observability observability;  ///< the oracle's summary (measured = false when off)
  double flight_s = 0;          ///< simulated time flown [s]
  int frame_count = 0;          ///< camera frames the system was given
  Timing timing;

  /// Why the system under test failed (status SystemFailed): what it
  /// threw or answered, and when ("update() threw at t = 3.01 s (step 301): …").
  std::string failure;

  [[nodiscard]] bool violation() const { return is_violation(status); }
  [[nodiscard]] bool ok() const { return status == Violation::None; }
};

/// A run's outcome and its per-step records.
/// One probe frame of the oracle: its time and what it saw.
struct ProbeRecord {
  double t = 0;
  TargetView view;
};

struct ScenarioResult : ScenarioOutcome {
  std::vector<TrajectorySample> trajectory;  ///< every physics step
  std::vector<FrameRecord> frames;           ///< every camera frame
  std::vector<ProbeRecord> probe;            ///< the oracle's probe frames
};

/// What run_scenario() gives a system's reset() for `scenario`: the camera,
/// the marker to look for, the approximate (GPS) target and the drone's radius.
SystemSetup system_setup(const Scenario& scenario, const RunOptions& options);

/// One closed-loop run stepped by its caller: run_scenario() is this class
/// stepped to the end. Lets a caller advance several runs in turn, look at
/// every step, or stop early. Holds references to `scenario` and `system`:
/// they must outlive it. `options` is copied.
class ScenarioRun {
 public:
  /// Resets `system` for `scenario`. `max_time` > 0 ends the run after that
  /// many simulated seconds if the scenario's time limit is longer. Throws
  /// InvalidArgument for invalid options or scenario.
  ScenarioRun(const Scenario& scenario, LandingSystem& system, const RunOptions& options = {}, double max_time = 0);
  /// A temporary scenario would be gone before the first step.
  ScenarioRun(Scenario&& scenario, LandingSystem& system, const RunOptions& options = {}, double max_time = 0) = delete;

  /// One physics step (a camera frame first when one is due); false, and
  /// nothing done, once the run is over. A system that throws from update()
  /// or answers a non-finite command ends the run (false, the world not
  /// stepped; failure() says why).
  bool step();
  /// Time limit reached, collided, landed or the system failed.
  [[nodiscard]] bool over() const;
  /// Why the system under test failed (empty: it has not): reset() or
  /// update() threw, or update() answered a non-finite command.
  [[nodiscard]] const std::string& failure() const { return failure_; }

  /// The last step's input to the system and its answer, valid until the
  /// next step (the input's frame, when it had one, and the output's phase
  /// are views).
  [[nodiscard]] const SystemInput& last_input() const { return last_input_; }
  [[nodiscard]] const SystemOutput& last_output() const { return last_output_; }
  [[nodiscard]] const World& world() const { return world_; }
  /// The run's duration limit [s]: the scenario's, or `max_time` if shorter.
  [[nodiscard]] double time_limit() const { return time_limit_; }

  /// The outcome at this point (the run's outcome once over()); moves the
  /// records out, so call it once.
  [[nodiscard]] ScenarioResult finish();

 private:
  const Scenario& scenario_;
  LandingSystem& system_;
  RunOptions options_;
  std::chrono::steady_clock::time_point start_;
  World world_;
  Renderer renderer_;
  double time_limit_ = 0;
  long steps_ = 0, k_ = 0;
  double frame_period_ = 0, next_frame_ = 0;
  int frame_index_ = 0;
  CameraFrame frame_;
  SceneState scene_;
  std::vector<ObjectAction> actions_;
  SystemInput last_input_;
  SystemOutput last_output_;
  ScenarioResult result_;
  std::string failure_;
  // The observability oracle: the target's code, the probe's camera and frame.
  std::unique_ptr<TargetOracle> oracle_;
  std::unique_ptr<Renderer> probe_renderer_;
  CameraOptions probe_camera_;
  CameraFrame probe_frame_;
  SceneState probe_scene_;
  double next_probe_ = 0;
  int probe_index_ = 0;
  // The objects that may hide the target: names and bounding spheres of
  // their solids (static in the world, dynamic in their own frame), in
  // static_objects then dynamic_objects order.
  std::vector<std::string> occluder_names_;
  std::vector<std::vector<std::pair<Eigen::Vector3d, double>>> occluder_spheres_;

  void record_frame(const SystemOutput& out, const DroneState& state);
  void probe(double t);
  DetectionTruth detection_truth(const Detection& d, double t) const;
  void build_occluders();
  void record_occluders(FrameRecord& rec, double t);
};

/// Runs `system` in `scenario` until it lands, collides or the time limit.
/// Throws InvalidArgument for invalid options or scenario.
ScenarioResult run_scenario(const Scenario& scenario, LandingSystem& system, const RunOptions& options = {});

}  // namespace touchdown::scenario
