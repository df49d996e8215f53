// The landing mission's guidance (guidance.hpp).
#include "touchdown/mission/guidance.hpp"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <numbers>

#include "core/checks.hpp"
#include "touchdown/core/error.hpp"
#include "touchdown/core/units.hpp"

namespace touchdown::mission {
namespace {

using touchdown::detail::positive;

plan::PadMotion motion_of(const PadState& pad) {
  plan::PadMotion m;
  m.velocity = pad.velocity;
  m.yaw_rate = pad.yaw_rate;
  const Eigen::Matrix3d& R = pad.T_world_pad.linear();
  m.yaw = std::atan2(R(1, 0), R(0, 0));
  return m;
}

}  // namespace

plan::KinematicState pad_to_world(const PadState& pad, const plan::KinematicState& rel) {
  const Eigen::Matrix3d& R = pad.T_world_pad.linear();
  const Eigen::Vector3d w(0, 0, pad.yaw_rate), wdot(0, 0, pad.yaw_acceleration);
  plan::KinematicState out;
  out.p = pad.T_world_pad * rel.p;
  out.v = pad.velocity + R * (rel.v + w.cross(rel.p));
  out.a = pad.acceleration + R * (rel.a + 2 * w.cross(rel.v) + w.cross(w.cross(rel.p)) + wdot.cross(rel.p));
  return out;
}

plan::KinematicState world_to_pad(const PadState& pad, const plan::KinematicState& world) {
  const Eigen::Matrix3d Rt = pad.T_world_pad.linear().transpose();
  const Eigen::Vector3d w(0, 0, pad.yaw_rate), wdot(0, 0, pad.yaw_acceleration);
  plan::KinematicState rel;
  rel.p = pad.T_world_pad.inverse() * world.p;
  rel.v = Rt * (world.v - pad.velocity) - w.cross(rel.p);
  rel.a = Rt * (world.a - pad.acceleration) - 2 * w.cross(rel.v) - w.cross(w.cross(rel.p)) - wdot.cross(rel.p);
  return rel;
}

plan::PlannerOptions GuidanceOptions::default_planner() {
  plan::PlannerOptions o;
  o.order = 7;
  o.segments = 2;
  o.v_max = 3.0;
  o.a_max = 4.0;
  o.time = {0.3, 6.0, 1.0, 120};
  plan::CorridorOptions c;
  c.h_touchdown = 0.4;
  c.deflate = 0.1;
  c.dilate = 0.2;
  c.radius = 0.12;  // the 180 mm quadrotor with its propellers
  c.margin = 0.6;
  plan::CameraFov cam;
  // 0.5 m ahead of the pad centre, optical axis back and 20° up; image
  // right = pad +y.
  const double up = deg_to_rad(20.0);
  const Eigen::Vector3d z(-std::cos(up), 0, std::sin(up)), x(0, 1, 0);
  cam.T_pad_camera.linear().col(0) = x;
  cam.T_pad_camera.linear().col(1) = z.cross(x);
  cam.T_pad_camera.linear().col(2) = z;
  cam.T_pad_camera.translation() = Eigen::Vector3d(0.5, 0, 0.05);
  cam.horizontal_fov_rad = deg_to_rad(87.0);
  cam.vertical_fov_rad = deg_to_rad(58.0);
  cam.near_m = 0.2;
  cam.far_m = 6.0;
  c.camera = cam;
  o.corridor = c;
  return o;
}

bool GuidanceOptions::validate(std::string* why) const {
  std::string p;
  if (!planner.validate(&p)) return invalid(why, "guidance.planner: " + p);
  if (!planner.durations.empty()) return invalid(why, "guidance.planner: durations must be empty (allocated online)");
  if (!tracking_point.allFinite() || !(tracking_point.z() > 0)) {
    return invalid(why, "guidance.tracking_point: must be finite and above the pad (z > 0)");
  }
  if (!(replan_period > 0 && replan_period <= 1)) return invalid(why, "guidance.replan_period: must be in (0, 1] s");
  if (!positive(replan_reset_distance)) return invalid(why, "guidance.replan_reset_distance: must be positive [m]");
  if (!positive(terminal_height)) return invalid(why, "guidance.terminal_height: must be positive [m]");
  if (!positive(terminal_speed)) return invalid(why, "guidance.terminal_speed: must be positive [m/s]");
  if (!positive(terminal_centre_tolerance))
    return invalid(why, "guidance.terminal_centre_tolerance: must be positive [m]");
  if (!positive(terminal_acceleration)) return invalid(why, "guidance.terminal_acceleration: must be positive [m/s^2]");
  if (!(pad_integral_gain >= 0) || !std::isfinite(pad_integral_gain)) {
    return invalid(why, "guidance.pad_integral_gain: must be >= 0 [1/s]");
  }
  if (!positive(pad_integral_window)) return invalid(why, "guidance.pad_integral_window: must be positive [m]");
  if (!(pad_integral_limit >= 0) || !std::isfinite(pad_integral_limit)) {
    return invalid(why, "guidance.pad_integral_limit: must be >= 0 [m]");
  }
  if (!(replan_stop >= 0) || !std::isfinite(replan_stop)) return invalid(why, "guidance.replan_stop: must be >= 0 [s]");
  return true;
}

Guidance::Guidance(GuidanceOptions options, double landed_com_height)
    : options_(std::move(options)), landed_com_height_(landed_com_height) {
  std::string why;
  if (!options_.validate(&why)) throw InvalidArgument(why);
  if (!positive(landed_com_height_)) throw InvalidArgument("guidance: landed centre-of-mass height must be positive");
}

Eigen::Vector3d Guidance::terminal_point() const { return {0, 0, landed_com_height_ + options_.terminal_height}; }

GuidanceOutput Guidance::hold(const PadState& pad, const Eigen::Vector3d& point) const {
  GuidanceOutput out;
  out.reference.p = point;
  const plan::KinematicState w = pad_to_world(pad, out.reference);
  out.setpoint.position = w.p;
  out.setpoint.velocity = w.v;
  out.setpoint.acceleration = w.a;
  const Eigen::Matrix3d& R = pad.T_world_pad.linear();
  out.setpoint.yaw = std::atan2(R(1, 0), R(0, 0));  // facing the pad's forward
  return out;
}

// A new plan from `from` (pad frame) at t: within the corridor of this
// landing (built by the first plan), at the remaining durations of the
// last plan; a fresh time allocation when they fail, a new corridor when
// the start has left it.
ReplanOutcome Guidance::replan(double t, const PadState& pad, const plan::KinematicState& from, bool fresh) {
  const plan::PadMotion motion = motion_of(pad);
  plan::KinematicState goal;
  goal.p = terminal_point();
  goal.v = Eigen::Vector3d(0, 0, -options_.terminal_speed);  // hands over to the terminal rule without a step
  const auto solve = [&](const plan::PlannerOptions& o, const std::vector<plan::Polytope>& polytopes) {
    try {
      return polytopes.empty() ? plan::plan(from, goal, motion, o)
                               : plan::plan_in_corridor(from, goal, motion, o, polytopes);
    } catch (const InvalidArgument& e) {  // a start outside the corridor it builds
      plan::PlanResult r;
      r.status = plan::PlanStatus::NoCorridor;
      r.message = e.what();
      return r;
    }
  };
  const auto take = [&](const plan::PiecewiseBezier& trajectory) {
    trajectory_ = trajectory;  // same sizes: the curve's storage is reused
    have_plan_ = true;
    plan_t0_ = t;
    return ReplanOutcome::Ok;
  };
  // A new corridor plans within what the wind leaves (set_acceleration_capacity).
  plan::PlannerOptions limited = options_.planner;
  limited.a_max = std::min(limited.a_max, std::max(0.5 * limited.a_max, capacity_));
  const std::size_t segments = static_cast<std::size_t>(options_.planner.segments);
  if (!fresh && have_plan_ && polytopes_.size() == segments && replanner_) {
    // The start in the first polytope it lies in; both segments in the
    // touchdown part when the rear part is behind it.
    plan::Replanner* r = nullptr;
    if (polytopes_.front().contains(from.p, 1e-9)) {
      r = replanner_.get();
    } else if (polytopes_.back().contains(from.p, 1e-9)) {
      if (!replanner_low_) {
        replanner_low_ = std::make_unique<plan::Replanner>(replanner_->options(),
                                                           std::vector<plan::Polytope>(segments, polytopes_.back()));
      }
      r = replanner_low_.get();
    }
    if (r != nullptr) {
      // What is left of each segment, keeping the plan's end time: a
      // segment shorter than the shortest allowed borrows from the next.
      const double elapsed = t - plan_t0_;
      const double shortest = 0.5 * options_.planner.time.min;
      double end = 0, borrowed = 0;
      for (std::size_t k = 0; k < segments; ++k) {
        const double T = trajectory_.duration(static_cast<int>(k));
        end += T;
        const double left = std::clamp(end - elapsed, 0.0, T) - borrowed;
        durations_[k] = std::max(shortest, left);
        borrowed = durations_[k] - left;
      }
      if (r->plan(from, goal, motion, durations_) == plan::PlanStatus::Ok) return take(r->trajectory());
      // Those durations fail: a new time allocation in the same polytopes.
      const plan::PlanResult next = solve(r->options(), r->segment_polytopes());
      if (next.ok()) return take(next.trajectory);
    }
  }
  // A new corridor and time allocation (the landing's first plan, or the
  // start has left the corridor): its polytopes are kept for the replans.
  plan::PlanResult next = solve(limited, {});
  if (!next.ok()) {
    message_ = next.message;
    return ReplanOutcome::Failed;
  }
  polytopes_ = next.segment_polytopes;
  replanner_ = std::make_unique<plan::Replanner>(limited, polytopes_);
  replanner_low_.reset();
  // Size the replanner's work space now, with the plan just found (this
  // plan allocates anyway): the replans that follow do not.
  durations_.assign(segments, 0.0);
  for (std::size_t k = 0; k < segments; ++k) durations_[k] = next.trajectory.duration(static_cast<int>(k));
  (void)replanner_->plan(from, goal, motion, durations_);
  return take(next.trajectory);
}

GuidanceOutput Guidance::update(double t, MissionState state, bool entered, const PadState& pad,
                                const plan::KinematicState& estimate, const Eigen::Vector3d& fix,
                                const StateMachineOptions& machine) {
  GuidanceOutput out = compute(t, state, entered, pad, estimate, fix, machine);
  // The pad-frame integral: what the drone's world-frame loops cannot
  // remove in a turning frame (drag and wind against a setpoint whose error
  // turns with the pad) is taken out here, horizontally, in every flying
  // state (the drag does not change with the state; the estimate rests on
  // the fix before the tracker locks).
  const double h = std::clamp(t - last_update_, 0.0, 0.1);
  last_update_ = t;
  if (state != MissionState::Shutdown) {
    // Conditional integration (anti-windup): only near the reference, where
    // the error is the steady one, not a transient (a hold point's jump, the
    // approach).
    const Eigen::Vector2d error = (out.reference.p - estimate.p).head<2>();
    if (error.norm() < options_.pad_integral_window) offset_ += options_.pad_integral_gain * h * error;
    if (offset_.norm() > options_.pad_integral_limit) offset_ *= options_.pad_integral_limit / offset_.norm();
    // The offset moves with the pad: its point's world velocity and
    // acceleration (ω × offset, ω × (ω × offset)) are fed forward with it,
    // else a turning pad leaves the shifted point's own motion to the
    // position loop, which lags it by a rotation that made this integral
    // ring (a 10 s swing of ±0.3 m on the figure-eight at 4 m/s).
    plan::KinematicState shifted = out.reference;
    shifted.p.head<2>() += offset_;
    const plan::KinematicState w = pad_to_world(pad, shifted);
    out.setpoint.position = w.p;
    out.setpoint.velocity = w.v;
    out.setpoint.acceleration = w.a;
  } else {
    offset_.setZero();
  }
  return out;
}

GuidanceOutput Guidance::compute(double t, MissionState state, bool entered, const PadState& pad,
                                 const plan::KinematicState& estimate, const Eigen::Vector3d& fix,
                                 const StateMachineOptions& machine) {
  (void)fix;
  switch (state) {
    case MissionState::Searching:
    case MissionState::Rendezvous:
      terminal_ = false;
      return hold(pad, machine.rendezvous_point);
    case MissionState::Tracking:
      terminal_ = false;
      return hold(pad, options_.tracking_point);
    case MissionState::Shutdown: {
      GuidanceOutput out = hold(pad, estimate.p);
      out.have_plan = true;
      return out;
    }
    case MissionState::Landing:
      break;
  }
  GuidanceOutput out;
  if (entered) {
    terminal_ = false;
    have_plan_ = false;
    next_replan_ = t;
  }
  const Eigen::Vector3d top = terminal_point();
  // Below the terminal point (by the plan's end or the estimate): the
  // terminal rule, straight down over the pad centre.
  if (!terminal_ && have_plan_ && t - plan_t0_ >= trajectory_.total_duration()) {
    terminal_ = true;
    terminal_last_t_ = t;
    terminal_z_ = top.z();
    terminal_rate_ = options_.terminal_speed;
  }
  if (terminal_) {
    // Down over the pad centre while the estimate is within
    // terminal_centre_tolerance of it, else hold the height until it is;
    // the descent rate changes at no more than terminal_acceleration.
    const double h = t - terminal_last_t_;
    terminal_last_t_ = t;
    const bool centred = (estimate.p.head<2>() - touchdown_point_).norm() <= options_.terminal_centre_tolerance;
    const double target = centred ? options_.terminal_speed : 0.0;
    terminal_rate_ +=
        std::clamp(target - terminal_rate_, -options_.terminal_acceleration * h, options_.terminal_acceleration * h);
    terminal_z_ = std::max(terminal_z_ - terminal_rate_ * h, landed_com_height_ - 0.1);
    out = hold(pad, Eigen::Vector3d(touchdown_point_.x(), touchdown_point_.y(), terminal_z_));
    out.reference.v = Eigen::Vector3d(0, 0, -terminal_rate_);
    const plan::KinematicState w = pad_to_world(pad, out.reference);
    out.setpoint.position = w.p;
    out.setpoint.velocity = w.v;
    out.setpoint.acceleration = w.a;
    out.have_plan = true;
    out.terminal = true;
    return out;
  }
  // The last `replan_stop` seconds of a plan are flown as planned (a
  // replan there would only shrink the segments below what the corridor
  // and the limits allow).
  const bool closing = have_plan_ && plan_t0_ + trajectory_.total_duration() - t < options_.replan_stop;
  if (t >= next_replan_ && !closing) {
    next_replan_ = t + options_.replan_period;
    // From the plan's reference now, or the estimate when they drifted apart.
    plan::KinematicState from = estimate;
    const bool fresh = !have_plan_;
    if (have_plan_) {
      const double tau = t - plan_t0_;
      const plan::KinematicState ref{trajectory_.evaluate(tau), trajectory_.evaluate(tau, 1),
                                     trajectory_.evaluate(tau, 2)};
      if ((ref.p - estimate.p).norm() <= options_.replan_reset_distance) from = ref;
    }
    const auto t0 = std::chrono::steady_clock::now();
    out.replan = replan(t, pad, from, fresh);
    out.replan_ms = std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - t0).count();
  }
  if (!have_plan_) {
    // No plan yet: hold where the landing began (the tracking point).
    GuidanceOutput h = hold(pad, options_.tracking_point);
    h.replan = out.replan;
    h.replan_ms = out.replan_ms;
    return h;
  }
  const double tau = std::min(t - plan_t0_, trajectory_.total_duration());
  out.reference = {trajectory_.evaluate(tau), trajectory_.evaluate(tau, 1), trajectory_.evaluate(tau, 2)};
  const plan::KinematicState w = pad_to_world(pad, out.reference);
  const GuidanceOutput h = hold(pad, out.reference.p);
  out.setpoint = h.setpoint;
  out.setpoint.position = w.p;
  out.setpoint.velocity = w.v;
  out.setpoint.acceleration = w.a;
  out.have_plan = true;
  return out;
}

}  // namespace touchdown::mission
