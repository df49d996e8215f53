#pragma once
/// \file
/// One scenario run, closed loop: world → camera → landing system → world,
/// and its outcome with the RLaGA paper's violation semantics:
/// violation = a collision with any object, or a final landing position more
/// than 1.5 m from the marker centre (including no landing within the time
/// limit). Classified automatically (the paper did it by hand from videos):
///   Type I    landed at a false-positive location (a detection elsewhere
///             triggered the descent);
///   Type II   no landing: the marker was never (or not long enough) detected;
///   Type III  collision.
#include <Eigen/Core>
#include <array>
#include <chrono>
#include <functional>
#include <string>
#include <string_view>
#include <vector>

#include "touchdown/core/enum_names.hpp"
#include "touchdown/scenario/camera.hpp"
#include "touchdown/scenario/landing_system.hpp"
#include "touchdown/scenario/world.hpp"

namespace touchdown::scenario {

enum class Violation {
  None,
  TypeI,    ///< landed > radius from the marker: a false detection led it there
  TypeII,   ///< did not land in time
  TypeIII,  ///< collision
};

}  // namespace touchdown::scenario

// As the outputs print a type (JSON "type", the campaign CSV, "Type II" in
// messages): the paper's roman numerals.
template <>
struct touchdown::EnumNames<touchdown::scenario::Violation> {
  static constexpr std::array<std::string_view, 4> names{"none", "I", "II", "III"};
};

namespace touchdown::scenario {

inline std::string_view to_string(Violation v) { return enum_name(v); }

struct RunOptions {
  CameraOptions camera;
  FlightOptions flight;
  double violation_radius = 1.5;  ///< [m]
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

/// Per camera frame: the eq. 5 reward inputs and what the system detected.
struct FrameRecord {
  double t = 0;
  double marker_area_visible_px = 0;
  double marker_area_truth_px = 0;
  int detections = 0;      ///< markers the system reported
  int accepted = 0;        ///< of which counted as the target
  int false_accepted = 0;  ///< accepted, but not on the true marker (mask)
};

struct Timing {
  double render_s = 0;
  double system_s = 0;   ///< detection and decision
  double physics_s = 0;  ///< flight, objects, collisions
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
  double flight_s = 0;           ///< simulated time flown [s]
  int frame_count = 0;           ///< camera frames the system was given
  Timing timing;

  [[nodiscard]] bool violation() const { return status != Violation::None; }
  [[nodiscard]] bool ok() const { return status == Violation::None; }
};

/// A run's outcome and its per-step records.
struct ScenarioResult : ScenarioOutcome {
  std::vector<TrajectorySample> trajectory;  ///< every physics step
  std::vector<FrameRecord> frames;           ///< every camera frame
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

  /// One physics step (a camera frame first when one is due); false, and
  /// nothing done, once the run is over.
  bool step();
  /// Time limit reached, collided or landed.
  [[nodiscard]] bool over() const;

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
};

/// Runs `system` in `scenario` until it lands, collides or the time limit.
/// Throws InvalidArgument for invalid options or scenario.
ScenarioResult run_scenario(const Scenario& scenario, LandingSystem& system, const RunOptions& options = {});

}  // namespace touchdown::scenario
