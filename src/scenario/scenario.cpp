// Landing scenarios: the bounds table, validation, the YAML/JSON files and
// random scenarios (docs/formats.md, "Landing scenarios").
#include "touchdown/scenario/scenario.hpp"

#include <yaml-cpp/yaml.h>

#include <Eigen/Geometry>
#include <algorithm>
#include <array>
#include <cmath>
#include <cstddef>
#include <cstdint>
#include <initializer_list>
#include <map>
#include <numbers>
#include <string>
#include <utility>

#include "core/io_util.hpp"
#include "core/yaml_util.hpp"
#include "pose/aruco_dictionary.hpp"
#include "touchdown/core/error.hpp"
#include "touchdown/core/random.hpp"
#include "touchdown/core/units.hpp"

namespace touchdown::scenario {
namespace {

// ---- names ----------------------------------------------------------------------------

constexpr std::array<std::string_view, 2> kMapNames{"ground", "lawn"};
constexpr std::array<std::string_view, 3> kDistractorNames{"wrong_id", "lookalike", "pattern"};
constexpr std::array<std::string_view, 4> kStaticNames{"box", "chair", "pole", "tree"};
constexpr std::array<std::string_view, 3> kDynamicNames{"person", "dog", "bird"};
constexpr std::array<std::string_view, 5> kMotionNames{"still", "line", "circle", "wander", "external"};

template <typename E, std::size_t N>
std::string_view name_of(E e, const std::array<std::string_view, N>& names) {
  const auto i = static_cast<std::size_t>(e);
  return i < N ? names[i] : std::string_view("unknown");
}

// ---- the bounds table -----------------------------------------------------------------

// 2^53: the largest integer every JSON reader (IEEE doubles) reads exactly.
constexpr std::uint64_t kMaxSeedInteger = std::uint64_t{1} << 53;
constexpr double kMaxSeed = static_cast<double>(kMaxSeedInteger);
// Half the side of the map area [m]: everything starts within ±kMapHalf.
constexpr double kMapHalf = 20.0;
// The largest dictionary (ARUCO_ORIGINAL) has 1024 codes; validate() checks
// an id against its own dictionary's size.
constexpr double kMaxMarkerId = 1023.0;
// A drone starting above a static object's footprint must clear its top by
// this much [m] (about the size of a landing drone, so it does not start in
// contact).
constexpr double kDroneClearance = 1.0;

std::vector<PropertyBound> make_bounds() {
  // Realistic values for a marker-landing test with a small multirotor:
  // sizes of real objects, walking and flying speeds, weather that a camera
  // can still see through. Per-kind rows ("static_objects[pole].size[2]")
  // narrow the envelope row of the same property ("static_objects[].size");
  // a row ending in "[i]" bounds component i only.
  return {
      {"seed", 0, kMaxSeed, "",
       "seed of the scene's place on the map, its cover pattern, particles and wandering objects (written exactly in "
       "JSON)",
       true},
      {"time_limit", 10, 300, "s", "no landing by then is a violation", false},
      {"marker.id", 0, kMaxMarkerId, "", "the target's id, below its dictionary's size", true},
      {"marker.size", 0.3, 2, "m", "black-border edge of the landing marker", false},
      {"marker.position", -kMapHalf, kMapHalf, "m", "marker centre x, y", false},
      {"marker.yaw_deg", -180, 180, "deg", "marker rotation, counter-clockwise from +x", false},
      {"distractors", 0, 4, "", "number of marker-like distractors on the ground", true},
      {"distractors[].id", 0, kMaxMarkerId, "", "wrong_id: the id drawn (in the dictionary); pattern: grid seed", true},
      {"distractors[].flipped_bits", 1, 4, "", "lookalike: cells of the target's code inverted", true},
      {"distractors[].size", 0.3, 2, "m", "black-border edge", false},
      {"distractors[].position", -kMapHalf, kMapHalf, "m", "centre x, y", false},
      {"distractors[].yaw_deg", -180, 180, "deg", "rotation, counter-clockwise from +x", false},
      {"static_objects", 0, 12, "", "number of static objects", true},
      {"static_objects[].position", -kMapHalf, kMapHalf, "m", "footprint centre x, y", false},
      {"static_objects[].yaw_deg", -180, 180, "deg", "rotation, counter-clockwise from +x", false},
      {"static_objects[].size", 0.05, 12, "m", "envelope of every kind (rows below)", false},
      {"static_objects[box].size", 0.2, 3, "m", "box extents x, y, z", false},
      {"static_objects[chair].size[0]", 0.35, 0.8, "m", "chair seat width", false},
      {"static_objects[chair].size[1]", 0.35, 0.8, "m", "chair seat depth", false},
      {"static_objects[chair].size[2]", 0.6, 1.2, "m", "chair back height", false},
      {"static_objects[pole].size[0]", 0.05, 0.5, "m", "pole diameter", false},
      {"static_objects[pole].size[1]", 0.05, 0.5, "m", "pole diameter (equal to size[0])", false},
      {"static_objects[pole].size[2]", 1, 8, "m", "pole height", false},
      {"static_objects[tree].size[0]", 1, 8, "m", "tree crown diameter", false},
      {"static_objects[tree].size[1]", 0.1, 1, "m", "tree trunk diameter (below the crown's)", false},
      {"static_objects[tree].size[2]", 2, 12, "m", "tree height", false},
      {"dynamic_objects", 0, 6, "", "number of moving objects", true},
      {"dynamic_objects[].position", -kMapHalf, kMapHalf, "m", "start x, y", false},
      {"dynamic_objects[].heading_deg", -180, 180, "deg", "start heading, counter-clockwise from +x", false},
      {"dynamic_objects[].extent", 0.5, 15, "m", "line length, circle radius or wander radius", false},
      {"dynamic_objects[].size", 0.05, 2, "m", "envelope of every kind (rows below)", false},
      {"dynamic_objects[].speed", 0, 12, "m/s", "envelope of every kind (rows below)", false},
      {"dynamic_objects[].altitude", 0, 20, "m", "envelope of every kind (rows below)", false},
      {"dynamic_objects[person].size[0]", 0.2, 0.6, "m", "person depth (front to back)", false},
      {"dynamic_objects[person].size[1]", 0.3, 0.7, "m", "person shoulder width", false},
      {"dynamic_objects[person].size[2]", 1.5, 2, "m", "person height", false},
      {"dynamic_objects[person].speed", 0, 2.5, "m/s", "person walking to jogging speed", false},
      {"dynamic_objects[person].altitude", 0, 0, "m", "a person walks on the ground", false},
      {"dynamic_objects[dog].size[0]", 0.4, 1.2, "m", "dog length", false},
      {"dynamic_objects[dog].size[1]", 0.15, 0.4, "m", "dog width", false},
      {"dynamic_objects[dog].size[2]", 0.3, 0.9, "m", "dog height", false},
      {"dynamic_objects[dog].speed", 0, 4, "m/s", "dog walking to trotting speed", false},
      {"dynamic_objects[dog].altitude", 0, 0, "m", "a dog walks on the ground", false},
      {"dynamic_objects[bird].size[0]", 0.1, 0.6, "m", "bird length", false},
      {"dynamic_objects[bird].size[1]", 0.15, 1.5, "m", "bird wingspan", false},
      {"dynamic_objects[bird].size[2]", 0.05, 0.4, "m", "bird height", false},
      {"dynamic_objects[bird].speed", 0, 12, "m/s", "bird flying speed", false},
      {"dynamic_objects[bird].altitude", 2, 20, "m", "bird flight height above the ground", false},
      {"weather.fog", 0, 0.4, "1/m", "extinction coefficient; visibility 3.912/fog >= 9.8 m", false},
      {"weather.rain", 0, 1, "", "rain intensity (streaks, drops on the lens)", false},
      {"weather.snow", 0, 1, "", "snowfall intensity", false},
      {"weather.dust", 0, 1, "", "dust haze intensity", false},
      {"weather.leaves", 0, 1, "", "falling leaves intensity", false},
      {"weather.ground_wetness", 0, 1, "", "wet ground: darker, with sun glare", false},
      {"weather.ground_snow", 0, 1, "", "snow cover of the ground and the marker", false},
      {"weather.ground_leaves", 0, 1, "", "leaf cover of the ground and the marker", false},
      {"weather.sun_elevation_deg", 5, 90, "deg", "sun above the horizon", false},
      {"weather.sun_azimuth_deg", 0, 360, "deg", "sun direction, counter-clockwise from +x", false},
      {"weather.ambient", 0.15, 1, "", "light level: 1 overcast day, 0.15 dusk (sensor noise)", false},
      {"drone.position[0]", -kMapHalf, kMapHalf, "m", "drone start x", false},
      {"drone.position[1]", -kMapHalf, kMapHalf, "m", "drone start y", false},
      {"drone.position[2]", 4, 30, "m", "drone start height above the ground", false},
      {"drone.yaw_deg", -180, 180, "deg", "drone start heading, counter-clockwise from +x", false},
      {"drone.gps_error", -5, 5, "m", "error x, y of the approximate target the system is given", false},
  };
}

const PropertyBound* find_bound(std::string_view key) {
  const auto& rows = property_bounds();
  const auto it = std::find_if(rows.begin(), rows.end(), [&](const PropertyBound& b) { return b.key == key; });
  return it == rows.end() ? nullptr : &*it;
}

// ---- text helpers ---------------------------------------------------------------------

std::string num(double v) { return detail::format_exact(v); }

std::string numbers_text(const double* v, int n) {
  std::string s = "[";
  for (int i = 0; i < n; ++i) s += (i ? ", " : "") + num(v[i]);
  return s + "]";
}

std::string indexed(std::string_view list, std::size_t i, std::string_view prop) {
  return std::string(list) + "[" + std::to_string(i) + "]." + std::string(prop);
}

// ---- geometry of the consistency checks -----------------------------------------------

// A rotated rectangle on the ground.
struct Footprint {
  Eigen::Vector2d centre;
  double yaw_rad = 0;
  Eigen::Vector2d half;  // half extents along its own x, y
  bool round = false;    // a disc of radius half.x() (poles, tree crowns)

