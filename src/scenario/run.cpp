// One closed-loop scenario run and its outcome (run.hpp), with the RLaGA
// paper's violation semantics and an automatic Type I/II/III classification.
#include "touchdown/scenario/run.hpp"

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

ScenarioResult run_scenario(const Scenario& scenario, LandingSystem& system, const RunOptions& options) {
  std::string why;
  if (!options.validate(&why)) throw InvalidArgument("run options: " + why);
  const auto t_start = Clock::now();
  World world(scenario, options.flight);
  Renderer renderer(scenario, options.camera);

  system.reset(system_setup(scenario, options));

  ScenarioResult r;
  const double dt = world.dt();
  const auto steps = static_cast<long>(std::ceil(scenario.time_limit / dt - 1e-9));
  const double frame_period = 1.0 / options.camera.rate_hz;
  double next_frame = 0;
  int frame_index = 0;
  CameraFrame frame;
  SceneState scene;
  std::vector<ObjectAction> actions(static_cast<std::size_t>(world.external_count()), ObjectAction::Stay);
  r.trajectory.reserve(static_cast<std::size_t>(steps) + 1);
  const Eigen::Vector2d marker = scenario.marker.position;

  for (long k = 0; k < steps; ++k) {
    const DroneState& state = world.drone();
    SystemInput in;
    in.state = state;
    const bool frame_due = state.t >= next_frame - 1e-9;
    if (frame_due) {
      auto t0 = Clock::now();
      scene.t = state.t;
      scene.frame_index = frame_index++;
      scene.T_world_body = state.T_world_body();
      scene.v_world = state.velocity;
      scene.T_world_dynamic = world.dynamic_poses();
      renderer.render(scene, frame);
      r.timing.render_s += seconds_since(t0);
      in.frame = &frame;
      next_frame += frame_period;
    }
    auto t1 = Clock::now();
    SystemOutput out = system.update(in);
    r.timing.system_s += seconds_since(t1);

    if (frame_due) {
      FrameRecord rec;
      rec.t = state.t;
      rec.marker_area_visible_px = frame.marker_area_visible_px;
      rec.marker_area_truth_px = frame.marker_area_truth_px;
      rec.detections = static_cast<int>(out.detections.size());
      for (const Detection& d : out.detections) {
        if (!d.accepted) continue;
        ++rec.accepted;
        // Ground truth from the semantic mask: is the detection's centre on
        // the target marker?
        const Eigen::Vector2d c = 0.25 * (d.corners[0] + d.corners[1] + d.corners[2] + d.corners[3]);
        const int u = static_cast<int>(std::lround(c.x())), v = static_cast<int>(std::lround(c.y()));
        const bool inside = u >= 0 && v >= 0 && u < frame.width && v < frame.height;
        if (!inside || frame.mask[static_cast<std::size_t>(v) * static_cast<std::size_t>(frame.width) +
                                  static_cast<std::size_t>(u)] != mask_value(Label::Marker)) {
          ++rec.false_accepted;
          r.false_detection = true;
        }
      }
      r.frames.push_back(rec);
      if (options.on_frame) options.on_frame(frame, out, state);
    }
    if (out.descent_started) {
      r.descent_started = true;
      r.descent_time = state.t;
      r.descent_target = out.target;
    }

    auto t2 = Clock::now();
    if (options.external && !actions.empty()) options.external(world, actions);
    world.step(out.command, actions);
    r.timing.physics_s += seconds_since(t2);
    const DroneState& now = world.drone();
    r.trajectory.push_back({now.t, now.position, now.velocity, now.yaw_deg, std::string(out.phase)});
    if (world.collision() || now.landed) break;
  }

  const DroneState& last = world.drone();
  r.final_position = last.position;
  r.dtl = (last.position.head<2>() - marker).norm();
  r.landed = last.landed;
  r.ttl = last.landed ? last.t : scenario.time_limit;
  const double radius = options.violation_radius;
  if (const CollisionEvent* c = world.collision()) {
    r.collided = true;
    r.collision = *c;
    r.violation = true;
    r.type = Violation::TypeIII;
    r.message = "Type III: collided with " + c->what + " at t = " + format_fixed(c->t, 2) + " s";
  } else if (!r.landed) {
    r.violation = true;
    r.type = Violation::TypeII;
    r.message = std::string("Type II: no landing within ") + format_fixed(scenario.time_limit, 0) + " s (" +
                (r.descent_started
                     ? "a descent started at t = " + format_fixed(r.descent_time, 1) + " s did not reach the ground"
                     : std::string("the marker was never seen long enough")) +
                ")";
  } else if (r.dtl > radius) {
    // Landed off target: something the system took for the marker led it
    // there (a false positive, the paper's Type I).
    r.violation = true;
    r.type = Violation::TypeI;
    r.message = "Type I: landed " + format_fixed(r.dtl, 2) + " m from the marker";
    if (r.descent_started)
      r.message += "; the descent was triggered by a detection " + format_fixed((r.descent_target - marker).norm(), 2) +
                   " m from it";
    if (r.false_detection) r.message += " (false detections seen)";
  } else {
    r.message = "landed " + format_fixed(r.dtl, 2) + " m from the marker after " + format_fixed(r.ttl, 1) + " s";
  }
  r.timing.total_s = seconds_since(t_start);
  return r;
}

}  // namespace touchdown::scenario
