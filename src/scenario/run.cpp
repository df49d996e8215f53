// One closed-loop scenario run and its outcome (run.hpp), with the RLaGA
// paper's violation semantics and an automatic Type I/II/III classification.
#include "touchdown/scenario/run.hpp"

#include <algorithm>
#include <chrono>
#include <cmath>

#include "core/format.hpp"
#include "touchdown/core/error.hpp"
#include "touchdown/core/statistics.hpp"
#include "touchdown/core/units.hpp"
#include "touchdown/scenario/geometry.hpp"

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
  if (!oracle.validate(&w)) return invalid(why, "oracle." + w);
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

/// " (id N)" when the system read an id.
std::string id_text(const DetectionTruth& d) { return d.id >= 0 ? " (id " + std::to_string(d.id) + ")" : ""; }

/// The violation classification and its one-line message.
void classify(ScenarioOutcome& r, const Eigen::Vector2d& marker, double time_limit, double radius,
              const CollisionEvent* collision) {
  if (collision) {
    r.collided = true;
    r.collision = *collision;
    r.status = Violation::TypeIII;
    r.message = "Type III: collided with " + collision->what + " at t = " + format_fixed(collision->t, 2) + " s" +
                (r.collision_phase.empty() ? "" : " (" + r.collision_phase + ")");
  } else if (!r.landed) {
    r.status = Violation::TypeII;
    r.message = std::string("Type II: no landing within ") + format_fixed(time_limit, 0) + " s (" +
                (r.descent_started
                     ? "a descent started at t = " + format_fixed(r.descent_time, 1) + " s did not reach the ground"
                     : std::string("the marker was never seen long enough")) +
                ")";
    const Observability& o = r.observability;
    if (o.measured && !o.observable_long_enough()) {
      r.message += "; unfair: the target was observable for " +
                   format_fixed(std::max(o.longest_s, o.probe_longest_s), 1) + " s at most (the probe: mostly " +
                   std::string(to_string(o.probe_failure)) + ")";
    }
  } else if (r.dtl > radius) {
    // Off the marker. Type I only when a false detection took the drone
    // there (the paper's definition): the descent was committed on a
    // detection that was not the target, or on an estimate that false
    // detections had pulled off it, or it was committed on the target and
    // then re-aimed by a false detection (the last one the system accepted,
    // after the descent began, with the landing nearer to it than to the
    // marker). After a true detection (or none) it is an off-marker landing.
    const DetectionTruth* why = r.has_trigger ? &r.trigger : (r.has_last_accepted ? &r.last_accepted : nullptr);
    const bool aimed_off = r.descent_started && (r.descent_target - marker).norm() > radius;
    const Eigen::Vector2d landing = r.final_position.head<2>();
    const DetectionTruth& last = r.last_accepted;
    const bool re_aimed = why && why->on_target() && !aimed_off && r.descent_started && r.has_last_accepted &&
                          !last.on_target() && last.t >= r.descent_time &&
                          (landing - last.ground).norm() < (landing - marker).norm();
    const std::string landed = "landed " + format_fixed(r.dtl, 2) + " m from the marker";
    if (why && (!why->on_target() || (aimed_off && r.false_detection))) {
      r.status = Violation::TypeI;
      r.message = "Type I: " + landed + "; the descent was committed on " +
                  (why->on_target() ? "an estimate pulled off by false detections"
                                    : "a detection of " + why->object + id_text(*why)) +
                  " at t = " + format_fixed(why->t, 1) + " s";
    } else if (re_aimed) {
      r.status = Violation::TypeI;
      r.message = "Type I: " + landed + "; the descent was committed on the marker at t = " + format_fixed(why->t, 1) +
                  " s, then re-aimed by a detection of " + last.object + id_text(last) +
                  " at t = " + format_fixed(last.t, 1) + " s";
    } else {
      r.status = Violation::OffMarker;
      r.message = "off-marker: " + landed +
                  (why ? " after a true detection at t = " + format_fixed(why->t, 1) + " s" +
                             (aimed_off ? "; the descent aimed " + format_fixed((r.descent_target - marker).norm(), 2) +
                                              " m from it"
                                        : std::string("; drifted on the way down"))
                       : std::string(" with no detection accepted (a blind landing)"));
    }
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
  try {
    system_.reset(system_setup(scenario, options));
  } catch (const std::exception& e) {
    failure_ = std::string("reset() threw: ") + e.what();
  } catch (...) {
    failure_ = "reset() threw (not a std::exception)";
  }
  steps_ = static_cast<long>(std::ceil(time_limit_ / world_.dt() - 1e-9));
  frame_period_ = 1.0 / options.camera.rate_hz;
  actions_.assign(static_cast<std::size_t>(world_.external_count()), ObjectAction::Stay);
  result_.trajectory.reserve(static_cast<std::size_t>(steps_) + 1);
  if (options_.oracle.enabled) {
    oracle_ = std::make_unique<TargetOracle>(scenario, options_.oracle);
    // The probe: a nadir camera above the marker with the run's focal
    // length (the same pixels per metre as the run's camera straight below).
    const OracleOptions& o = options_.oracle;
    probe_camera_ = options_.camera;
    probe_camera_.width = probe_camera_.height = o.probe_size_px;
    probe_camera_.hfov_deg = rad_to_deg(2 * std::atan(0.5 * o.probe_size_px / options_.camera.fx()));
    probe_camera_.tilt_deg = 0;
    probe_camera_.rate_hz = o.probe_rate_hz;
    probe_camera_.offset_body = Eigen::Vector3d::Zero();
    probe_renderer_ = std::make_unique<Renderer>(scenario, probe_camera_);
    Eigen::Isometry3d T = Eigen::Isometry3d::Identity();
    T.translation() = Eigen::Vector3d(scenario.marker.position.x(), scenario.marker.position.y(), o.probe_altitude);
    T.linear() = Eigen::AngleAxisd(deg_to_rad(scenario.marker.yaw_deg), Eigen::Vector3d::UnitZ()).toRotationMatrix();
    probe_scene_.T_world_body = T;
    result_.frames.reserve(static_cast<std::size_t>(time_limit_ * options.camera.rate_hz) + 2);
    result_.probe.reserve(static_cast<std::size_t>(time_limit_ * o.probe_rate_hz) + 2);
    build_occluders();
  }
}

bool ScenarioRun::over() const {
  return !failure_.empty() || k_ >= steps_ || world_.collision() || world_.drone().landed;
}

namespace {

/// Why an answer cannot be flown (empty: it can).
std::string unflyable(const SystemOutput& out) {
  const DroneCommand& c = out.command;
  if (!c.velocity_world.allFinite()) return "a non-finite command (velocity setpoint)";
  if (!std::isfinite(c.yaw_rate_deg)) return "a non-finite command (yaw rate)";
  if (out.descent_started && !out.target.allFinite()) return "a non-finite descent target";
  return {};
}

}  // namespace

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
  const auto when = [&] { return " at t = " + format_fixed(state.t, 2) + " s (step " + std::to_string(k_) + ")"; };
  try {
    last_output_ = system_.update(in);
  } catch (const std::exception& e) {
    failure_ = "update() threw" + when() + ": " + e.what();
  } catch (...) {
    failure_ = "update() threw" + when() + " (not a std::exception)";
  }
  r.timing.system_s += seconds_since(t1);
  if (failure_.empty()) {
    if (std::string why = unflyable(last_output_); !why.empty()) failure_ = "update() answered " + why + when();
  }
  if (!failure_.empty()) {
    last_output_ = SystemOutput{};
    return false;
  }
  const SystemOutput& out = last_output_;

  if (frame_due) record_frame(out, state);
  if (out.descent_started) {
    r.descent_started = true;
    r.descent_time = state.t;
    r.descent_target = out.target;
    r.has_trigger = r.has_last_accepted;
    r.trigger = r.last_accepted;
  }
  if (oracle_ && state.t >= next_probe_ - 1e-9) {
    probe(state.t);
    next_probe_ += 1.0 / options_.oracle.probe_rate_hz;
  }

  auto t2 = Clock::now();
  if (options_.external && !actions_.empty()) options_.external(world_, actions_);
  world_.step(out.command, actions_);
  r.timing.physics_s += seconds_since(t2);
  const DroneState& now = world_.drone();
  r.trajectory.push_back({now.t, now.position, now.velocity, now.yaw_deg, std::string(out.phase)});
  if (world_.collision() && r.collision_phase.empty()) r.collision_phase = std::string(out.phase);
  if ((frame_due && !now.on_ground) || world_.collision()) {
    const auto t3 = Clock::now();
    NearestObject near = world_.nearest_object();
    if (world_.collision()) near = {world_.collision()->object, world_.collision()->what, 0.0};
    if (near.object >= 0 && (!r.has_nearest || near.distance < r.nearest.distance)) {
      r.has_nearest = true;
      r.nearest = std::move(near);
      r.nearest_t = now.t;
      r.nearest_phase = std::string(out.phase);
    }
    r.timing.physics_s += seconds_since(t3);
  }
  return true;
}

