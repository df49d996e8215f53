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

  Facts& f = e.facts;
  f.recorded = true;
  const scenario::Observability& o = result.observability;
  f.fair = result.status != scenario::Violation::TypeII || o.observable_long_enough();
  f.sighting_time = o.sighting_time;
  f.observable_s = o.observable_s;
  f.longest_s = o.longest_s;
  f.probe_observable_s = o.probe_observable_s;
  f.probe_longest_s = o.probe_longest_s;
  f.probe_failure = std::string(scenario::to_string(o.probe_failure));
  f.probe_contrast = o.probe_contrast;
  f.descent_started = result.descent_started;
  f.descent_time = result.descent_time;
  f.descent_target = {result.descent_target.x(), result.descent_target.y()};
  if (result.has_trigger) f.trigger = result.trigger.object, f.trigger_t = result.trigger.t;
  if (result.has_last_accepted) f.last_accepted = result.last_accepted.object;
  f.false_detection = result.false_detection;
  for (const scenario::OccluderRecord& r : result.occluders) {
    f.occluders.push_back({r.object, r.first_t, r.last_t, r.frames, r.frames_descending});
  }
  if (result.collided) f.collided_with = result.collision.what, f.collision_phase = result.collision_phase;
  if (result.has_nearest) {
    f.nearest_object = result.nearest.what;
    f.nearest_m = result.nearest.distance;
    f.nearest_t = result.nearest_t;
    f.nearest_phase = result.nearest_phase;
  }
  return e;
}

}  // namespace touchdown::search
