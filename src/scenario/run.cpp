// One closed-loop scenario run and its outcome (run.hpp), with the RLaGA
// paper's violation semantics and an automatic Type I/II/III classification.
#include "touchdown/scenario/run.hpp"

#include <algorithm>
#include <chrono>
#include <cmath>

#include "core/format.hpp"
#include "touchdown/core/error.hpp"

namespace touchdown::scenario {

namespace {

using Clock = std::chrono::steady_clock;
double seconds_since(Clock::time_point t0) { return std::chrono::duration<double>(Clock::now() - t0).count(); }

using detail::format_fixed;

}  // namespace

bool RunOptions::validate(std::string* why) const {
  std::string w;
  if (!camera.validate(&w)) return invalid(why, "camera." + w);
  if (!flight.validate(&w)) return invalid(why, "flight." + w);
  if (!(std::isfinite(violation_radius) && violation_radius > 0 && violation_radius <= 100))
    return invalid(why, "violation_radius: must be in (0, 100] m");
  if (camera.rate_hz > flight.rate_hz) return invalid(why, "camera.rate_hz: must not exceed flight.rate_hz");
  return true;
}

SystemSetup system_setup(const Scenario& scenario, const RunOptions& options) {
  SystemSetup setup;
  setup.camera = options.camera;
  setup.dictionary = scenario.marker.dictionary;
  setup.marker_id = scenario.marker.id;
  setup.marker_size = scenario.marker.size;
  setup.gps_target = scenario.gps_target();
  setup.drone_radius = options.flight.airframe.footprint_radius();
  return setup;
}

namespace {

const RunOptions& validated(const RunOptions& options) {
  std::string why;
  if (!options.validate(&why)) throw InvalidArgument("run options: " + why);
  return options;
}

/// Ground truth from the semantic mask: is the detection's centre on the
/// target marker?
bool on_marker(const Detection& d, const CameraFrame& frame) {
  const Eigen::Vector2d c = 0.25 * (d.corners[0] + d.corners[1] + d.corners[2] + d.corners[3]);
  const int u = static_cast<int>(std::lround(c.x())), v = static_cast<int>(std::lround(c.y()));
  const bool inside = u >= 0 && v >= 0 && u < frame.width && v < frame.height;
  return inside && frame.mask[static_cast<std::size_t>(v) * static_cast<std::size_t>(frame.width) +
                              static_cast<std::size_t>(u)] == mask_value(Label::Marker);
}

/// The violation classification and its one-line message.
void classify(ScenarioOutcome& r, const Eigen::Vector2d& marker, double time_limit, double radius,
              const CollisionEvent* collision) {
  if (collision) {
    r.collided = true;
    r.collision = *collision;
    r.status = Violation::TypeIII;
    r.message = "Type III: collided with " + collision->what + " at t = " + format_fixed(collision->t, 2) + " s";
  } else if (!r.landed) {
    r.status = Violation::TypeII;
    r.message = std::string("Type II: no landing within ") + format_fixed(time_limit, 0) + " s (" +
                (r.descent_started
                     ? "a descent started at t = " + format_fixed(r.descent_time, 1) + " s did not reach the ground"
                     : std::string("the marker was never seen long enough")) +
                ")";
  } else if (r.dtl > radius) {
    // Landed off target: something the system took for the marker led it
    // there (a false positive, the paper's Type I).
    r.status = Violation::TypeI;
    r.message = "Type I: landed " + format_fixed(r.dtl, 2) + " m from the marker";
    if (r.descent_started)
      r.message += "; the descent was triggered by a detection " + format_fixed((r.descent_target - marker).norm(), 2) +
                   " m from it";
    if (r.false_detection) r.message += " (false detections seen)";
  } else {
    r.status = Violation::None;
    r.message = "landed " + format_fixed(r.dtl, 2) + " m from the marker after " + format_fixed(r.ttl, 1) + " s";
  }
}

}  // namespace

ScenarioRun::ScenarioRun(const Scenario& scenario, LandingSystem& system, const RunOptions& options, double max_time)
    : scenario_(scenario),
      system_(system),
      options_(validated(options)),
      start_(Clock::now()),
      world_(scenario, options.flight),
      renderer_(scenario, options.camera),
      time_limit_(max_time > 0 ? std::min(max_time, scenario.time_limit) : scenario.time_limit) {
  system_.reset(system_setup(scenario, options));
  steps_ = static_cast<long>(std::ceil(time_limit_ / world_.dt() - 1e-9));
  frame_period_ = 1.0 / options.camera.rate_hz;
  actions_.assign(static_cast<std::size_t>(world_.external_count()), ObjectAction::Stay);
  result_.trajectory.reserve(static_cast<std::size_t>(steps_) + 1);
}

bool ScenarioRun::over() const { return k_ >= steps_ || world_.collision() || world_.drone().landed; }

bool ScenarioRun::step() {
  if (over()) return false;
  ++k_;
  ScenarioResult& r = result_;
  const DroneState& state = world_.drone();
  SystemInput& in = last_input_;
  in.state = state;
  in.frame = nullptr;
  const bool frame_due = state.t >= next_frame_ - 1e-9;
  if (frame_due) {
    auto t0 = Clock::now();
    scene_.t = state.t;
    scene_.frame_index = frame_index_++;
    scene_.T_world_body = state.T_world_body();
    scene_.v_world = state.velocity;
    scene_.T_world_dynamic = world_.dynamic_poses();
    renderer_.render(scene_, frame_);
    r.timing.render_s += seconds_since(t0);
    in.frame = &frame_;
    next_frame_ += frame_period_;
  }
  auto t1 = Clock::now();
  last_output_ = system_.update(in);
  r.timing.system_s += seconds_since(t1);
  const SystemOutput& out = last_output_;

  if (frame_due) {
    FrameRecord rec;
    rec.t = state.t;
    rec.marker_area_visible_px = frame_.marker_area_visible_px;
    rec.marker_area_truth_px = frame_.marker_area_truth_px;
    rec.detections = static_cast<int>(out.detections.size());
    for (const Detection& d : out.detections) {
      if (!d.accepted) continue;
      ++rec.accepted;
      if (!on_marker(d, frame_)) {
        ++rec.false_accepted;
        r.false_detection = true;
      }
    }
    r.frames.push_back(rec);
    if (options_.on_frame) options_.on_frame(frame_, out, state);
  }
  if (out.descent_started) {
    r.descent_started = true;
    r.descent_time = state.t;
    r.descent_target = out.target;
  }

  auto t2 = Clock::now();
  if (options_.external && !actions_.empty()) options_.external(world_, actions_);
  world_.step(out.command, actions_);
  r.timing.physics_s += seconds_since(t2);
  const DroneState& now = world_.drone();
  r.trajectory.push_back({now.t, now.position, now.velocity, now.yaw_deg, std::string(out.phase)});
  return true;
}

ScenarioResult ScenarioRun::finish() {
  ScenarioResult r = std::move(result_);
  result_ = {};
  const DroneState& last = world_.drone();
  r.final_position = last.position;
  const Eigen::Vector2d marker = scenario_.marker.position;
  r.dtl = (last.position.head<2>() - marker).norm();
  r.landed = last.landed;
  r.ttl = last.landed ? last.t : time_limit_;
  r.flight_s = r.trajectory.empty() ? 0.0 : r.trajectory.back().t;
  r.frame_count = static_cast<int>(r.frames.size());
  classify(r, marker, time_limit_, options_.violation_radius, world_.collision());
  r.timing.total_s = seconds_since(start_);
  return r;
}

ScenarioResult run_scenario(const Scenario& scenario, LandingSystem& system, const RunOptions& options) {
  ScenarioRun run(scenario, system, options);
  while (run.step()) {
  }
  return run.finish();
}

}  // namespace touchdown::scenario