/// The frame's record: the eq. 5 areas, what the system accepted and what
/// that really was, the oracle's view and the target's occluders.
void ScenarioRun::record_frame(const SystemOutput& out, const DroneState& state) {
  ScenarioResult& r = result_;
  FrameRecord rec;
  rec.t = state.t;
  rec.marker_area_visible_px = frame_.marker_area_visible_px;
  rec.marker_area_truth_px = frame_.marker_area_truth_px;
  rec.detections = static_cast<int>(out.detections.size());
  const Detection* largest = nullptr;
  double largest_area = -1;
  for (const Detection& d : out.detections) {
    if (!d.accepted) continue;
    ++rec.accepted;
    if (!on_marker(d, frame_)) {
      ++rec.false_accepted;
      r.false_detection = true;
    }
    // Shoelace area of the corners: the largest is the one a system follows.
    double area = 0;
    for (std::size_t i = 0; i < 4; ++i) {
      const Eigen::Vector2d& a = d.corners[i];
      const Eigen::Vector2d& b = d.corners[(i + 1) % 4];
      area += a.x() * b.y() - b.x() * a.y();
    }
    if (std::abs(area) > largest_area) largest_area = std::abs(area), largest = &d;
  }
  if (largest) {
    r.has_last_accepted = true;
    r.last_accepted = detection_truth(*largest, state.t);
  }
  if (oracle_) {
    const auto t0 = Clock::now();
    rec.view = oracle_->observe(frame_, scene_.T_world_body * options_.camera.T_body_camera(), options_.camera);
    record_occluders(rec, state.t);
    r.timing.oracle_s += seconds_since(t0);
  }
  r.frames.push_back(rec);
  if (options_.on_frame) options_.on_frame(frame_, out, state);
}

