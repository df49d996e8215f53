// The landing problem YAML (docs/formats.md, "Landing problem").
#include "touchdown/plan/problem_io.hpp"

#include <yaml-cpp/yaml.h>

#include <algorithm>
#include <cmath>
#include <initializer_list>
#include <limits>
#include <numbers>
#include <sstream>

#include "core/format.hpp"
#include "core/io_util.hpp"
#include "core/yaml_util.hpp"
#include "touchdown/core/error.hpp"
#include "touchdown/core/rotation.hpp"
#include "touchdown/core/units.hpp"

namespace touchdown::plan {
namespace {

using detail::YamlReader;

// Upper bounds that keep the QP of a problem file a size a computer solves.
constexpr int kMinOrder = 5;
constexpr int kMaxOrder = 20;
constexpr int kMaxSegments = 16;
constexpr int kMaxEvaluations = 100000;
constexpr int kMaxDilations = 100;
// |angle| of rpy_deg and pad.yaw_deg, checked in radians (see degrees()).
const double kMaxAngleRad = deg_to_rad(360.0);

using detail::format_exact;
using detail::format_general;

Eigen::Vector3d vec3(const YamlReader& r, const YAML::Node& n, const std::string& key) {
  const auto v = r.vec3(n, key);
  return {v[0], v[1], v[2]};
}

// YamlReader::only, with a readable error for a key that is not a plain
// name (yaml-cpp's own would be "bad conversion").
void only(const YamlReader& r, const YAML::Node& map, const std::string& prefix,
          std::initializer_list<const char*> keys) {
  if (map.IsMap()) {
    for (const auto& kv : map) {
      if (!kv.first.IsScalar()) {
        r.fail(kv.first, prefix.empty() ? "<document>" : prefix.substr(0, prefix.size() - 1),
               "a key must be a plain name");
      }
    }
  }
  r.only(map, prefix, keys);
}

double positive(const YamlReader& r, const YAML::Node& n, const std::string& key) {
  const double v = r.number(n, key);
  if (!(v > 0)) r.fail(n, key, "must be > 0, got " + format_general(v));
  return v;
}

double non_negative(const YamlReader& r, const YAML::Node& n, const std::string& key) {
  const double v = r.number(n, key);
  if (!(v >= 0)) r.fail(n, key, "must be >= 0, got " + format_general(v));
  return v;
}

// A segment duration [s]: kMinSegmentDuration..kMaxSegmentDuration.
double duration(const YamlReader& r, const YAML::Node& n, const std::string& key, double v) {
  if (!(v >= kMinSegmentDuration && v <= kMaxSegmentDuration)) {
    r.fail(n, key,
           "must be in [" + format_general(kMinSegmentDuration) + ", " + format_general(kMaxSegmentDuration) +
               "] s, got " + format_general(v));
  }
  return v;
}

int integer_in(const YamlReader& r, const YAML::Node& n, const std::string& key, int lo, int hi) {
  const int v = r.integer(n, key);
  if (v < lo || v > hi) {
    r.fail(n, key, "must be in " + std::to_string(lo) + ".." + std::to_string(hi) + ", got " + std::to_string(v));
  }
  return v;
}

// Degrees in the file, radians in the struct. The check is on the radians
// so that a value written back by plan_problem_to_yaml() passes it again.
double angle_deg(const YamlReader& r, const YAML::Node& n, const std::string& key, double value_deg) {
  const double rad = deg_to_rad(value_deg);
  if (!(std::abs(rad) <= kMaxAngleRad))
    r.fail(n, key, "must be within [-360, 360] deg, got " + format_general(value_deg));
  return rad;
}

KinematicState read_state(const YamlReader& r, const YAML::Node& map, const std::string& name) {
  const std::string prefix = name + ".";
  only(r, map, prefix, {"p", "v", "a"});
  KinematicState s;
  s.p = vec3(r, r.child(map, prefix, "p"), prefix + "p");
  if (const YAML::Node v = map["v"]) s.v = vec3(r, v, prefix + "v");
  if (const YAML::Node a = map["a"]) s.a = vec3(r, a, prefix + "a");
  return s;
}

PadMotion read_pad(const YamlReader& r, const YAML::Node& map, std::vector<std::string>& warnings) {
  // The turn rate was `yaw_rate` in rad/s, alone among the file's angles:
  // the old name is refused (a value in rad/s read as deg/s would be 57x off).
  if (map.IsMap()) {
    if (const YAML::Node old = map["yaw_rate"]) {
      std::string what = "renamed to pad.yaw_rate_deg (deg/s); the file's other angles are degrees too";
      double rad = 0;
      if (old.IsScalar() && detail::parse_double(detail::trim(old.Scalar()), rad) && std::isfinite(rad)) {
        what += ": " + format_general(rad) + " rad/s is yaw_rate_deg: " + format_general(rad_to_deg(rad));
      }
      r.fail(old, "pad.yaw_rate", what);
    }
  }
  only(r, map, "pad.", {"v", "yaw_rate_deg", "yaw_deg"});
  PadMotion pad;
  if (const YAML::Node v = map["v"]) pad.velocity = vec3(r, v, "pad.v");
  if (const YAML::Node w = map["yaw_rate_deg"]) pad.yaw_rate = deg_to_rad(r.number(w, "pad.yaw_rate_deg"));
  if (const YAML::Node y = map["yaw_deg"]) {
    const double deg = r.number(y, "pad.yaw_deg");
    pad.yaw = angle_deg(r, y, "pad.yaw_deg", deg);
    if (std::string w = r.radians_warning(y, "pad.yaw_deg", {deg}); !w.empty()) warnings.push_back(std::move(w));
  }
  return pad;
}

void read_time(const YamlReader& r, const YAML::Node& map, const std::string& at, TimeAllocationOptions& t) {
  const std::string k = at + "time.";
  only(r, map, k, {"min", "max", "rho", "max_evaluations"});
  if (const YAML::Node n = map["min"]) t.min = duration(r, n, k + "min", r.number(n, k + "min"));
  if (const YAML::Node n = map["max"]) t.max = duration(r, n, k + "max", r.number(n, k + "max"));
  if (!(t.min < t.max)) {
    const YAML::Node where = map["max"] ? map["max"] : map["min"];
    r.fail(where, map["max"] ? k + "max" : k + "min",
           "need time.min < time.max, got min " + format_general(t.min) + " s, max " + format_general(t.max) + " s");
  }
  if (const YAML::Node n = map["rho"]) t.rho = non_negative(r, n, k + "rho");
  if (const YAML::Node n = map["max_evaluations"]) {
    t.max_evaluations = integer_in(r, n, k + "max_evaluations", 1, kMaxEvaluations);
  }
}

CameraFov read_camera(const YamlReader& r, const YAML::Node& map, const std::string& at,
                      std::vector<std::string>& warnings) {
  const std::string prefix = at + "corridor.camera.";
  only(r, map, prefix, {"p", "rpy_deg", "fov_deg", "range"});
  CameraFov c;
  if (const YAML::Node n = map["p"]) c.T_pad_camera.translation() = vec3(r, n, prefix + "p");
  if (const YAML::Node n = map["rpy_deg"]) {
    const Eigen::Vector3d deg = vec3(r, n, prefix + "rpy_deg");
    Eigen::Vector3d rad;
    for (int i = 0; i < 3; ++i) rad(i) = angle_deg(r, n, prefix + "rpy_deg", deg(i));
    if (std::string w = r.radians_warning(n, prefix + "rpy_deg", {deg.x(), deg.y(), deg.z()}); !w.empty()) {
      warnings.push_back(std::move(w));
    }
    c.T_pad_camera.linear() = rotation_from_rpy(rad);
  }
  if (const YAML::Node n = map["fov_deg"]) {
    const auto v = r.numbers(n, prefix + "fov_deg");
    if (v.size() != 2) {
      r.fail(n, prefix + "fov_deg", "expected [horizontal, vertical], got " + std::to_string(v.size()) + " numbers");
    }
    const double pi = std::numbers::pi;
    const double h = deg_to_rad(v[0]), w = deg_to_rad(v[1]);
    if (!(h > 0 && h < pi) || !(w > 0 && w < pi)) {
      r.fail(n, prefix + "fov_deg",
             "each angle must be in (0, 180) deg, got [" + format_general(v[0]) + ", " + format_general(v[1]) + "]");
    }
    c.horizontal_fov_rad = h;
    c.vertical_fov_rad = w;
  }
  if (const YAML::Node n = map["range"]) {
    const auto v = r.numbers(n, prefix + "range");
    if (v.size() != 2) {
      r.fail(n, prefix + "range", "expected [near, far], got " + std::to_string(v.size()) + " numbers");
    }
    if (!(v[0] >= 0 && v[1] > v[0])) {
      r.fail(n, prefix + "range",
             "need 0 <= near < far, got [" + format_general(v[0]) + ", " + format_general(v[1]) + "]");
    }
    c.near_m = v[0];
    c.far_m = v[1];
  }
  return c;
}

CorridorOptions read_corridor(const YamlReader& r, const YAML::Node& map, const std::string& at,
                              std::vector<std::string>& warnings) {
  const std::string k = at + "corridor.";
  only(r, map, k, {"h_touchdown", "deflate", "dilate", "max_dilations", "radius", "margin", "camera"});
  CorridorOptions c;
  if (const YAML::Node n = map["h_touchdown"]) c.h_touchdown = positive(r, n, k + "h_touchdown");
  if (const YAML::Node n = map["deflate"]) c.deflate = non_negative(r, n, k + "deflate");
  if (const YAML::Node n = map["dilate"]) c.dilate = positive(r, n, k + "dilate");
  if (const YAML::Node n = map["max_dilations"]) {
    c.max_dilations = integer_in(r, n, k + "max_dilations", 1, kMaxDilations);
  }
  if (const YAML::Node n = map["radius"]) c.radius = non_negative(r, n, k + "radius");
  if (const YAML::Node n = map["margin"]) c.margin = non_negative(r, n, k + "margin");
  if (const YAML::Node n = map["camera"]) c.camera = read_camera(r, n, at, warnings);
  return c;
}

std::vector<Box> read_obstacles(const YamlReader& r, const YAML::Node& list, const std::string& at) {
  if (!list.IsSequence()) r.fail(list, at + "obstacles", "expected a list of {min: [x, y, z], max: [x, y, z]}");
  std::vector<Box> out;
  for (std::size_t i = 0; i < list.size(); ++i) {
    const std::string prefix = at + "obstacles[" + std::to_string(i) + "].";
    const YAML::Node o = list[i];
    only(r, o, prefix, {"min", "max"});
    Box b;
    b.min = vec3(r, r.child(o, prefix, "min"), prefix + "min");
    const YAML::Node max = r.child(o, prefix, "max");
    b.max = vec3(r, max, prefix + "max");
    for (int k = 0; k < 3; ++k) {
      if (b.max(k) < b.min(k)) {
        r.fail(max, prefix + "max",
               std::string("must be >= min on every axis, got ") + "xyz"[k] + " max " + format_general(b.max(k)) +
                   " < min " + format_general(b.min(k)));
      }
    }
    out.push_back(b);
  }
  return out;
}

// Reads the planner keys present in `root` (limits, order, segments,
// durations, time, corridor, obstacles; docs/formats.md, "Landing problem")
// into `o` (the others keep their values); `at` prefixes every key in
// messages ("" or "guidance.planner.").
void read_planner(const YamlReader& r, const YAML::Node& root, const std::string& at, bool limits_required,
                  PlannerOptions& o, std::vector<std::string>& warnings) {
  const YAML::Node limits = limits_required ? r.child(root, at, "limits") : root["limits"];
  if (limits) {
    const std::string k = at + "limits.";
    only(r, limits, k, {"v_max", "a_max"});
    if (limits_required || limits["v_max"]) o.v_max = positive(r, r.child(limits, k, "v_max"), k + "v_max");
    if (limits_required || limits["a_max"]) o.a_max = positive(r, r.child(limits, k, "a_max"), k + "a_max");
  }
  if (const YAML::Node n = root["order"]) o.order = integer_in(r, n, at + "order", kMinOrder, kMaxOrder);
  if (const YAML::Node n = root["segments"]) o.segments = integer_in(r, n, at + "segments", 1, kMaxSegments);
  if (const YAML::Node c = root["corridor"]) o.corridor = read_corridor(r, c, at, warnings);
  if (o.corridor && o.segments < 2) {
    r.fail(root["segments"] ? root["segments"] : root["corridor"], at + "segments",
           "must be >= 2 with a corridor (the rear part and the touchdown part need a segment each), got " +
               std::to_string(o.segments));
  }
  if (const YAML::Node n = root["durations"]) {
    const auto d = r.numbers(n, at + "durations");
    for (std::size_t i = 0; i < d.size(); ++i) {
      duration(r, n[i], at + "durations[" + std::to_string(i) + "]", d[i]);
    }
    if (d.size() != static_cast<std::size_t>(o.segments)) {
      r.fail(n, at + "durations",
             "expected one per segment (" + std::to_string(o.segments) + "), got " + std::to_string(d.size()));
    }
    o.durations = d;
  }
  if (const YAML::Node t = root["time"]) read_time(r, t, at, o.time);
  if (const YAML::Node obstacles = root["obstacles"]) o.obstacles = read_obstacles(r, obstacles, at);
}

void read_problem(const YamlReader& r, const YAML::Node& root, PlanProblem& p) {
  only(r, root, "",
       {"start", "goal", "pad", "limits", "order", "segments", "durations", "time", "corridor", "obstacles"});
  p.start = read_state(r, r.child(root, "", "start"), "start");
  if (const YAML::Node g = root["goal"]) p.goal = read_state(r, g, "goal");
  if (const YAML::Node pad = root["pad"]) p.pad = read_pad(r, pad, p.warnings);
  read_planner(r, root, "", true, p.options, p.warnings);
}

// The degrees that deg_to_rad() maps to exactly `rad`, when one lies within
// a few ulps of rad_to_deg(rad) (always, for radians that came from
// degrees): the file then reads back to the same bits.
double degrees(double rad) {
  const double d = rad_to_deg(rad);
  if (deg_to_rad(d) == rad) return d;
  double lo = d, hi = d;
  for (int i = 0; i < 8; ++i) {
    lo = std::nextafter(lo, -std::numeric_limits<double>::infinity());
    if (deg_to_rad(lo) == rad) return lo;
    hi = std::nextafter(hi, std::numeric_limits<double>::infinity());
    if (deg_to_rad(hi) == rad) return hi;
  }
  return d;
}

std::string vec(const Eigen::Vector3d& v) {
  return "[" + format_exact(v.x()) + ", " + format_exact(v.y()) + ", " + format_exact(v.z()) + "]";
}

std::string state(const KinematicState& s) { return "{p: " + vec(s.p) + ", v: " + vec(s.v) + ", a: " + vec(s.a) + "}"; }

}  // namespace

PlanProblem parse_plan_problem(std::string_view yaml_text, std::string_view source) {
  const YAML::Node root = detail::load_yaml(yaml_text, source);
  const YamlReader reader{source};
  PlanProblem problem;
  try {
    read_problem(reader, root, problem);
  } catch (const YAML::Exception& e) {
    throw ParseError(std::string(source) + ":" + std::to_string(e.mark.line + 1) + ": " + e.msg);
  }
  std::string why;
  if (!problem.options.validate(&why)) throw ParseError(std::string(source) + ": " + why);
  return problem;
}

void parse_planner_section(std::string_view yaml_text, std::string_view source, std::string_view section,
                           PlannerOptions& options, std::vector<std::string>& warnings) {
  const YAML::Node root = detail::load_yaml(yaml_text, source);
  const YamlReader reader{source};
  try {
    YAML::Node node = root;
    std::string at;  // "guidance.planner." once walked
    for (std::size_t begin = 0; begin <= section.size();) {
      const std::size_t end = std::min(section.find('.', begin), section.size());
      const std::string part(section.substr(begin, end - begin));
      if (part.empty()) throw InvalidArgument("parse_planner_section: bad section '" + std::string(section) + "'");
      if (!node.IsMap())
        reader.fail(node, at.empty() ? "<document>" : at.substr(0, at.size() - 1), "expected a mapping");
      const YAML::Node next = node[part];
      if (!next) return;  // no such section: the options keep their values
      node.reset(next);
      at += part + ".";
      begin = end + 1;
    }
    only(reader, node, at, {"limits", "order", "segments", "durations", "time", "corridor", "obstacles"});
    read_planner(reader, node, at, false, options, warnings);
  } catch (const YAML::Exception& e) {
    throw ParseError(std::string(source) + ":" + std::to_string(e.mark.line + 1) + ": " + e.msg);
  }
}

PlanProblem load_plan_problem(const std::string& path) {
  return parse_plan_problem(detail::read_text_file(path), path);
}

std::string plan_problem_to_yaml(const PlanProblem& p) {
  const PlannerOptions& o = p.options;
  std::ostringstream os;
  os << "start: " << state(p.start) << "\n";
  if (p.goal) os << "goal: " << state(*p.goal) << "\n";
  os << "pad: {v: " << vec(p.pad.velocity) << ", yaw_rate_deg: " << format_exact(degrees(p.pad.yaw_rate))
     << ", yaw_deg: " << format_exact(degrees(p.pad.yaw)) << "}\n";
  os << "limits: {v_max: " << format_exact(o.v_max) << ", a_max: " << format_exact(o.a_max) << "}\n";
  os << "order: " << o.order << "\nsegments: " << o.segments << "\n";
  if (!o.durations.empty()) {
    os << "durations: [";
    for (std::size_t i = 0; i < o.durations.size(); ++i) os << (i ? ", " : "") << format_exact(o.durations[i]);
    os << "]\n";
  }
  os << "time: {min: " << format_exact(o.time.min) << ", max: " << format_exact(o.time.max)
     << ", rho: " << format_exact(o.time.rho) << ", max_evaluations: " << o.time.max_evaluations << "}\n";
  if (o.corridor) {
    const CorridorOptions& c = *o.corridor;
    os << "corridor:\n  h_touchdown: " << format_exact(c.h_touchdown) << "\n  deflate: " << format_exact(c.deflate)
       << "\n  dilate: " << format_exact(c.dilate) << "\n  max_dilations: " << c.max_dilations
       << "\n  radius: " << format_exact(c.radius) << "\n  margin: " << format_exact(c.margin) << "\n";
    if (c.camera) {
      const CameraFov& cam = *c.camera;
      // Rounded to 1e-12 deg (2e-14 rad): the rotation reads back to rounding,
      // and a camera pitched by 90 deg reads 90, not 89.99999999999999.
      Eigen::Vector3d rpy = rpy_from_rotation(cam.T_pad_camera.linear());
      for (int i = 0; i < 3; ++i) rpy(i) = std::round(rad_to_deg(rpy(i)) * 1e12) / 1e12 + 0.0;
      os << "  camera:\n    p: " << vec(cam.T_pad_camera.translation()) << "\n    rpy_deg: [" << format_exact(rpy.x())
         << ", " << format_exact(rpy.y()) << ", " << format_exact(rpy.z()) << "]\n    fov_deg: ["
         << format_exact(degrees(cam.horizontal_fov_rad)) << ", " << format_exact(degrees(cam.vertical_fov_rad))
         << "]\n    range: [" << format_exact(cam.near_m) << ", " << format_exact(cam.far_m) << "]\n";
    }
  }
  if (!o.obstacles.empty()) {
    os << "obstacles:\n";
    for (const Box& b : o.obstacles) os << "  - {min: " << vec(b.min) << ", max: " << vec(b.max) << "}\n";
  }
  return os.str();
}

}  // namespace touchdown::plan
