// The search's view of a finished run (evaluation.hpp).
#include "touchdown/search/evaluation.hpp"

#include <algorithm>
#include <cmath>

namespace touchdown::search {

Evaluation evaluate_result(const scenario::ScenarioResult& result, double time_limit) {
  Evaluation e;
  e.violation = result.status;
  e.message = result.message;
  e.dtl = result.dtl;
  e.ttl = result.ttl;
  e.time_limit = time_limit;
  e.landed = result.landed;
  e.collided = result.collided;
  e.frames = result.frame_count;
  e.flight_s = result.flight_s;
  for (const scenario::FrameRecord& f : result.frames) {
    e.reward_sum += frame_reward(f.marker_area_truth_px, f.marker_area_visible_px);
  }
  e.cells.reserve(result.trajectory.size() / 16 + 1);
  for (const scenario::TrajectorySample& s : result.trajectory) {
    std::array<int, 3> c{};
    for (int k = 0; k < 3; ++k) c[k] = static_cast<int>(std::floor(s.position[k] / kCoverageCell));
    if (e.cells.empty() || e.cells.back() != c) e.cells.push_back(c);
  }
  std::sort(e.cells.begin(), e.cells.end());
  e.cells.erase(std::unique(e.cells.begin(), e.cells.end()), e.cells.end());
  return e;
}

}  // namespace touchdown::search