  [[nodiscard]] bool contains(const Eigen::Vector2d& p) const {
    const Eigen::Vector2d d = Eigen::Rotation2Dd(-yaw_rad) * (p - centre);
    if (round) return d.norm() <= half.x();
    return std::abs(d.x()) <= half.x() && std::abs(d.y()) <= half.y();
  }
};

// Separating-axis test of two rotated rectangles (touching counts as overlap).
bool overlap(const Footprint& a, const Footprint& b) {
  const Eigen::Matrix2d ra = Eigen::Rotation2Dd(a.yaw_rad).toRotationMatrix();
  const Eigen::Matrix2d rb = Eigen::Rotation2Dd(b.yaw_rad).toRotationMatrix();
  const Eigen::Vector2d d = b.centre - a.centre;
  for (const Eigen::Vector2d axis : {ra.col(0), ra.col(1), rb.col(0), rb.col(1)}) {
    const double extent_a = a.half.x() * std::abs(axis.dot(ra.col(0))) + a.half.y() * std::abs(axis.dot(ra.col(1)));
    const double extent_b = b.half.x() * std::abs(axis.dot(rb.col(0))) + b.half.y() * std::abs(axis.dot(rb.col(1)));
    if (std::abs(axis.dot(d)) > extent_a + extent_b) return false;
  }
  return true;
}

// A marker-like square with its white margin of one cell: the black-border
// edge `size` spans bits + 2 cells, the margin adds one cell on each side.
Footprint marker_square(const Eigen::Vector2d& centre, double yaw_deg, double size, int bits) {
  const double edge = size * (bits + 4) / (bits + 2);
  return {centre, deg_to_rad(yaw_deg), Eigen::Vector2d::Constant(edge / 2), false};
}

Footprint static_footprint(const StaticObject& o) {
  const bool round = o.kind == StaticKind::pole || o.kind == StaticKind::tree;
  return {o.position, deg_to_rad(o.yaw_deg), Eigen::Vector2d(o.size.x() / 2, o.size.y() / 2), round};
}

// ---- validation -----------------------------------------------------------------------

// Keeps the first problem found; later checks are skipped once one failed.
struct Checker {
  std::string error;

  [[nodiscard]] bool failed() const { return !error.empty(); }
  void fail(std::string message) {
    if (!failed()) error = std::move(message);
  }

