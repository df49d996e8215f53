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

  [[nodiscard]] bool violation_found() const { return violation != scenario::Violation::None; }
};

/// The search's view of a finished run: its outcome, eq. 5 summed over its
/// frames and the cells its trajectory visited.
Evaluation evaluate_result(const scenario::ScenarioResult& result, double time_limit);

}  // namespace touchdown::search
