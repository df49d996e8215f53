// The reference landing systems under test (landing_system.hpp): their
// options, and the factory. opencv-mls is in opencv_mls.cpp, mm-mls (which
// extends it) in mm_mls.cpp, mm-mls's obstacle map in obstacle_grid.cpp.
#include "touchdown/scenario/landing_system.hpp"

#include <string>

#include "scenario/opencv_mls.hpp"
#include "touchdown/core/error.hpp"
#include "touchdown/plan/planner.hpp"
#include "touchdown/scenario/system_registry.hpp"

namespace touchdown::scenario {

namespace {

using detail::in_range;
using touchdown::detail::in_range_int;

/// Guidance of both systems (the first fields and the guidance block).
bool validate_guidance(const MlsOptions& o, std::string* why) {
  if (!in_range(o.cruise_altitude, 2, 100)) return invalid(why, "cruise_altitude: must be in [2, 100] m");
  if (!in_range(o.approach_speed, 0.1, 20)) return invalid(why, "approach_speed: must be in [0.1, 20] m/s");
  if (!in_range(o.seen_time, 0, 60)) return invalid(why, "seen_time: must be in [0, 60] s");
  if (!in_range(o.min_quality_px, 0, 10000)) return invalid(why, "min_quality_px: must be in [0, 10000] px");
  if (!in_range(o.lost_timeout, 0, 60)) return invalid(why, "lost_timeout: must be in [0, 60] s");
  if (!in_range(o.descent_speed, 0.05, 10)) return invalid(why, "descent_speed: must be in [0.05, 10] m/s");
  if (!in_range(o.land_altitude, 0, 20)) return invalid(why, "land_altitude: must be in [0, 20] m");
  if (!in_range(o.centring_gain, 0.01, 10)) return invalid(why, "centring_gain: must be in [0.01, 10] 1/s");
  if (!in_range(o.search_radius, 0, 100)) return invalid(why, "search_radius: must be in [0, 100] m");
  if (!o.detector.validate(why)) return false;
  if (!in_range(o.min_confidence, 0, 1)) return invalid(why, "min_confidence: must be in [0, 1]");
  if (!in_range(o.altitude_gain, 0.01, 10)) return invalid(why, "altitude_gain: must be in [0.01, 10] 1/s");
  if (!in_range(o.max_vertical_speed, 0.1, 10)) return invalid(why, "max_vertical_speed: must be in [0.1, 10] m/s");
  if (!in_range(o.approach_gain, 0.01, 10)) return invalid(why, "approach_gain: must be in [0.01, 10] 1/s");
  if (!in_range(o.search_start_distance, 0.01, 100))
    return invalid(why, "search_start_distance: must be in [0.01, 100] m");
  if (!in_range(o.search_growth, 0, 10)) return invalid(why, "search_growth: must be in [0, 10] m/s");
  if (!in_range(o.search_speed, 0, 20)) return invalid(why, "search_speed: must be in [0, 20] m/s");
  if (!in_range(o.search_min_radius, 0.01, 100)) return invalid(why, "search_min_radius: must be in [0.01, 100] m");
  if (!in_range(o.track_lost_time, 0, 600)) return invalid(why, "track_lost_time: must be in [0, 600] s");
  if (!in_range(o.estimate_weight, 0.01, 1)) return invalid(why, "estimate_weight: must be in [0.01, 1]");
  if (!in_range(o.land_speed, 0, 10)) return invalid(why, "land_speed: must be in [0, 10] m/s");
  return true;
}

/// mm-mls's tracking, map, clearance and landing point.
bool validate_map(const MlsOptions& o, std::string* why) {
  if (!in_range(o.obstacle_clearance, 0, 20)) return invalid(why, "obstacle_clearance: must be in [0, 20] m");
  if (!in_range(o.obstacle_height, 0.05, 5)) return invalid(why, "obstacle_height: must be in [0.05, 5] m");
  if (!in_range(o.map_cell, 0.05, 2)) return invalid(why, "map_cell: must be in [0.05, 2] m");
  if (!in_range(o.obstacle_margin, 0, 5)) return invalid(why, "obstacle_margin: must be in [0, 5] m");
  if (!in_range(o.max_landing_offset, 0, 10)) return invalid(why, "max_landing_offset: must be in [0, 10] m");
  if (!in_range(o.replan_period, 0.1, 60)) return invalid(why, "replan_period: must be in [0.1, 60] s");
  if (!in_range(o.track_gate, 0.1, 100)) return invalid(why, "track_gate: must be in [0.1, 100] m");
  if (!in_range(o.map_half_extent, 1, 100)) return invalid(why, "map_half_extent: must be in [1, 100] m");
  if (!in_range_int(o.depth_samples, 100, 100000000))
    return invalid(why, "depth_samples: must be in [100, 1e8] samples");
  // The per-frame counters are bytes.
  if (!in_range_int(o.map_ground_hits, 1, 255)) return invalid(why, "map_ground_hits: must be in [1, 255] samples");
  if (!in_range_int(o.map_clear_frames, 1, 255)) return invalid(why, "map_clear_frames: must be in [1, 255] frames");
  if (!in_range(o.map_change_height, 0, 10)) return invalid(why, "map_change_height: must be in [0, 10] m");
  if (!in_range(o.box_merge_height, 0, 100)) return invalid(why, "box_merge_height: must be in [0, 100] m");
  if (!in_range_int(o.max_obstacle_boxes, 1, 1000)) return invalid(why, "max_obstacle_boxes: must be in [1, 1000]");
  if (!in_range(o.clearance_climb_speed, 0, 10)) return invalid(why, "clearance_climb_speed: must be in [0, 10] m/s");
  if (!in_range(o.clearance_look_ahead, 0, 20)) return invalid(why, "clearance_look_ahead: must be in [0, 20] m");
  if (!in_range(o.landing_ring_step, 0.01, 10)) return invalid(why, "landing_ring_step: must be in [0.01, 10] m");
  if (!in_range_int(o.landing_bearings, 1, 360)) return invalid(why, "landing_bearings: must be in [1, 360]");
  if (!in_range(o.landing_hysteresis, 0, 10)) return invalid(why, "landing_hysteresis: must be in [0, 10] m");
  if (!in_range(o.no_spot_speed, 0, 20)) return invalid(why, "no_spot_speed: must be in [0, 20] m/s");
  return true;
}

/// mm-mls's planned descent (the planner's own bounds where it has them).
bool validate_descent_plan(const MlsOptions& o, std::string* why) {
  if (!in_range_int(o.plan_order, 5, 20)) return invalid(why, "plan_order: must be in [5, 20]");
  if (!in_range_int(o.plan_segments, 2, 16)) return invalid(why, "plan_segments: must be in [2, 16]");
  if (!in_range(o.plan_speed_factor, 0.1, 20)) return invalid(why, "plan_speed_factor: must be in [0.1, 20]");
  if (!in_range(o.plan_max_acceleration, 0.1, 50))
    return invalid(why, "plan_max_acceleration: must be in [0.1, 50] m/s²");
  if (!in_range(o.plan_min_segment_time, plan::kMinSegmentDuration, 100))
    return invalid(why, "plan_min_segment_time: must be in [0.001, 100] s");
  if (!(in_range(o.plan_max_segment_time, 0, plan::kMaxSegmentDuration) &&
        o.plan_max_segment_time > o.plan_min_segment_time))
    return invalid(why, "plan_max_segment_time: must be in (plan_min_segment_time, 1000] s");
  if (!in_range_int(o.plan_max_evaluations, 1, 100000))
    return invalid(why, "plan_max_evaluations: must be in [1, 100000]");
  if (!in_range(o.plan_start_speed_fraction, 0, 1)) return invalid(why, "plan_start_speed_fraction: must be in [0, 1]");
  if (!in_range(o.corridor_margin, 0, 50)) return invalid(why, "corridor_margin: must be in [0, 50] m");
  if (!in_range(o.corridor_deflate, 0, 10)) return invalid(why, "corridor_deflate: must be in [0, 10] m");
  if (!in_range(o.corridor_dilate, 0.01, 10)) return invalid(why, "corridor_dilate: must be in [0.01, 10] m");
  if (!in_range(o.plan_feedback_gain, 0, 10)) return invalid(why, "plan_feedback_gain: must be in [0, 10] 1/s");
  if (!in_range(o.receding_tolerance, 0, 10)) return invalid(why, "receding_tolerance: must be in [0, 10] m");
  if (!in_range(o.replan_retry, 0, 60)) return invalid(why, "replan_retry: must be in [0, 60] s");
  if (!in_range(o.landing_move, 0, 10)) return invalid(why, "landing_move: must be in [0, 10] m");
  if (!in_range(o.plan_check_step, 0.01, 10)) return invalid(why, "plan_check_step: must be in [0.01, 10] s");
  if (!in_range(o.land_tolerance, 0, 10)) return invalid(why, "land_tolerance: must be in [0, 10] m");
  if (!in_range(o.replan_climb_clearance, 0, 20)) return invalid(why, "replan_climb_clearance: must be in [0, 20] m");
  if (!in_range(o.replan_climb_speed, 0, 10)) return invalid(why, "replan_climb_speed: must be in [0, 10] m/s");
  return true;
}

}  // namespace

bool MlsOptions::validate(std::string* why) const {
  return validate_guidance(*this, why) && validate_map(*this, why) && validate_descent_plan(*this, why);
}

std::unique_ptr<LandingSystem> make_landing_system(std::string_view spec, const MlsOptions& options) {
  return SystemFactory(std::string(spec)).make(options);
}

std::vector<std::string> landing_system_names() { return system_registry().names(); }

}  // namespace touchdown::scenario