  // Checks v[0..n) against row `row_key` (every component) and against the
  // rows `row_key[j]` (component j), those that exist. `name` is the key in
  // the message; per-kind rows add their meaning to it.
  void values(const std::string& name, const std::string& row_key, const double* v, int n) {
    if (failed()) return;
    const bool per_kind = row_key.find("[]") == std::string::npos && row_key.find('[') != std::string::npos;
    if (const PropertyBound* b = find_bound(row_key)) {
      for (int j = 0; j < n; ++j) {
        if (!within(*b, v[j])) {
          fail(name + ": " + (n > 1 ? "each component " : "") + bounds_text(*b, per_kind) + ", got " +
               (n > 1 ? numbers_text(v, n) : num(v[0])));
          return;
        }
      }
    }
    for (int j = 0; j < n && n > 1; ++j) {
      const PropertyBound* b = find_bound(row_key + "[" + std::to_string(j) + "]");
      if (b && !within(*b, v[j])) {
        fail(name + "[" + std::to_string(j) + "]: " + bounds_text(*b, per_kind) + ", got " + num(v[j]));
        return;
      }
    }
  }
  void value(const std::string& name, const std::string& row_key, double v) { values(name, row_key, &v, 1); }
  void vec2(const std::string& name, const std::string& row_key, const Eigen::Vector2d& v) {
    values(name, row_key, v.data(), 2);
  }
  void vec3(const std::string& name, const std::string& row_key, const Eigen::Vector3d& v) {
    values(name, row_key, v.data(), 3);
  }
  // A list element's property: the envelope row "list[].prop", then the
  // element kind's rows "list[kind].prop" and "list[kind].prop[j]".
  void element(std::string_view list, std::size_t i, std::string_view kind, std::string_view prop, const double* v,
               int n) {
    const std::string name = indexed(list, i, prop);
    values(name, std::string(list) + "[]." + std::string(prop), v, n);
    if (!kind.empty()) values(name, std::string(list) + "[" + std::string(kind) + "]." + std::string(prop), v, n);
  }
  void count(std::string_view list, std::size_t n) {
    if (failed()) return;
    const PropertyBound& b = *find_bound(list);
    if (static_cast<double>(n) > b.max) {
      fail(std::string(list) + ": at most " + num(b.max) + " allowed, got " + std::to_string(n));
    }
  }