namespace {

/// "static_objects[2] (tree)".
template <class Object>
std::string object_name(const char* list, std::size_t i, const Object& o) {
  return std::string(list) + "[" + std::to_string(i) + "] (" + std::string(to_string(o.kind)) + ")";
}

/// The index of the nearest of `positions` to `p`, or -1 when empty.
int nearest(const std::vector<Eigen::Vector2d>& positions, const Eigen::Vector2d& p) {
  int best = -1;
  for (std::size_t i = 0; i < positions.size(); ++i) {
    if (best < 0 || (positions[i] - p).squaredNorm() < (positions[static_cast<std::size_t>(best)] - p).squaredNorm())
      best = static_cast<int>(i);
  }
  return best;
}

/// Bounding sphere of a solid (centre in the solid's parent frame, radius).
std::pair<Eigen::Vector3d, double> bounding_sphere(const Solid& s) {
  double r = 0;
  switch (s.shape) {
    case Solid::Shape::Box:
      r = 0.5 * s.size.norm();
      break;
    case Solid::Shape::Cylinder:
    case Solid::Shape::Cone:
      r = std::hypot(s.size.x(), 0.5 * s.size.z());
      break;
    case Solid::Shape::Sphere:
      r = s.size.x();
      break;
    case Solid::Shape::Capsule:
      r = s.size.x() + 0.5 * s.size.z();
      break;
  }
  return {s.pose.translation(), r};
}

/// Does the segment a→b pass within `radius` of `c`?
bool segment_near(const Eigen::Vector3d& a, const Eigen::Vector3d& b, const Eigen::Vector3d& c, double radius) {
  const Eigen::Vector3d ab = b - a;
  const double t = std::clamp((c - a).dot(ab) / std::max(ab.squaredNorm(), 1e-12), 0.0, 1.0);
  return (a + t * ab - c).squaredNorm() <= radius * radius;
}

}  // namespace

