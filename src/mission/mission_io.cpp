// The mission file (mission_io.hpp; docs/formats.md, "Landing mission").
#include "touchdown/mission/mission_io.hpp"

#include <yaml-cpp/yaml.h>

#include <cmath>
#include <functional>
#include <memory>
#include <utility>

#include "core/io_util.hpp"
#include "core/yaml_util.hpp"
#include "touchdown/core/data_path.hpp"
#include "touchdown/core/error.hpp"
#include "touchdown/core/units.hpp"
#include "touchdown/plan/problem_io.hpp"

namespace touchdown::mission {
namespace {

using touchdown::detail::format_general;
using touchdown::detail::YamlReader;

// One key of a section: how to read it.
struct Field {
  const char* key;
  std::function<void(const YamlReader&, const YAML::Node&, const std::string&)> read;
};

Field num(const char* key, double& target) {
  return {key, [&target](const YamlReader& r, const YAML::Node& n, const std::string& k) { target = r.number(n, k); }};
}
Field deg(const char* key, double& target_rad) {
  return {key, [&target_rad](const YamlReader& r, const YAML::Node& n, const std::string& k) {
            target_rad = deg_to_rad(r.number(n, k));
          }};
}
Field integer(const char* key, int& target) {
  return {key, [&target](const YamlReader& r, const YAML::Node& n, const std::string& k) { target = r.integer(n, k); }};
}
Field flag(const char* key, bool& target) {
  return {key, [&target](const YamlReader& r, const YAML::Node& n, const std::string& k) {
            const std::string t = r.text(n, k);
            if (t == "true") {
              target = true;
            } else if (t == "false") {
              target = false;
            } else {
              r.fail(n, k, "expected true or false, got '" + t + "'");
            }
          }};
}
// A name (checked by validate(), e.g. against a registry).
Field word(const char* key, std::string& target) {
  return {key, [&target](const YamlReader& r, const YAML::Node& n, const std::string& k) { target = r.text(n, k); }};
}
Field vec3(const char* key, Eigen::Vector3d& target) {
  return {key, [&target](const YamlReader& r, const YAML::Node& n, const std::string& k) {
            const auto v = r.vec3(n, k);
            target = {v[0], v[1], v[2]};
          }};
}
Field vec2(const char* key, Eigen::Vector2d& target) {
  return {key, [&target](const YamlReader& r, const YAML::Node& n, const std::string& k) {
            const auto v = r.numbers(n, k);
            if (v.size() != 2) r.fail(n, k, "expected 2 numbers, got " + std::to_string(v.size()));
            target = {v[0], v[1]};
          }};
}
template <NamedEnum E>
Field named(const char* key, E& target) {
  return {key, [&target](const YamlReader& r, const YAML::Node& n, const std::string& k) {
            try {
              target = from_string<E>(r.text(n, k));
            } catch (const InvalidArgument& e) {
              r.fail(n, k, e.what());
            }
          }};
}
// A subsection read by its own fields.
Field section(const char* key, std::function<void(const YamlReader&, const YAML::Node&, const std::string&)> read) {
  return {key, std::move(read)};
}

// Reads the fields of `map` (a mapping; every key must be one of them).
void read_fields(const YamlReader& r, const YAML::Node& map, const std::string& prefix,
                 const std::vector<Field>& fields) {
  if (!map.IsMap())
    r.fail(map, prefix.empty() ? "<document>" : prefix.substr(0, prefix.size() - 1), "expected a mapping");
  for (const auto& kv : map) {
    if (!kv.first.IsScalar()) r.fail(kv.first, prefix + "<key>", "a key must be a plain name");
    const std::string k = kv.first.Scalar();
    const auto it = std::find_if(fields.begin(), fields.end(), [&](const Field& f) { return k == f.key; });
    if (it == fields.end()) {
      std::string known;
      for (const Field& f : fields) known += (known.empty() ? "" : ", ") + std::string(f.key);
      r.fail(kv.first, prefix + k, "unknown key (expected " + known + ")");
    }
    it->read(r, kv.second, prefix + k);
  }
}

// The line of a dotted key path in the document (for the messages of
// validate(), which know the key but not the line); -1 when absent.
int line_of(const YAML::Node& root, const std::string& path) {
  YAML::Node node = root;
  std::size_t start = 0;
  while (start <= path.size()) {
    const std::size_t dot = path.find('.', start);
    const std::string part = path.substr(start, dot == std::string::npos ? std::string::npos : dot - start);
    if (!node.IsMap() || !node[part]) return -1;
    node = node[part];
    if (dot == std::string::npos) break;
    start = dot + 1;
  }
  return node.Mark().line >= 0 ? node.Mark().line + 1 : -1;
}

// The keys of the vehicle's log, read with the vehicle section.
struct LogKeys {
  std::string name;
  double max_gap = 1.0;
  double smoothing = 2.0;                                    ///< [s] vehicle.log_smoothing (VehicleLog::parse)
  YAML::Node log_node, gap_node, smoothing_node, path_node;  ///< where messages point: the key, else the section
};

void load_log(const YamlReader& r, const LogKeys& k, const std::filesystem::path& base, MissionFile& file) {
  MissionOptions& o = file.options;
  VehicleOptions& v = o.vehicle;
  // The vehicle's log, once its keys are read (log_max_gap may come after
  // log): beside the mission first, then touchdown's data directories.
  if (!(k.max_gap > 0) || !std::isfinite(k.max_gap)) {
    r.fail(k.gap_node, "vehicle.log_max_gap", "must be positive [s]");
  }
  if (!(k.smoothing >= 0) || !std::isfinite(k.smoothing) || k.smoothing > 10) {
    r.fail(k.smoothing_node, "vehicle.log_smoothing", "must be in [0, 10] s");
  }
  if (k.name.empty()) {
    if (v.path == VehiclePath::Log) r.fail(k.path_node, "vehicle.log", "path log needs a log file");
    return;
  }
  if (v.path != VehiclePath::Log) r.fail(k.log_node, "vehicle.log", "a log is only read with path: log");
  std::filesystem::path path;
  try {
    path = resolve_data_file(base, k.name, "vehicle_logs");
  } catch (const Error& e) {
    r.fail(k.log_node, "vehicle.log", e.what());
  }
  // A log's own errors name its file and line (ParseError, exit 2).
  v.log = std::make_shared<const VehicleLog>(VehicleLog::load(path, k.max_gap, k.smoothing));
  file.vehicle_log = path;
  if (v.log->duration() < o.timeout) {
    file.warnings.push_back("vehicle.log: " + path.string() + " covers " + format_general(v.log->duration()) +
                            " s, the mission's timeout " + format_general(o.timeout) +
                            " s: after it the vehicle keeps its last speed and turn rate");
  }
}

// The vehicle section's keys.
std::vector<Field> vehicle_fields(VehicleOptions& v, LogKeys& log) {
  return {named("path", v.path),
          num("speed", v.speed),
          num("radius", v.radius),
          flag("counter_clockwise", v.counter_clockwise),
          num("max_acceleration", v.max_acceleration),
          num("max_wheel_speed", v.max_wheel_speed),
          num("track_width", v.track_width),
          num("drive_time_constant", v.drive_time_constant),
          num("lookahead", v.lookahead),
          flag("start_at_speed", v.start_at_speed),
          num("random_speed_sigma", v.random_speed_sigma),
          num("random_change_time", v.random_change_time),
          vec3("pad_position", v.pad_position),
          word("log", log.name),
          num("log_max_gap", log.max_gap),
          num("log_smoothing", log.smoothing),
          named("model", v.model),
          num("wheelbase", v.wheelbase),
          deg("max_steer_deg", v.max_steer),
          deg("max_steer_rate_deg", v.max_steer_rate),
          num("road_straight", v.road_straight),
          num("lane_width", v.lane_width),
          num("lane_change_length", v.lane_change_length)};
}

// The perception section's keys (the model's, the mode, the render mode's
// camera errors).
std::vector<Field> perception_fields(MissionOptions& o) {
  PerceptionModelOptions& p = o.perception_model;
  CameraErrors& e = o.render.errors;
  return {word("mode", o.perception),
          num("rate_hz", p.rate_hz),
          num("latency", p.latency),
          num("sigma_a", p.sigma_a),
          num("sigma_b", p.sigma_b),
          num("bias_sigma", p.bias_sigma),
          num("dropout", p.dropout),
          num("dropout_b", p.dropout_b),
          num("min_range", p.min_range),
          num("max_range", p.max_range),
          num("fov_margin", p.fov_margin),
          section("camera_errors", [&e](const YamlReader& r, const YAML::Node& n, const std::string& k) {
            read_fields(
                r, n, k + ".",
                {num("focal_sigma", e.focal_sigma), num("principal_sigma_px", e.principal_sigma_px),
                 num("extrinsic_position_sigma", e.extrinsic_position_sigma),
                 num("extrinsic_angle_sigma_deg", e.extrinsic_angle_sigma_deg),
                 num("clock_offset_sigma", e.clock_offset_sigma), num("clock_jitter_sigma", e.clock_jitter_sigma),
                 num("frame_drop", e.frame_drop), num("rolling_shutter_s", e.rolling_shutter_s)});
          })};
}

void read_mission(const YamlReader& r, const YAML::Node& root, std::string_view yaml_text,
                  const std::filesystem::path& base, MissionFile& file) {
  MissionOptions& o = file.options;
  VehicleOptions& v = o.vehicle;
  LogKeys log;
  DroneOptions& d = o.drone;
  twin::ControllerParams& c = d.controller;
  StateMachineOptions& m = o.machine;
  GuidanceOptions& g = o.guidance;
  const std::vector<Field> controller = {num("xy_p", c.xy_p),
                                         num("xy_vel_p", c.xy_vel_p),
                                         num("xy_vel_i", c.xy_vel_i),
                                         num("xy_vel_d", c.xy_vel_d),
                                         num("xy_vel_int_max_acc", c.xy_vel_int_max_acc),
                                         num("xy_vel_max", c.xy_vel_max),
                                         num("z_p", c.z_p),
                                         num("z_vel_p", c.z_vel_p),
                                         num("z_vel_i", c.z_vel_i),
                                         num("z_vel_max_up", c.z_vel_max_up),
                                         num("z_vel_max_down", c.z_vel_max_down),
                                         num("tilt_max_air_deg", c.tilt_max_air_deg),
                                         num("vel_deriv_lp_hz", c.vel_deriv_lp_hz),
                                         num("roll_p", c.roll_p),
                                         num("pitch_p", c.pitch_p),
                                         num("yaw_p", c.yaw_p),
                                         num("yaw_rate_max_deg", c.yaw_rate_max_deg),
                                         num("roll_pitch_rate_max_deg", c.roll_pitch_rate_max_deg),
                                         num("rate_p_roll_pitch", c.rate_p_roll_pitch),
                                         num("rate_p_yaw", c.rate_p_yaw)};
  const std::vector<Field> top = {
      section("vehicle",
              [&](const YamlReader& rr, const YAML::Node& n, const std::string& k) {
                read_fields(rr, n, k + ".", vehicle_fields(v, log));
                log.log_node = n["log"] ? n["log"] : n;
                log.gap_node = n["log_max_gap"] ? n["log_max_gap"] : n;
                log.smoothing_node = n["log_smoothing"] ? n["log_smoothing"] : n;
                log.path_node = n["path"] ? n["path"] : n;
              }),
      section("pad",
              [&](const YamlReader& rr, const YAML::Node& n, const std::string& k) {
                read_fields(
                    rr, n, k + ".",
                    {vec2("size", o.pad.size), num("thickness", o.pad.thickness), num("hold_force", o.pad.hold_force)});
              }),
      section("drone",
              [&](const YamlReader& rr, const YAML::Node& n, const std::string& k) {
                read_fields(
                    rr, n, k + ".",
                    {{"airframe",
                      [&](const YamlReader& r2, const YAML::Node& a, const std::string& ak) {
                        // Beside the mission first, then touchdown's data
                        // directories (a bundled mission copied elsewhere).
                        std::filesystem::path path;
                        try {
                          path = resolve_data_file(base, r2.text(a, ak), "airframes");
                          d.airframe = twin::load_airframe(path);
                        } catch (const Error& e) {
                          r2.fail(a, ak, e.what());
                        }
                        file.airframe = path;
                      }},
                     num("step", d.step),
                     num("drag_linear", d.drag_linear),
                     num("drag_quadratic", d.drag_quadratic),
                     num("contact_stiffness", d.contact_stiffness),
                     num("contact_damping", d.contact_damping),
                     num("pad_friction", d.pad_friction),
                     num("ground_friction", d.ground_friction),
                     num("wind_observer_time", d.wind_observer_time),
                     flag("drag_feed_forward", d.drag_feed_forward),
                     flag("turn_feed_forward", d.turn_feed_forward),
                     num("spool_down", d.spool_down),
                     vec3("start", o.drone_start),
                     num("imu_accel_sigma", o.imu_accel_sigma),
                     section("controller", [&](const YamlReader& r2, const YAML::Node& cn, const std::string& ck) {
                       read_fields(r2, cn, ck + ".", controller);
                     })});
              }),
      section("state_machine",
              [&](const YamlReader& rr, const YAML::Node& n, const std::string& k) {
                read_fields(rr, n, k + ".",
                            {vec3("rendezvous_point", m.rendezvous_point),
                             num("rendezvous_radius", m.rendezvous_radius),
                             integer("lock_frames", m.lock_frames),
                             num("lock_max_gap", m.lock_max_gap),
                             num("rendezvous_timeout", m.rendezvous_timeout),
                             num("stable_error", m.stable_error),
                             num("stable_speed", m.stable_speed),
                             num("stable_time", m.stable_time),
                             num("pose_timeout", m.pose_timeout),
                             integer("max_plan_failures", m.max_plan_failures),
                             num("max_vehicle_acceleration", m.max_vehicle_acceleration),
                             num("max_slide_ratio", m.max_slide_ratio),
                             num("max_tracking_time", m.max_tracking_time),
                             deg("max_vehicle_yaw_rate_deg", m.max_vehicle_yaw_rate),
                             num("min_height_without_plan", m.min_height_without_plan),
                             num("shutdown_radius", m.shutdown_radius),
                             num("shutdown_height", m.shutdown_height),
                             num("contact_height", m.contact_height),
                             num("contact_speed", m.contact_speed),
                             num("contact_time", m.contact_time),
                             integer("max_landing_attempts", m.max_landing_attempts)});
              }),
      section("guidance",
              [&](const YamlReader& rr, const YAML::Node& n, const std::string& k) {
                read_fields(
                    rr, n, k + ".",
                    {vec3("tracking_point", g.tracking_point), num("replan_period", g.replan_period),
                     num("replan_stop", g.replan_stop), num("replan_reset_distance", g.replan_reset_distance),
                     num("terminal_height", g.terminal_height), num("terminal_speed", g.terminal_speed),
                     num("terminal_centre_tolerance", g.terminal_centre_tolerance),
                     num("terminal_acceleration", g.terminal_acceleration),
                     num("pad_integral_gain", g.pad_integral_gain), num("pad_integral_limit", g.pad_integral_limit),
                     num("pad_integral_window", g.pad_integral_window),
                     section("planner", [&](const YamlReader& r2, const YAML::Node&, const std::string& pk) {
                       // The landing problem's planner keys, read by their owner.
                       plan::parse_planner_section(yaml_text, r2.source, pk, g.planner, file.warnings);
                     })});
              }),
      section("perception", [&](const YamlReader& rr, const YAML::Node& n,
                                const std::string& k) { read_fields(rr, n, k + ".", perception_fields(o)); }),
      section("wind",
              [&](const YamlReader& rr, const YAML::Node& n, const std::string& k) {
                read_fields(rr, n, k + ".",
                            {vec3("mean", o.wind.mean), num("turn_rate_deg", o.wind.turn_rate_deg),
                             num("gust_sigma", o.wind.gust_sigma), num("gust_time", o.wind.gust_time),
                             named("turbulence", o.wind.turbulence), num("w20", o.wind.w20),
                             num("min_airspeed", o.wind.min_airspeed)});
              }),
      section("link",
              [&](const YamlReader& rr, const YAML::Node& n, const std::string& k) {
                read_fields(rr, n, k + ".",
                            {num("latency", o.link.latency), num("dropout", o.link.dropout),
                             num("setpoint_timeout", o.link.setpoint_timeout)});
              }),
      section("fix",
              [&](const YamlReader& rr, const YAML::Node& n, const std::string& k) {
                read_fields(rr, n, k + ".",
                            {num("rate_hz", o.fix.rate_hz), num("sigma", o.fix.sigma),
                             num("correlation_time", o.fix.correlation_time)});
              }),
      num("ground_rate_hz", o.ground_rate_hz),
      num("timeout", o.timeout)};
  read_fields(r, root, "", top);
  load_log(r, log, base, file);
}

}  // namespace

MissionFile parse_mission(std::string_view yaml_text, std::string_view source, const std::filesystem::path& base) {
  const YAML::Node root = touchdown::detail::load_yaml(yaml_text, source);
  const YamlReader reader{source};
  MissionFile file;
  try {
    if (root.IsNull()) reader.fail(root, "<document>", "empty mission file");
    read_mission(reader, root, yaml_text, base, file);
  } catch (const YAML::Exception& e) {
    throw ParseError(std::string(source) + ":" + std::to_string(e.mark.line + 1) + ": " + e.msg);
  }
  std::string why;
  if (!file.options.validate(&why)) {
    // "key: what" → "source:line: key: what" where the key is in the file.
    const std::string yaw_rate = "state_machine.max_vehicle_yaw_rate:";
    if (why.rfind(yaw_rate, 0) == 0) why = "state_machine.max_vehicle_yaw_rate_deg: must be positive [deg/s]";
    const std::string key = why.substr(0, why.find(':'));
    const int line = line_of(root, key);
    throw ParseError(std::string(source) + (line > 0 ? ":" + std::to_string(line) : "") + ": " + why);
  }
  return file;
}

MissionFile load_mission(const std::filesystem::path& path) {
  const std::string text = touchdown::detail::read_text_file(path);
  const std::filesystem::path base = path.has_parent_path() ? path.parent_path() : std::filesystem::path(".");
  return parse_mission(text, path.string(), base);
}

}  // namespace touchdown::mission