  static bool within(const PropertyBound& b, double v) {
    return v >= b.min && v <= b.max && (!b.integer || v == std::floor(v));
  }
  static std::string bounds_text(const PropertyBound& b, bool with_meaning) {
    std::string s = "must be " + std::string(b.integer ? "an integer " : "") + "in [" + num(b.min) + ", " + num(b.max) +
                    "]" + (b.unit.empty() ? "" : " " + std::string(b.unit));
    if (with_meaning) s += " (" + std::string(b.meaning) + ")";
    return s;
  }
};

void check_marker_like(Checker& c, const Scenario& s, const pose::detail::ArucoDictionaryInfo& dict) {
  if (c.failed()) return;
  if (s.marker.id >= dict.codes) {
    c.fail("marker.id: " + std::string(dict.name) + " has ids 0.." + std::to_string(dict.codes - 1) + ", got " +
           std::to_string(s.marker.id));
    return;
  }
  const Footprint target = marker_square(s.marker.position, s.marker.yaw_deg, s.marker.size, dict.bits);
  for (std::size_t i = 0; i < s.distractors.size(); ++i) {
    const Distractor& d = s.distractors[i];
    if (d.kind == DistractorKind::wrong_id) {
      if (d.id == s.marker.id) {
        c.fail(indexed("distractors", i, "id") + ": a wrong_id distractor must differ from marker.id (" +
               std::to_string(s.marker.id) + ")");
        return;
      }
      if (d.id >= dict.codes) {
        c.fail(indexed("distractors", i, "id") + ": " + std::string(dict.name) + " has ids 0.." +
               std::to_string(dict.codes - 1) + ", got " + std::to_string(d.id));
        return;
      }
    }
    if (d.kind == DistractorKind::lookalike && d.flipped_bits > dict.bits * dict.bits) {
      c.fail(indexed("distractors", i, "flipped_bits") + ": " + std::string(dict.name) + " codes have only " +
             std::to_string(dict.bits * dict.bits) + " cells, got " + std::to_string(d.flipped_bits));
      return;
    }
    // Two markers drawn over each other would make the picture depend on
    // the drawing order; occluding the marker is the static objects' job.
    const Footprint square = marker_square(d.position, d.yaw_deg, d.size, dict.bits);
    if (overlap(square, target)) {
      c.fail(indexed("distractors", i, "position") + ": overlaps the marker (with its white margin)");
      return;
    }
    for (std::size_t j = 0; j < i; ++j) {
      const Distractor& e = s.distractors[j];
      if (overlap(square, marker_square(e.position, e.yaw_deg, e.size, dict.bits))) {
        c.fail(indexed("distractors", i, "position") + ": overlaps distractors[" + std::to_string(j) + "]");
        return;
      }
    }
  }
}

}  // namespace

// ---- public: table, names -------------------------------------------------------------

const std::vector<PropertyBound>& property_bounds() {
  static const std::vector<PropertyBound> rows = make_bounds();
  return rows;
}

const PropertyBound& property_bound(std::string_view key) {
  if (const PropertyBound* b = find_bound(key)) return *b;
  throw InvalidArgument("property_bound: unknown key '" + std::string(key) + "'");
}

std::string_view to_string(MapKind k) { return name_of(k, kMapNames); }
std::string_view to_string(DistractorKind k) { return name_of(k, kDistractorNames); }
std::string_view to_string(StaticKind k) { return name_of(k, kStaticNames); }
std::string_view to_string(DynamicKind k) { return name_of(k, kDynamicNames); }
std::string_view to_string(MotionKind k) { return name_of(k, kMotionNames); }

// ---- public: validate -----------------------------------------------------------------

bool Scenario::validate(std::string* why) const {
  Checker c;
  if (static_cast<std::size_t>(map) >= kMapNames.size()) c.fail("map: unknown map kind");
  // Compared as integers: 2^53 + 1 would round to 2^53 as a double.
  if (seed > kMaxSeedInteger) {
    c.fail("seed: must be an integer in [0, " + num(kMaxSeed) + "], got " + std::to_string(seed));
  }
  c.value("time_limit", "time_limit", time_limit);

  const auto* dict = pose::detail::find_aruco_dictionary(marker.dictionary);
  if (!c.failed() && !dict)
    c.fail("marker.dictionary: unknown " + pose::detail::unknown_aruco_dictionary(marker.dictionary));
  c.value("marker.id", "marker.id", marker.id);
  c.value("marker.size", "marker.size", marker.size);
  c.vec2("marker.position", "marker.position", marker.position);
  c.value("marker.yaw_deg", "marker.yaw_deg", marker.yaw_deg);

  c.count("distractors", distractors.size());
  for (std::size_t i = 0; i < distractors.size(); ++i) {
    const Distractor& d = distractors[i];
    if (!c.failed() && static_cast<std::size_t>(d.kind) >= kDistractorNames.size()) {
      c.fail(indexed("distractors", i, "kind") + ": unknown distractor kind");
    }
    const double id = d.id, bits = d.flipped_bits;
    c.element("distractors", i, {}, "id", &id, 1);
    c.element("distractors", i, {}, "flipped_bits", &bits, 1);
    c.element("distractors", i, {}, "size", &d.size, 1);
    c.element("distractors", i, {}, "position", d.position.data(), 2);
    c.element("distractors", i, {}, "yaw_deg", &d.yaw_deg, 1);
  }

  c.count("static_objects", static_objects.size());
  for (std::size_t i = 0; i < static_objects.size(); ++i) {
    const StaticObject& o = static_objects[i];
    if (!c.failed() && static_cast<std::size_t>(o.kind) >= kStaticNames.size()) {
      c.fail(indexed("static_objects", i, "kind") + ": unknown static object kind");
    }
    const std::string_view kind = to_string(o.kind);
    c.element("static_objects", i, kind, "position", o.position.data(), 2);
    c.element("static_objects", i, kind, "yaw_deg", &o.yaw_deg, 1);
    c.element("static_objects", i, kind, "size", o.size.data(), 3);
    if (!c.failed() && o.kind == StaticKind::pole && o.size.y() != o.size.x()) {
      c.fail(indexed("static_objects", i, "size") + ": a pole is round: size[1] must equal size[0], got " +
             numbers_text(o.size.data(), 3));
    }
    if (!c.failed() && o.kind == StaticKind::tree && !(o.size.y() < o.size.x())) {
      c.fail(indexed("static_objects", i, "size") + ": a tree's trunk (size[1]) must be thinner than its crown " +
             "(size[0]), got " + numbers_text(o.size.data(), 3));
    }
  }

  c.count("dynamic_objects", dynamic_objects.size());
  for (std::size_t i = 0; i < dynamic_objects.size(); ++i) {
    const DynamicObject& o = dynamic_objects[i];
    if (!c.failed() && static_cast<std::size_t>(o.kind) >= kDynamicNames.size()) {
      c.fail(indexed("dynamic_objects", i, "kind") + ": unknown dynamic object kind");
    }
    if (!c.failed() && static_cast<std::size_t>(o.motion) >= kMotionNames.size()) {
      c.fail(indexed("dynamic_objects", i, "motion") + ": unknown motion kind");
    }
    const std::string_view kind = to_string(o.kind);
    c.element("dynamic_objects", i, kind, "size", o.size.data(), 3);
    c.element("dynamic_objects", i, kind, "position", o.position.data(), 2);
    c.element("dynamic_objects", i, kind, "altitude", &o.altitude, 1);
    c.element("dynamic_objects", i, kind, "heading_deg", &o.heading_deg, 1);
    c.element("dynamic_objects", i, kind, "speed", &o.speed, 1);
    c.element("dynamic_objects", i, kind, "extent", &o.extent, 1);
  }

  c.value("weather.fog", "weather.fog", weather.fog);
  c.value("weather.rain", "weather.rain", weather.rain);
  c.value("weather.snow", "weather.snow", weather.snow);
  c.value("weather.dust", "weather.dust", weather.dust);
  c.value("weather.leaves", "weather.leaves", weather.leaves);
  c.value("weather.ground_wetness", "weather.ground_wetness", weather.ground_wetness);
  c.value("weather.ground_snow", "weather.ground_snow", weather.ground_snow);
  c.value("weather.ground_leaves", "weather.ground_leaves", weather.ground_leaves);
  c.value("weather.sun_elevation_deg", "weather.sun_elevation_deg", weather.sun_elevation_deg);
  c.value("weather.sun_azimuth_deg", "weather.sun_azimuth_deg", weather.sun_azimuth_deg);
  c.value("weather.ambient", "weather.ambient", weather.ambient);

  c.vec3("drone.position", "drone.position", drone.position);
  c.value("drone.yaw_deg", "drone.yaw_deg", drone.yaw_deg);
  c.vec2("drone.gps_error", "drone.gps_error", drone.gps_error);

  // Consistency: cheap checks of things no landing system could be blamed for.
  if (!c.failed() && dict) check_marker_like(c, *this, *dict);
  for (std::size_t i = 0; i < static_objects.size() && !c.failed(); ++i) {
    const StaticObject& o = static_objects[i];
    if (static_footprint(o).contains(drone.position.head<2>()) && drone.position.z() < o.size.z() + kDroneClearance) {
      c.fail("drone.position: starts inside static_objects[" + std::to_string(i) + "] (a " +
             std::string(to_string(o.kind)) + " " + num(o.size.z()) + " m tall): start at least " +
             num(kDroneClearance) + " m above its top or outside its footprint");
    }
  }
  if (c.failed()) return invalid(why, c.error);
  return true;
}

// ---- public: equality -----------------------------------------------------------------

bool operator==(const Scenario& a, const Scenario& b) {
  const auto same_marker = [](const Marker& x, const Marker& y) {
    return x.dictionary == y.dictionary && x.id == y.id && x.size == y.size && x.position == y.position &&
           x.yaw_deg == y.yaw_deg;
  };
  const auto same_distractor = [](const Distractor& x, const Distractor& y) {
    return x.kind == y.kind && x.id == y.id && x.flipped_bits == y.flipped_bits && x.size == y.size &&
           x.position == y.position && x.yaw_deg == y.yaw_deg;
  };
  const auto same_static = [](const StaticObject& x, const StaticObject& y) {
    return x.kind == y.kind && x.position == y.position && x.yaw_deg == y.yaw_deg && x.size == y.size;
  };
  const auto same_dynamic = [](const DynamicObject& x, const DynamicObject& y) {
    return x.kind == y.kind && x.size == y.size && x.position == y.position && x.altitude == y.altitude &&
           x.heading_deg == y.heading_deg && x.speed == y.speed && x.motion == y.motion && x.extent == y.extent;
  };
  const auto same_weather = [](const Weather& x, const Weather& y) {
    return x.fog == y.fog && x.rain == y.rain && x.snow == y.snow && x.dust == y.dust && x.leaves == y.leaves &&
           x.ground_wetness == y.ground_wetness && x.ground_snow == y.ground_snow &&
           x.ground_leaves == y.ground_leaves && x.sun_elevation_deg == y.sun_elevation_deg &&
           x.sun_azimuth_deg == y.sun_azimuth_deg && x.ambient == y.ambient;
  };
  const auto same_drone = [](const DroneStart& x, const DroneStart& y) {
    return x.position == y.position && x.yaw_deg == y.yaw_deg && x.gps_error == y.gps_error;
  };
  return a.map == b.map && a.seed == b.seed && a.time_limit == b.time_limit && same_marker(a.marker, b.marker) &&
         std::equal(a.distractors.begin(), a.distractors.end(), b.distractors.begin(), b.distractors.end(),
                    same_distractor) &&
         std::equal(a.static_objects.begin(), a.static_objects.end(), b.static_objects.begin(), b.static_objects.end(),
                    same_static) &&
         std::equal(a.dynamic_objects.begin(), a.dynamic_objects.end(), b.dynamic_objects.begin(),
                    b.dynamic_objects.end(), same_dynamic) &&
         same_weather(a.weather, b.weather) && same_drone(a.drone, b.drone);
}

// ---- reading --------------------------------------------------------------------------

namespace {

using detail::YamlReader;

// Reads the file and remembers the node of every key it read, so that a
// problem validate() finds ("static_objects[2].size: ...") is reported at
// the line of its key.
class ScenarioReader {
 public:
  explicit ScenarioReader(const YamlReader& r) : r_(r) {}