DetectionTruth ScenarioRun::detection_truth(const Detection& d, double t) const {
  DetectionTruth truth;
  truth.t = t;
  truth.id = d.id;
  const Eigen::Vector2d c = 0.25 * (d.corners[0] + d.corners[1] + d.corners[2] + d.corners[3]);
  if (!c.allFinite() || c.x() < -0.5 || c.y() < -0.5 || c.x() > frame_.width - 0.5 || c.y() > frame_.height - 0.5) {
    truth.label = Label::Sky;
    truth.object = "outside the image";
    return truth;
  }
  const int u = std::clamp(static_cast<int>(std::lround(c.x())), 0, frame_.width - 1);
  const int v = std::clamp(static_cast<int>(std::lround(c.y())), 0, frame_.height - 1);
  const std::size_t k =
      static_cast<std::size_t>(v) * static_cast<std::size_t>(frame_.width) + static_cast<std::size_t>(u);
  truth.label = static_cast<Label>(frame_.mask[k]);
  const Eigen::Isometry3d T_world_camera = scene_.T_world_body * options_.camera.T_body_camera();
  const double f = options_.camera.fx(), depth = frame_.depth[k];
  const Eigen::Vector3d p =
      std::isfinite(depth)
          ? Eigen::Vector3d(T_world_camera * (depth * Eigen::Vector3d((u - 0.5 * (frame_.width - 1)) / f,
                                                                      (v - 0.5 * (frame_.height - 1)) / f, 1.0)))
          : T_world_camera.translation();
  truth.ground = p.head<2>();
  std::vector<Eigen::Vector2d> at;
  switch (truth.label) {
    case Label::Marker:
      truth.object = "marker";
      break;
    case Label::Distractor:
      for (const Distractor& o : scenario_.distractors) at.push_back(o.position);
      if (const int i = nearest(at, truth.ground); i >= 0)
        truth.object =
            object_name("distractors", static_cast<std::size_t>(i), scenario_.distractors[static_cast<std::size_t>(i)]);
      break;
    case Label::StaticObject:
      for (const StaticObject& o : scenario_.static_objects) at.push_back(o.position);
      if (const int i = nearest(at, truth.ground); i >= 0)
        truth.object = object_name("static_objects", static_cast<std::size_t>(i),
                                   scenario_.static_objects[static_cast<std::size_t>(i)]);
      break;
    case Label::DynamicObject:
      for (const Eigen::Isometry3d& T : world_.dynamic_poses()) at.emplace_back(T.translation().head<2>());
      if (const int i = nearest(at, truth.ground); i >= 0)
        truth.object = object_name("dynamic_objects", static_cast<std::size_t>(i),
                                   scenario_.dynamic_objects[static_cast<std::size_t>(i)]);
      break;
    case Label::Ground:
      truth.object = "ground";
      break;
    case Label::Sky:
      truth.object = "sky";
      break;
  }
  if (truth.object.empty()) truth.object = std::string(to_string(truth.label));
  return truth;
}

/// Each object's name and the bounding spheres of its solids (static ones
/// in the world, moving ones in their own frame), once per run.
void ScenarioRun::build_occluders() {
  auto add = [&](std::string name, const std::vector<Solid>& solids) {
    occluder_names_.push_back(std::move(name));
    auto& spheres = occluder_spheres_.emplace_back();
    for (const Solid& s : solids) spheres.push_back(bounding_sphere(s));
  };
  for (std::size_t i = 0; i < scenario_.static_objects.size(); ++i)
    add(object_name("static_objects", i, scenario_.static_objects[i]), object_solids(scenario_.static_objects[i]));
  for (std::size_t i = 0; i < scenario_.dynamic_objects.size(); ++i)
    add(object_name("dynamic_objects", i, scenario_.dynamic_objects[i]), object_solids(scenario_.dynamic_objects[i]));
}

