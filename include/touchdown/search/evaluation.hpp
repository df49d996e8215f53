#pragma once
/// \file
/// What the violation search keeps of one scenario run (RLaGA paper, §3):
/// the outcome's violation type, DTL and TTL for the fitness (eq. 1), the
/// summed occlusion reward of the run's camera frames (eq. 5, for eq. 6),
/// and the 2 × 2 × 2 m cells the drone's trajectory visited (§4.3's 3-D
/// trajectory coverage). Shared by the GA, the DQN's reward, the results
/// directory and the metrics.
#include <array>
#include <string>
#include <vector>

#include "touchdown/scenario/run.hpp"

namespace touchdown::search {

/// Edge of a trajectory-coverage cell [m] (source §4.3).
inline constexpr double kCoverageCell = 2.0;

/// eq. 5: the reward of one camera frame from the marker's area in the
/// image, S_gt (as if nothing were in front of it) and S_d (what is
/// visible): R = S_gt / S_d, and 0 when S_d = 0 (the marker not in view or
/// fully hidden) or S_d = S_gt (nothing hides it). Areas in pixels.
inline double frame_reward(double area_truth_px, double area_visible_px) {
  if (area_visible_px <= 0 || area_visible_px >= area_truth_px) return 0.0;
  return area_truth_px / area_visible_px;
}

/// An object that hid part of the target from the run's camera
/// (scenario::OccluderRecord).
struct OccluderFact {
  std::string object;  ///< "static_objects[2] (tree)"
  double first_t = 0, last_t = 0;
  int frames = 0, frames_descending = 0;
};

/// What a run's classification rests on (issue 52), from the world's truth:
/// the oracle's observability, the detection the descent was committed on,
/// the occluders of the target, the collision. Results written before issue
/// 52 have none (recorded = false), and read as such.
struct Facts {
  bool recorded = false;
  /// The violation is the system's doing: every violation but a Type II in
  /// a run whose target was never observable long enough (oracle.hpp).
  bool fair = true;
  double sighting_time = 0;                            ///< [s] the oracle's "long enough"
  double observable_s = 0, longest_s = 0;              ///< the run's camera [s]
  double probe_observable_s = 0, probe_longest_s = 0;  ///< the probe above the marker [s]
  std::string probe_failure = "observable";            ///< the probe's most frequent scenario::Sight
  double probe_contrast = 0;                           ///< its median contrast [grey levels]
  bool descent_started = false;
  double descent_time = 0;
  std::array<double, 2> descent_target{0, 0};  ///< [m]
  /// The detection the descent was committed on (its object: "marker",
  /// "distractors[0] (lookalike)", "ground", ...); empty: none.
  std::string trigger;
  double trigger_t = 0;
  std::string last_accepted;     ///< the run's last accepted detection's object; empty: none
  bool false_detection = false;  ///< some accepted detection was not on the target
  std::vector<OccluderFact> occluders;
  std::string collided_with;  ///< the collision's object ("static_objects[1] (pole)"); empty: none
  std::string collision_phase;
  /// The object that came nearest the drone in flight
  /// (ScenarioOutcome::nearest); empty: none (no objects, or a result
  /// written before it was recorded).
  std::string nearest_object;
  double nearest_m = 0;  ///< [m]; 0 at a collision
  double nearest_t = 0;  ///< [s]
  std::string nearest_phase;
};

struct Evaluation {
  scenario::Violation violation = scenario::Violation::None;
  std::string message;     ///< the run's one-line outcome
  double dtl = 0;          ///< distance to landing [m] (ScenarioOutcome::dtl)
  double ttl = 0;          ///< time to landing [s]; the time limit when it did not land
  double time_limit = 60;  ///< of the run [s] (scales TTL in the fitness)
  bool landed = false;
  bool collided = false;
  double reward_sum = 0;  ///< eq. 5 summed over the run's camera frames
  int frames = 0;         ///< camera frames
  double flight_s = 0;    ///< simulated time [s]
  /// Cells floor(p / kCoverageCell) visited by the drone, sorted, unique.
  std::vector<std::array<int, 3>> cells;
  Facts facts;

  [[nodiscard]] bool violation_found() const { return scenario::is_violation(violation); }
  /// The system under test failed (threw, or answered garbage): no violation,
  /// scored as none.
  [[nodiscard]] bool system_failed() const { return violation == scenario::Violation::SystemFailed; }
  /// A violation the system is to blame for (Facts::fair); a result without
  /// facts (before issue 52) counts every violation.
  [[nodiscard]] bool fair_violation() const { return violation_found() && (!facts.recorded || facts.fair); }
};

/// The search's view of a finished run: its outcome, eq. 5 summed over its
/// frames and the cells its trajectory visited.
Evaluation evaluate_result(const scenario::ScenarioResult& result, double time_limit);

}  // namespace touchdown::search