  void read(const YAML::Node& root, Scenario& s) {
    only(root, "",
         {"map", "seed", "time_limit", "marker", "distractors", "static_objects", "dynamic_objects", "weather",
          "drone"});
    s.map = read_enum<MapKind>(r_.child(root, "", "map"), "map", kMapNames);
    if (const YAML::Node n = root["seed"]) s.seed = read_seed(n);
    if (const YAML::Node n = root["time_limit"]) s.time_limit = number(n, "time_limit");
    read_marker(r_.child(root, "", "marker"), s.marker);
    read_list(root, "distractors", s.distractors, [&](const YAML::Node& n, const std::string& p, Distractor& d) {
      only(n, p, {"kind", "id", "flipped_bits", "size", "position", "yaw_deg"});
      d.kind = read_enum<DistractorKind>(r_.child(n, p, "kind"), p + "kind", kDistractorNames);
      d.position = vec2(r_.child(n, p, "position"), p + "position");
      if (const YAML::Node v = n["id"]) d.id = integer(v, p + "id");
      if (const YAML::Node v = n["flipped_bits"]) d.flipped_bits = integer(v, p + "flipped_bits");
      if (const YAML::Node v = n["size"]) d.size = number(v, p + "size");
      if (const YAML::Node v = n["yaw_deg"]) d.yaw_deg = number(v, p + "yaw_deg");
    });
    read_list(root, "static_objects", s.static_objects,
              [&](const YAML::Node& n, const std::string& p, StaticObject& o) {
                only(n, p, {"kind", "position", "yaw_deg", "size"});
                o.kind = read_enum<StaticKind>(r_.child(n, p, "kind"), p + "kind", kStaticNames);
                o.position = vec2(r_.child(n, p, "position"), p + "position");
                if (const YAML::Node v = n["yaw_deg"]) o.yaw_deg = number(v, p + "yaw_deg");
                if (const YAML::Node v = n["size"]) o.size = vec3(v, p + "size");
              });
    read_list(root, "dynamic_objects", s.dynamic_objects,
              [&](const YAML::Node& n, const std::string& p, DynamicObject& o) {
                only(n, p, {"kind", "size", "position", "altitude", "heading_deg", "speed", "motion", "extent"});
                o.kind = read_enum<DynamicKind>(r_.child(n, p, "kind"), p + "kind", kDynamicNames);
                o.position = vec2(r_.child(n, p, "position"), p + "position");
                if (const YAML::Node v = n["size"]) o.size = vec3(v, p + "size");
                if (const YAML::Node v = n["altitude"]) o.altitude = number(v, p + "altitude");
                if (const YAML::Node v = n["heading_deg"]) o.heading_deg = number(v, p + "heading_deg");
                if (const YAML::Node v = n["speed"]) o.speed = number(v, p + "speed");
                if (const YAML::Node v = n["motion"]) o.motion = read_enum<MotionKind>(v, p + "motion", kMotionNames);
                if (const YAML::Node v = n["extent"]) o.extent = number(v, p + "extent");
              });
    if (const YAML::Node n = root["weather"]) read_weather(n, s.weather);
    read_drone(r_.child(root, "", "drone"), s.drone);

    // Bounds and consistency, reported at the line of the key at fault.
    std::string why;
    if (!s.validate(&why)) fail_at_key(why);
  }

 private:
  void read_marker(const YAML::Node& n, Marker& m) {
    remember("marker", n);
    only(n, "marker.", {"dictionary", "id", "size", "position", "yaw_deg"});
    m.position = vec2(r_.child(n, "marker.", "position"), "marker.position");
    if (const YAML::Node v = n["dictionary"]) m.dictionary = text(v, "marker.dictionary");
    if (const YAML::Node v = n["id"]) m.id = integer(v, "marker.id");
    if (const YAML::Node v = n["size"]) m.size = number(v, "marker.size");
    if (const YAML::Node v = n["yaw_deg"]) m.yaw_deg = number(v, "marker.yaw_deg");
  }

  void read_weather(const YAML::Node& n, Weather& w) {
    remember("weather", n);
    only(n, "weather.",
         {"fog", "rain", "snow", "dust", "leaves", "ground_wetness", "ground_snow", "ground_leaves",
          "sun_elevation_deg", "sun_azimuth_deg", "ambient"});
    const std::pair<const char*, double*> fields[] = {{"fog", &w.fog},
                                                      {"rain", &w.rain},
                                                      {"snow", &w.snow},
                                                      {"dust", &w.dust},
                                                      {"leaves", &w.leaves},
                                                      {"ground_wetness", &w.ground_wetness},
                                                      {"ground_snow", &w.ground_snow},
                                                      {"ground_leaves", &w.ground_leaves},
                                                      {"sun_elevation_deg", &w.sun_elevation_deg},
                                                      {"sun_azimuth_deg", &w.sun_azimuth_deg},
                                                      {"ambient", &w.ambient}};
    for (const auto& [key, value] : fields) {
      if (const YAML::Node v = n[key]) *value = number(v, std::string("weather.") + key);
    }
  }

  void read_drone(const YAML::Node& n, DroneStart& d) {
    remember("drone", n);
    only(n, "drone.", {"position", "yaw_deg", "gps_error"});
    d.position = vec3(r_.child(n, "drone.", "position"), "drone.position");
    if (const YAML::Node v = n["yaw_deg"]) d.yaw_deg = number(v, "drone.yaw_deg");
    if (const YAML::Node v = n["gps_error"]) d.gps_error = vec2(v, "drone.gps_error");
  }

  // An optional list; its length is checked before its elements are read.
  template <typename T, typename ReadElement>
  void read_list(const YAML::Node& root, const std::string& key, std::vector<T>& out, ReadElement&& read_element) {
    const YAML::Node list = root[key];
    if (!list) return;
    // The key's own line: a block list starts on the line after it.
    YAML::Node at = list;
    for (const auto& kv : root) {
      if (kv.first.Scalar() == key) at.reset(kv.first);  // operator= would overwrite `list`
    }
    remember(key, at);
    if (list.IsNull()) return;  // "distractors:" with nothing after it: none
    if (!list.IsSequence()) r_.fail(at, key, "expected a list");
    const PropertyBound& count = property_bound(key);
    if (static_cast<double>(list.size()) > count.max) {
      r_.fail(at, key, "at most " + num(count.max) + " allowed, got " + std::to_string(list.size()));
    }
    out.assign(list.size(), T{});
    for (std::size_t i = 0; i < list.size(); ++i) {
      const std::string name = key + "[" + std::to_string(i) + "]";
      remember(name, list[i]);
      read_element(list[i], name + ".", out[i]);
    }
  }

