// The reference landing system mm-mls (mm_mls.hpp).
#include "scenario/mm_mls.hpp"

#include <algorithm>
#include <cmath>
#include <numbers>

#include "touchdown/core/error.hpp"
#include "touchdown/plan/planner.hpp"

namespace touchdown::scenario::detail {

void MmMls::reset(const SystemSetup& setup) {
  OpencvMls::reset(setup);
  reader_.reset(setup.dictionary);
  map_.reset(setup.gps_target, options_);
  have_landing_ = false;
  have_plan_ = false;
  next_plan_try_ = 0;
  mm_phase_ = "descend";
}

// It follows the marker it tracks: the gate applies while the track is
// alive (the marker seen within lost_timeout).
bool MmMls::gated(const DroneState& s) const { return have_estimate_ && s.t - last_seen_ <= options_.lost_timeout; }

// The code is read while it can still matter: not for a track that has
// read exactly (it keeps its gate and stays exact).
bool MmMls::reads_exactly(const cv::Mat& gray, const MarkerDetection& m, const Detection& d, bool gated) {
  return d.accepted && m.has_corners && !(gated && track_exact_) &&
         reader_.code_errors(gray, m.corners, setup_.marker_id, m.oriented) == 0;
}

// Every depth frame goes into the obstacle grid.
void MmMls::see_depth(const CameraFrame& f, const Eigen::Isometry3d& T_world_camera) {
  map_.integrate(f, T_world_camera, K_inv_);
}

void MmMls::begin_descent(double t) {
  have_plan_ = false;
  have_landing_ = false;
  next_plan_try_ = t;
}

void MmMls::drop_descent() {
  have_plan_ = false;
  have_landing_ = false;
}

void MmMls::descend(const DroneState& s, Eigen::Vector2d* v_xy, double* v_z) {
  const Eigen::Vector3d v = planned_descent(s);
  *v_xy = v.head<2>();
  *v_z = v.z();
}

// Over its free landing point, whether or not the marker is in sight.
void MmMls::land(const Eigen::Vector2d& p, bool /*seen_recently*/, Eigen::Vector2d* v_xy) {
  *v_xy = limit((landing_ - p) * options_.centring_gain, options_.land_speed);
}

void MmMls::finish(const Eigen::Vector2d& p, double altitude, bool descended, Eigen::Vector2d* v_xy, double* v_z) {
  if (!descended && phase_ != Phase::Land) keep_clear(p, altitude, v_xy, v_z);
}

// Outside a planned descent (approach, search, track at cruise altitude):
// an obstacle within the clearance of the drone's radius that reaches
// within the clearance of its altitude stops the horizontal motion towards
// it and makes it climb.
void MmMls::keep_clear(const Eigen::Vector2d& p, double altitude, Eigen::Vector2d* v_xy, double* v_z) const {
  const double reach = setup_.drone_radius + options_.obstacle_clearance;
  if (map_.max_height_near(p, reach) <= altitude - options_.obstacle_clearance) return;
  *v_z = std::max(*v_z, options_.clearance_climb_speed);
  // Where it is heading in the next second (at most clearance_look_ahead away).
  const Eigen::Vector2d ahead = p + limit(*v_xy, options_.clearance_look_ahead);
  if (map_.max_height_near(ahead, reach) > altitude - options_.obstacle_clearance) v_xy->setZero();
}

/// The free landing point nearest the marker estimate: no mapped obstacle
/// within the drone's radius plus the margin, on rings of landing_ring_step
/// up to max_landing_offset (landing_bearings each). The current one is kept
/// while it stays free and no free point is landing_hysteresis nearer the
/// estimate. False when there is none (an object on or around the marker).
bool MmMls::choose_landing_point() {
  const double clear = setup_.drone_radius + options_.obstacle_margin;
  const auto free = [&](const Eigen::Vector2d& c) { return map_.max_height_near(c, clear) <= 0; };
  bool found = false;
  Eigen::Vector2d best = estimate_;
  double best_rho = 0;
  const int rings = static_cast<int>(std::floor(options_.max_landing_offset / options_.landing_ring_step + 1e-9));
  for (int k = 0; k <= rings && !found; ++k) {
    const double rho = options_.landing_ring_step * k;
    const int bearings = k == 0 ? 1 : options_.landing_bearings;
    for (int b = 0; b < bearings && !found; ++b) {
      const double a = 2 * std::numbers::pi * b / bearings;
      const Eigen::Vector2d c = estimate_ + rho * Eigen::Vector2d(std::cos(a), std::sin(a));
      if (free(c)) {
        found = true;
        best = c;
        best_rho = rho;
      }
    }
  }
  const double current_rho = (landing_ - estimate_).norm();
  if (have_landing_ && current_rho <= options_.max_landing_offset + 1e-9 && free(landing_) &&
      (!found || current_rho <= best_rho + options_.landing_hysteresis))
    return true;
  have_landing_ = found;
  if (found) landing_ = best;
  return found;
}

/// After the sighting gate: to above the free landing point on a planned
/// trajectory, replanned about once a second, when the landing point moves,
/// or when the map puts an obstacle on the rest of the plan; the land mode
/// over a free footprint only. Returns the velocity setpoint.
Eigen::Vector3d MmMls::planned_descent(const DroneState& s) {
  const double t = s.t;
  const Eigen::Vector2d p = s.position.head<2>();
  const double altitude = s.position.z();
  const auto climb_to_cruise = [&]() {  // never down
    return std::clamp(options_.altitude_gain * (options_.cruise_altitude - altitude), 0.0, options_.max_vertical_speed);
  };
  const Eigen::Vector2d before = landing_;
  const bool had_landing = have_landing_;
  if (!choose_landing_point()) {
    // An object on the marker (or all round it): refuse to land there.
    // Back up to the cruise altitude above the marker, keep mapping and
    // looking; should the object move away, the descent resumes.
    mm_phase_ = "no-landing-spot";
    have_plan_ = false;
    const Eigen::Vector2d v = limit((hover_point(estimate_, s) - p) * options_.centring_gain, options_.no_spot_speed);
    return {v.x(), v.y(), climb_to_cruise()};
  }
  const bool moved = !had_landing || (landing_ - before).norm() > options_.landing_move;
  const double remaining = have_plan_ ? plan_duration_ - (t - plan_t0_) : 0;
  const bool stale = remaining > options_.replan_period && t - plan_t0_ >= options_.replan_period;
  const bool blocked = have_plan_ && map_.changes() != plan_changes_ && plan_blocked(t);
  // A plan that leads elsewhere or into a mapped obstacle is dropped; a
  // stale one is kept until a new one succeeds.
  if (moved || blocked) have_plan_ = false;
  if ((!have_plan_ || stale) && t >= next_plan_try_) replan(s);
  if (!have_plan_) {
    // No plan into the landing point: do not descend into the unknown.
    // Climb while something mapped is close below, else hold.
    const double reach = setup_.drone_radius + options_.obstacle_margin + options_.map_cell;
    const bool close =
        map_.max_height_near(p, reach) > altitude - setup_.drone_radius - options_.replan_climb_clearance;
    mm_phase_ = close ? "replan-climb" : "replan-hold";
    return {0, 0, close ? std::max(options_.replan_climb_speed, climb_to_cruise()) : 0.0};
  }
  // Follow the plan: its velocity as feed-forward, position feedback.
  const double tau = std::min(t - plan_t0_, plan_duration_);
  const Eigen::Vector3d p_ref = c3_plan_ + trajectory_.evaluate(tau);
  const Eigen::Vector3d v_ref = trajectory_.evaluate(tau, 1);
  Eigen::Vector3d v = v_ref + options_.plan_feedback_gain * (p_ref - s.position);
  v.head<2>() = limit(v.head<2>(), options_.approach_speed);
  mm_phase_ = "descend";
  const bool done = t - plan_t0_ >= plan_duration_ && (p - landing_).norm() < options_.land_tolerance &&
                    altitude < options_.land_altitude + options_.land_tolerance;
  // The land mode only with nothing mapped under the footprint.
  if (done && map_.max_height_near(p, setup_.drone_radius) <= 0) phase_ = Phase::Land;
  return v;
}

/// The rest of the plan passes within the drone's radius of a mapped obstacle.
bool MmMls::plan_blocked(double t) const {
  const double step = options_.plan_check_step;
  for (double tau = std::max(0.0, t - plan_t0_); tau < plan_duration_ + 0.5 * step; tau += step) {
    const Eigen::Vector3d q = c3_plan_ + trajectory_.evaluate(std::min(tau, plan_duration_));
    if (map_.max_height_near(q.head<2>(), setup_.drone_radius) > q.z() - setup_.drone_radius) return true;
  }
  return false;
}

/// Plans from the drone's state to above the landing point (the pad frame
/// of touchdown::plan: origin on the ground at the landing point, a static
/// pad) inside a safe flight corridor around the mapped obstacles, grown by
/// the margin (the corridor adds the drone's radius).
void MmMls::replan(const DroneState& s) {
  const double t = s.t;
  next_plan_try_ = t + options_.replan_retry;  // a failed plan is tried again after replan_retry
  const Eigen::Vector3d c3(landing_.x(), landing_.y(), 0);
  plan::PlannerOptions po;
  po.order = options_.plan_order;
  po.segments = options_.plan_segments;
  // A minimum-jerk descent peaks at about 1.875× its mean speed: the
  // default factor keeps the mean near descent_speed.
  po.v_max = options_.plan_speed_factor * options_.descent_speed;
  po.a_max = options_.plan_max_acceleration;
  po.time.min = options_.plan_min_segment_time;
  po.time.max = options_.plan_max_segment_time;
  po.time.max_evaluations = options_.plan_max_evaluations;
  plan::CorridorOptions co;
  co.h_touchdown = options_.land_altitude;
  co.radius = setup_.drone_radius;
  co.margin = options_.corridor_margin;
  co.deflate = options_.corridor_deflate;
  co.dilate = options_.corridor_dilate;
  po.corridor = co;
  plan::KinematicState start;
  const double tau = t - plan_t0_;
  if (have_plan_ && tau <= plan_duration_ &&
      (c3_plan_ + trajectory_.evaluate(tau) - s.position).norm() < options_.receding_tolerance) {
    // Receding horizon: from the current plan's reference state while the
    // drone follows it, so that a replan continues the motion instead of
    // starting over from the vehicle's lagging state.
    start.p = c3_plan_ + trajectory_.evaluate(tau) - c3;
    start.v = trajectory_.evaluate(tau, 1);
    start.a = trajectory_.evaluate(tau, 2);
  } else {
    // The vehicle's velocity follows its setpoint within a fraction of a
    // second (FlightOptions::velocity_time_constant): the plan starts from
    // its position and velocity at rest acceleration, which also keeps the
    // third control point near the start for long segments.
    start.p = s.position - c3;
    const double v_start = options_.plan_start_speed_fraction * po.v_max;
    start.v = s.velocity.cwiseMax(-v_start).cwiseMin(v_start);
  }
  plan::KinematicState goal;
  goal.p = Eigen::Vector3d(0, 0, options_.land_altitude);
  // The obstacles the corridor can meet: around start and goal.
  const double reach = co.margin + co.radius + options_.obstacle_margin;
  const Eigen::Vector2d lo = s.position.head<2>().cwiseMin(landing_) - Eigen::Vector2d::Constant(reach);
  const Eigen::Vector2d hi = s.position.head<2>().cwiseMax(landing_) + Eigen::Vector2d::Constant(reach);
  plan_changes_ = map_.changes();
  const auto max_boxes = static_cast<std::size_t>(options_.max_obstacle_boxes);
  if (!map_.boxes(lo, hi, options_.obstacle_margin, max_boxes, &boxes_)) return;  // too cluttered to plan: hold
  for (plan::Box& b : boxes_) {
    b.min -= c3;
    b.max -= c3;
  }
  po.obstacles = boxes_;
  // The corridor's split between the approach part and the column above
  // the landing point: just over the highest obstacle, so that the two
  // parts overlap after a dilation step or two (from the land altitude
  // it would take one dilation step per corridor_dilate of obstacle, each
  // costing a few hundred µs of polytope work).
  double top = 0;
  for (const plan::Box& b : boxes_) top = std::max(top, b.max.z());
  po.corridor->h_touchdown =
      std::clamp(top + co.radius, options_.land_altitude, std::max(options_.land_altitude, start.p.z()));
  plan::PlanResult r;
  try {
    r = plan::plan(start, goal, plan::PadMotion{}, po);
  } catch (const Error&) {
    return;  // a state the planner refuses (e.g. outside its corridor): hold, try again
  }
  if (!r.ok()) return;
  trajectory_ = std::move(r.trajectory);
  c3_plan_ = c3;
  plan_duration_ = trajectory_.total_duration();
  plan_t0_ = t;
  have_plan_ = true;
}

}  // namespace touchdown::scenario::detail