/// When the target is in view but partly hidden, the objects on a line of
/// sight from the camera to its centre or a corner (bounding spheres of
/// their solids) are its occluders in this frame.
void ScenarioRun::record_occluders(FrameRecord& rec, double t) {
  if (rec.marker_area_truth_px <= 0 || rec.marker_area_visible_px >= 0.97 * rec.marker_area_truth_px) return;
  const Eigen::Vector3d cam = (scene_.T_world_body * options_.camera.T_body_camera()).translation();
  const Marker& m = scenario_.marker;
  const double h = 0.5 * m.size, cy = std::cos(deg_to_rad(m.yaw_deg)), sy = std::sin(deg_to_rad(m.yaw_deg));
  std::array<Eigen::Vector3d, 5> targets;
  targets[0] = Eigen::Vector3d(m.position.x(), m.position.y(), 0);
  for (int i = 0; i < 4; ++i) {
    const double lx = (i & 1) ? h : -h, ly = (i & 2) ? h : -h;
    targets[static_cast<std::size_t>(i) + 1] =
        Eigen::Vector3d(m.position.x() + cy * lx - sy * ly, m.position.y() + sy * lx + cy * ly, 0);
  }
  auto hits = [&](const std::vector<std::pair<Eigen::Vector3d, double>>& spheres, const Eigen::Isometry3d* T) {
    for (const auto& [centre, radius] : spheres) {
      const Eigen::Vector3d c = T ? Eigen::Vector3d(*T * centre) : centre;
      for (const Eigen::Vector3d& p : targets) {
        if (segment_near(cam, p, c, radius)) return true;
      }
    }
    return false;
  };
  const bool descending = result_.descent_started;
  auto note = [&](const std::string& name) {
    auto it = std::find_if(result_.occluders.begin(), result_.occluders.end(),
                           [&](const OccluderRecord& o) { return o.object == name; });
    if (it == result_.occluders.end()) {
      result_.occluders.push_back({name, t, t, 0, 0});
      it = result_.occluders.end() - 1;
    }
    it->last_t = t;
    ++it->frames;
    it->frames_descending += descending ? 1 : 0;
  };
  const std::size_t statics = scenario_.static_objects.size();
  const std::vector<Eigen::Isometry3d>& poses = world_.dynamic_poses();
  for (std::size_t i = 0; i < occluder_spheres_.size(); ++i) {
    const Eigen::Isometry3d* T = i < statics ? nullptr : &poses[i - statics];
    if (hits(occluder_spheres_[i], T)) note(occluder_names_[i]);
  }
}

/// One probe frame: the world as it is now, seen from above the marker.
void ScenarioRun::probe(double t) {
  auto t0 = Clock::now();
  probe_scene_.t = t;
  probe_scene_.frame_index = probe_index_++;
  probe_scene_.T_world_dynamic = world_.dynamic_poses();
  probe_renderer_->render(probe_scene_, probe_frame_);
  const TargetView view =
      oracle_->observe(probe_frame_, probe_scene_.T_world_body * probe_camera_.T_body_camera(), probe_camera_);
  result_.probe.push_back({t, view});
  result_.timing.oracle_s += seconds_since(t0);
}

namespace {

/// The oracle's summary of a run's frames and probe.
Observability summarise(const ScenarioResult& r, const OracleOptions& o, double frame_period) {
  Observability s;
  s.measured = true;
  s.sighting_time = o.sighting_time;
  std::vector<double> t;
  std::vector<char> ok;
  for (const FrameRecord& f : r.frames) t.push_back(f.t), ok.push_back(f.view.observable() ? 1 : 0);
  s.observable_s = static_cast<double>(std::count(ok.begin(), ok.end(), 1)) * frame_period;
  s.longest_s = longest_stretch(t, ok, frame_period, o.max_gap);
  t.clear(), ok.clear();
  std::array<int, EnumNames<Sight>::names.size()> why{};
  std::vector<double> contrast;
  for (const ProbeRecord& p : r.probe) {
    t.push_back(p.t), ok.push_back(p.view.observable() ? 1 : 0);
    ++why[static_cast<std::size_t>(p.view.sight)];
    if (p.view.contrast > 0) contrast.push_back(p.view.contrast);
  }
  const double probe_period = 1.0 / o.probe_rate_hz;
  s.probe_observable_s = static_cast<double>(std::count(ok.begin(), ok.end(), 1)) * probe_period;
  s.probe_longest_s = longest_stretch(t, ok, probe_period, o.max_gap);
  int most = 0;
  for (std::size_t i = 1; i < why.size(); ++i) {
    if (why[i] > most) most = why[i], s.probe_failure = static_cast<Sight>(i);
  }
  if (!contrast.empty()) {
    s.probe_contrast = upper_median_in_place(std::span(contrast));
  }
  return s;
}

}  // namespace

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
  if (oracle_) {
    const auto t0 = Clock::now();
    r.observability = summarise(r, options_.oracle, frame_period_);
    r.timing.oracle_s += seconds_since(t0);
  }
  if (failure_.empty()) {
    classify(r, marker, time_limit_, options_.violation_radius, world_.collision());
  } else {
    r.status = Violation::SystemFailed;
    r.failure = failure_;
    r.landed = false;  // never a landing, whatever the drone did before
    r.ttl = time_limit_;
    r.message = "system failed: " + failure_;
  }
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