  // YamlReader::only, with a readable error for a key that is not a plain
  // name (yaml-cpp's own would be "bad conversion").
  void only(const YAML::Node& map, const std::string& prefix, std::initializer_list<const char*> keys) const {
    if (map.IsMap()) {
      for (const auto& kv : map) {
        if (!kv.first.IsScalar()) {
          r_.fail(kv.first, prefix.empty() ? "<document>" : prefix.substr(0, prefix.size() - 1),
                  "a key must be a plain name");
        }
      }
    }
    r_.only(map, prefix, keys);
  }

  double number(const YAML::Node& n, const std::string& key) {
    remember(key, n);
    return r_.number(n, key);
  }
  int integer(const YAML::Node& n, const std::string& key) {
    remember(key, n);
    return r_.integer(n, key);
  }
  std::string text(const YAML::Node& n, const std::string& key) {
    remember(key, n);
    return r_.text(n, key);
  }
  Eigen::Vector2d vec2(const YAML::Node& n, const std::string& key) {
    remember(key, n);
    const auto v = r_.numbers(n, key);
    if (v.size() != 2) r_.fail(n, key, "expected 2 numbers [x, y], got " + std::to_string(v.size()));
    return {v[0], v[1]};
  }
  Eigen::Vector3d vec3(const YAML::Node& n, const std::string& key) {
    remember(key, n);
    const auto v = r_.vec3(n, key);
    return {v[0], v[1], v[2]};
  }
  // Digits only: a uint64 must not go through a double.
  std::uint64_t read_seed(const YAML::Node& n) {
    remember("seed", n);
    std::uint64_t v = 0;
    if (!n.IsScalar() || !detail::parse_int(detail::trim(n.Scalar()), v) || v > kMaxSeedInteger) {
      r_.fail(n, "seed",
              "expected an integer in [0, " + num(kMaxSeed) + "]" +
                  (n.IsScalar() ? ", got '" + n.Scalar() + "'" : std::string()));
    }
    return v;
  }
  template <typename E, std::size_t N>
  E read_enum(const YAML::Node& n, const std::string& key, const std::array<std::string_view, N>& names) {
    const std::string t = text(n, key);
    for (std::size_t i = 0; i < N; ++i) {
      if (names[i] == t) return static_cast<E>(i);
    }
    std::string allowed;
    for (const auto name : names) allowed += (allowed.empty() ? "" : ", ") + std::string(name);
    r_.fail(n, key, "expected one of " + allowed + ", got '" + t + "'");
  }

  // `why` is "key: what" from validate(): thrown at the line of the key, or
  // of the closest enclosing key the file gave ("static_objects[2].size[1]"
  // -> "static_objects[2].size" -> "static_objects[2]" -> ...).
  [[noreturn]] void fail_at_key(const std::string& why) const {
    const std::string named = why.substr(0, why.find(": "));
    const std::string what = why.substr(std::min(why.size(), named.size() + 2));
    std::string key = named;
    while (!key.empty()) {
      if (const auto it = nodes_.find(key); it != nodes_.end()) r_.fail(it->second, named, what);
      const auto cut = key.find_last_of(".[");
      key.resize(cut == std::string::npos ? 0 : cut);
    }
    throw ParseError(std::string(r_.source) + ": " + why);
  }

  // YAML::Node's operator= writes into the node it refers to: rebind instead.
  void remember(const std::string& key, const YAML::Node& n) {
    nodes_.erase(key);
    nodes_.emplace(key, n);
  }

  const YamlReader& r_;
  std::map<std::string, YAML::Node> nodes_;
};

}  // namespace

Scenario parse_scenario(std::string_view text, std::string_view source) {
  return detail::parse_validated<Scenario>(
      text, source, [](const YamlReader& r, const YAML::Node& root, Scenario& s) { ScenarioReader(r).read(root, s); });
}

Scenario load_scenario(const std::filesystem::path& path) {
  return parse_scenario(detail::read_text_file(path), path.string());
}

// ---- writing --------------------------------------------------------------------------

namespace {

// The dictionary name is the only free text; JSON escapes keep any name
// readable by both YAML and JSON readers.
std::string quoted(std::string_view s) {
  std::string out = "\"";
  for (const char ch : s) {
    const auto u = static_cast<unsigned char>(ch);
    if (ch == '"' || ch == '\\') {
      out += '\\';
      out += ch;
    } else if (u < 0x20 || u == 0x7f) {
      constexpr char hex[] = "0123456789abcdef";
      out += "\\u00";
      out += hex[u >> 4];
      out += hex[u & 15];
    } else {
      out += ch;
    }
  }
  return out + "\"";
}

std::string list_text(const double* v, int n) { return numbers_text(v, n); }

// One writer for both formats: YAML block mappings with one flow mapping
// per list element, or JSON (whose flow syntax YAML reads too).
class Writer {
 public:
  explicit Writer(bool json) : json_(json) {}

  std::string write(const Scenario& s) {
    open();
    field("map", str(to_string(s.map)));
    field("seed", std::to_string(s.seed));
    field("time_limit", num(s.time_limit));
    begin_map("marker");
    field("dictionary", str(s.marker.dictionary));
    field("id", std::to_string(s.marker.id));
    field("size", num(s.marker.size));
    field("position", list_text(s.marker.position.data(), 2));
    field("yaw_deg", num(s.marker.yaw_deg));
    end_map();
    list("distractors", s.distractors, [&](const Distractor& d) {
      return std::vector<std::pair<const char*, std::string>>{{"kind", str(to_string(d.kind))},
                                                              {"id", std::to_string(d.id)},
                                                              {"flipped_bits", std::to_string(d.flipped_bits)},
                                                              {"size", num(d.size)},
                                                              {"position", list_text(d.position.data(), 2)},
                                                              {"yaw_deg", num(d.yaw_deg)}};
    });
    list("static_objects", s.static_objects, [&](const StaticObject& o) {
      return std::vector<std::pair<const char*, std::string>>{{"kind", str(to_string(o.kind))},
                                                              {"position", list_text(o.position.data(), 2)},
                                                              {"yaw_deg", num(o.yaw_deg)},
                                                              {"size", list_text(o.size.data(), 3)}};
    });
    list("dynamic_objects", s.dynamic_objects, [&](const DynamicObject& o) {
      return std::vector<std::pair<const char*, std::string>>{{"kind", str(to_string(o.kind))},
                                                              {"size", list_text(o.size.data(), 3)},
                                                              {"position", list_text(o.position.data(), 2)},
                                                              {"altitude", num(o.altitude)},
                                                              {"heading_deg", num(o.heading_deg)},
                                                              {"speed", num(o.speed)},
                                                              {"motion", str(to_string(o.motion))},
                                                              {"extent", num(o.extent)}};
    });
    const Weather& w = s.weather;
    begin_map("weather");
    field("fog", num(w.fog));
    field("rain", num(w.rain));
    field("snow", num(w.snow));
    field("dust", num(w.dust));
    field("leaves", num(w.leaves));
    field("ground_wetness", num(w.ground_wetness));
    field("ground_snow", num(w.ground_snow));
    field("ground_leaves", num(w.ground_leaves));
    field("sun_elevation_deg", num(w.sun_elevation_deg));
    field("sun_azimuth_deg", num(w.sun_azimuth_deg));
    field("ambient", num(w.ambient));
    end_map();
    begin_map("drone");
    field("position", list_text(s.drone.position.data(), 3));
    field("yaw_deg", num(s.drone.yaw_deg));
    field("gps_error", list_text(s.drone.gps_error.data(), 2));
    end_map();
    close();
    return out_;
  }

 private:
  // Enum names are plain words in YAML, strings in JSON.
  std::string str(std::string_view s) const {
    if (json_) return quoted(s);
    const bool plain = !s.empty() && std::all_of(s.begin(), s.end(), [](char c) {
      return (c >= 'a' && c <= 'z') || (c >= 'A' && c <= 'Z') || (c >= '0' && c <= '9') || c == '_';
    });
    // A plain name that YAML would read as a number or a boolean is quoted.
    double unused = 0;
    return plain && !detail::parse_double(s, unused) ? std::string(s) : quoted(s);
  }
  std::string key(const char* k) const { return json_ ? quoted(k) : std::string(k); }
  void indent() { out_.append(2 * static_cast<std::size_t>(depth_), ' '); }
  void open() {
    if (json_) {
      out_ += "{";
      ++depth_;
    }
  }
  void close() {
    if (json_) out_ += "\n}\n";
  }
  // Before each field: JSON needs commas between fields.
  void next() {
    if (json_) {
      out_ += first_ ? "\n" : ",\n";
      first_ = false;
    }
    indent();
  }
  void field(const char* k, const std::string& value) {
    next();
    out_ += key(k) + ": " + value;
    if (!json_) out_ += "\n";
  }
  void begin_map(const char* k) {
    next();
    out_ += key(k) + (json_ ? ": {" : ":\n");
    ++depth_;
    first_ = true;
  }
  void end_map() {
    --depth_;
    if (json_) {
      out_ += "\n";
      indent();
      out_ += "}";
    }
    first_ = false;
  }
  template <typename T, typename Fields>
  void list(const char* k, const std::vector<T>& items, Fields&& fields) {
    next();
    out_ += key(k) + ":";
    if (items.empty()) {
      out_ += json_ ? " []" : " []\n";
      return;
    }
    out_ += json_ ? " [" : "\n";
    for (std::size_t i = 0; i < items.size(); ++i) {
      if (json_) out_ += i ? ",\n" : "\n";
      indent();
      out_ += json_ ? "  {" : "  - {";
      bool first = true;
      for (const auto& [name, value] : fields(items[i])) {
        out_ += (first ? "" : ", ") + key(name) + ": " + value;
        first = false;
      }
      out_ += json_ ? "}" : "}\n";
    }
    if (json_) {
      out_ += "\n";
      indent();
      out_ += "]";
    }
  }

  bool json_;
  int depth_ = 0;
  bool first_ = true;
  std::string out_;
};

}  // namespace

std::string to_yaml(const Scenario& s) { return Writer(false).write(s); }
std::string to_json(const Scenario& s) { return Writer(true).write(s); }

// ---- random scenarios -----------------------------------------------------------------

namespace {

// Draws of a landing test: a marker near the origin, the drone a few metres
// off at a realistic approach height, objects around the marker, weather
// mostly mild. Values are rounded to a readable step (1 cm, 0.1 deg, ...):
// bounds are multiples of the steps, so rounding stays within them.
class Drawer {
 public:
  explicit Drawer(std::uint64_t seed) : rng_(seed, 0) {}

  // Uniform in [lo, hi], rounded to 1/per_unit: the division by a whole
  // number gives the double nearest the decimal (2.01, not 2.0100000000000002);
  // + 0.0 turns -0 into 0.
  double uniform(double lo, double hi, double per_unit) {
    return std::clamp(std::round(rng_.uniform(lo, hi) * per_unit) / per_unit + 0.0, lo, hi);
  }
  double fraction() { return rng_.uniform(); }
  double angle() { return uniform(-180, 180, 10); }
  // Within the bounds of `key` (component j for per-component rows).
  double in_row(std::string_view key, double per_unit) {
    const PropertyBound& b = property_bound(key);
    return uniform(b.min, b.max, per_unit);
  }
  int integer(int lo, int hi) {  // in [lo, hi]
    return lo + static_cast<int>(rng_.next() % static_cast<std::uint64_t>(hi - lo + 1));
  }
  bool chance(double p) { return rng_.uniform() < p; }
  Eigen::Vector2d around(const Eigen::Vector2d& centre, double r_min, double r_max) {
    const double r = rng_.uniform(r_min, r_max), phi = rng_.uniform(0, 2 * std::numbers::pi);
    const Eigen::Vector2d p = centre + r * Eigen::Vector2d(std::cos(phi), std::sin(phi));
    return {std::clamp(std::round(p.x() * 100) / 100 + 0.0, -kMapHalf, kMapHalf),
            std::clamp(std::round(p.y() * 100) / 100 + 0.0, -kMapHalf, kMapHalf)};
  }
  std::uint64_t bits() { return rng_.next(); }

 private:
  Rng rng_;
};

std::string kind_key(std::string_view list, std::string_view kind, std::string_view prop) {
  return std::string(list) + "[" + std::string(kind) + "]." + std::string(prop);
}

Eigen::Vector3d draw_size(Drawer& d, std::string_view list, std::string_view kind) {
  Eigen::Vector3d size;
  const std::string whole = kind_key(list, kind, "size");
  for (int j = 0; j < 3; ++j) {
    size[j] = find_bound(whole) ? d.in_row(whole, 100) : d.in_row(whole + "[" + std::to_string(j) + "]", 100);
  }
  return size;
}

void draw_distractors(Drawer& d, Scenario& s, const pose::detail::ArucoDictionaryInfo& dict) {
  const int n = d.integer(0, 3);
  const Footprint target = marker_square(s.marker.position, s.marker.yaw_deg, s.marker.size, dict.bits);
  for (int k = 0; k < n; ++k) {
    Distractor x;
    const double kind = d.fraction();
    x.kind = kind < 0.4 ? DistractorKind::wrong_id : kind < 0.7 ? DistractorKind::lookalike : DistractorKind::pattern;
    if (x.kind == DistractorKind::wrong_id) {
      x.id = d.integer(0, dict.codes - 2);
      if (x.id >= s.marker.id) ++x.id;  // every id but the marker's
    } else {
      x.id = d.integer(0, static_cast<int>(kMaxMarkerId));
    }
    x.flipped_bits = x.kind == DistractorKind::lookalike ? d.integer(1, 4) : 1;
    x.size = d.uniform(0.5, 1.5, 100);
    x.yaw_deg = d.angle();
    // A few tries to find free ground near the marker, else no distractor.
    for (int attempt = 0; attempt < 10; ++attempt) {
      x.position = d.around(s.marker.position, 1.5, 6);
      const Footprint square = marker_square(x.position, x.yaw_deg, x.size, dict.bits);
      bool free = !overlap(square, target);
      for (const Distractor& e : s.distractors) {
        free = free && !overlap(square, marker_square(e.position, e.yaw_deg, e.size, dict.bits));
      }
      if (free) {
        s.distractors.push_back(x);
        break;
      }
    }
  }
}

void draw_static_objects(Drawer& d, Scenario& s) {
  const int n = d.integer(0, 6);
  for (int k = 0; k < n; ++k) {
    StaticObject o;
    o.kind = static_cast<StaticKind>(d.integer(0, static_cast<int>(kStaticNames.size()) - 1));
    o.position = {d.uniform(-12, 12, 100), d.uniform(-12, 12, 100)};
    o.yaw_deg = d.angle();
    o.size = draw_size(d, "static_objects", to_string(o.kind));
    if (o.kind == StaticKind::pole) o.size.y() = o.size.x();
    // A tree's trunk is at most half its crown (both rounded to 1 cm, the
    // crown at least 1 m: the trunk stays thinner).
    if (o.kind == StaticKind::tree) o.size.y() = std::min(o.size.y(), std::round(o.size.x() * 50) / 100);
    s.static_objects.push_back(o);
  }
}

void draw_dynamic_objects(Drawer& d, Scenario& s) {
  const int n = d.integer(0, 3);
  for (int k = 0; k < n; ++k) {
    DynamicObject o;
    const double kind = d.fraction();
    o.kind = kind < 0.5 ? DynamicKind::person : kind < 0.75 ? DynamicKind::dog : DynamicKind::bird;
    const std::string_view name = to_string(o.kind);
    o.size = draw_size(d, "dynamic_objects", name);
    o.position = {d.uniform(-12, 12, 100), d.uniform(-12, 12, 100)};
    o.altitude = d.in_row(kind_key("dynamic_objects", name, "altitude"), 100);
    o.heading_deg = d.angle();
    // From a stroll to the kind's top speed.
    o.speed = d.uniform(0.2 * property_bound(kind_key("dynamic_objects", name, "speed")).max,
                        property_bound(kind_key("dynamic_objects", name, "speed")).max, 100);
    // Scripted motions only: `external` needs a controller.
    o.motion = o.kind == DynamicKind::bird ? (d.chance(0.5) ? MotionKind::line : MotionKind::circle)
                                           : static_cast<MotionKind>(d.integer(0, 3));
    o.extent = d.uniform(2, 10, 100);
    s.dynamic_objects.push_back(o);
  }
}

void draw_weather(Drawer& d, Scenario& s) {
  Weather& w = s.weather;
  const bool lawn = s.map == MapKind::lawn;
  // Each effect is off half of the time (leaves mostly on the lawn).
  const auto effect = [&](double p_on, double lo, double hi) { return d.chance(p_on) ? d.uniform(lo, hi, 100) : 0.0; };
  // Fog mostly light (visibility over 26 m); dense fog now and then.
  if (d.chance(0.5)) w.fog = d.chance(0.8) ? d.uniform(0, 0.15, 1000) : d.uniform(0.15, 0.4, 1000);
  w.rain = effect(0.5, 0, 1);
  w.snow = effect(0.5, 0, 1);
  w.dust = effect(0.5, 0, 1);
  w.leaves = effect(lawn ? 0.5 : 0.2, 0, 1);
  w.ground_wetness = effect(0.5, 0, 1);
  w.ground_snow = effect(0.5, 0, 1);
  w.ground_leaves = effect(lawn ? 0.5 : 0.2, 0, 1);
  w.sun_elevation_deg = d.in_row("weather.sun_elevation_deg", 10);
  w.sun_azimuth_deg = d.in_row("weather.sun_azimuth_deg", 10);
  w.ambient = d.chance(0.7) ? d.uniform(0.6, 1, 100) : d.uniform(0.15, 0.6, 100);
}

// 5-15 m from the marker at 8-15 m, outside every static object (a few
// tries, then high enough above them).
void draw_drone(Drawer& d, Scenario& s) {
  DroneStart& drone = s.drone;
  drone.yaw_deg = d.angle();
  drone.gps_error = {d.uniform(-3, 3, 100), d.uniform(-3, 3, 100)};
  for (int attempt = 0; attempt < 20; ++attempt) {
    drone.position << d.around(s.marker.position, 5, 15), d.uniform(8, 15, 100);
    const bool clear = std::none_of(s.static_objects.begin(), s.static_objects.end(), [&](const StaticObject& o) {
      return static_footprint(o).contains(drone.position.head<2>()) &&
             drone.position.z() < o.size.z() + kDroneClearance;
    });
    if (clear) return;
  }
  double top = 0;
  for (const StaticObject& o : s.static_objects) top = std::max(top, o.size.z());
  drone.position.z() = std::max(drone.position.z(), std::ceil(top + kDroneClearance + 1));
}

}  // namespace

Scenario random_scenario(std::uint64_t seed, MapKind map) {
  Drawer d(seed);
  Scenario s;
  s.map = map;
  s.seed = d.bits() >> 11;  // below 2^53
  // The time limit is the test's criterion, not part of the world: every
  // random scenario gets the same one (the default, 60 s: a clear landing
  // takes about 20 s, a full spiral search about 25 s more).
  s.time_limit = Scenario{}.time_limit;
  // Dictionaries with and without error correction at OpenCV's default
  // rate (4X4_50 corrects no cell, 5X5_50 and 6X6_50 do), so that
  // look-alike distractors can be read as the target.
  static constexpr const char* kDictionaries[] = {"4X4_50", "5X5_50", "6X6_50"};
  s.marker.dictionary = kDictionaries[d.integer(0, 2)];
  const auto* dict = pose::detail::find_aruco_dictionary(s.marker.dictionary);
  s.marker.id = d.integer(0, dict->codes - 1);
  s.marker.size = d.uniform(0.5, 1.5, 100);
  s.marker.position = {d.uniform(-3, 3, 100), d.uniform(-3, 3, 100)};
  s.marker.yaw_deg = d.angle();
  draw_distractors(d, s, *dict);
  draw_static_objects(d, s);
  draw_dynamic_objects(d, s);
  draw_weather(d, s);
  draw_drone(d, s);
  return s;
}

// The map comes from its own stream, so random_scenario(seed) equals
// random_scenario(seed, its map).
Scenario random_scenario(std::uint64_t seed) {
  Rng rng(seed, 1);
  return random_scenario(seed, (rng.next() >> 63) ? MapKind::lawn : MapKind::ground);
}

}  // namespace touchdown::scenario
