// Landing scenarios: the bounds table, validation and equality
// (docs/formats.md, "Landing scenarios"). The file format is in
// scenario_io.cpp, random scenarios in scenario_random.cpp.
#include "touchdown/scenario/scenario.hpp"

#include <Eigen/Geometry>
#include <algorithm>
#include <array>
#include <cmath>
#include <string>
#include <utility>

#include "scenario/scenario_internal.hpp"
#include "touchdown/core/error.hpp"
#include "touchdown/core/units.hpp"
#include "touchdown/pose/sim/aruco_dictionary.hpp"

namespace touchdown::scenario {

using namespace detail;  // NOLINT(google-build-using-namespace): the module's own private helpers

// ---- the bounds table -----------------------------------------------------------------

namespace {

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

}  // namespace

namespace detail {

const PropertyBound* find_bound(std::string_view key) {
  const auto& rows = property_bounds();
  const auto it = std::find_if(rows.begin(), rows.end(), [&](const PropertyBound& b) { return b.key == key; });
  return it == rows.end() ? nullptr : &*it;
}

std::string numbers_text(const double* v, int n) {
  std::string s = "[";
  for (int i = 0; i < n; ++i) s += (i ? ", " : "") + num(v[i]);
  return s + "]";
}

std::string indexed(std::string_view list, std::size_t i, std::string_view prop) {
  return std::string(list) + "[" + std::to_string(i) + "]." + std::string(prop);
}

}  // namespace detail

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
  const bool round = o.kind == StaticKind::Pole || o.kind == StaticKind::Tree;
  return {o.position, deg_to_rad(o.yaw_deg), Eigen::Vector2d(o.size.x() / 2, o.size.y() / 2), round};
}

const PropertyBound* find_property_bound(std::string_view key) { return detail::find_bound(key); }

const PropertyBound* find_kind_bound(std::string_view list, std::string_view kind, std::string_view prop, int j) {
  const std::string whole = std::string(list) + "[" + std::string(kind) + "]." + std::string(prop);
  if (const PropertyBound* b = detail::find_bound(whole)) return b;
  return detail::find_bound(whole + "[" + std::to_string(j) + "]");
}

std::string indexed_key(std::string_view list, std::size_t i, std::string_view prop) {
  return detail::indexed(list, i, prop);
}

namespace {

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

void check_marker_like(Checker& c, const Scenario& s, const pose::ArucoDictionaryInfo& dict) {
  if (c.failed()) return;
  if (s.marker.id >= dict.codes) {
    c.fail("marker.id: " + std::string(dict.name) + " has ids 0.." + std::to_string(dict.codes - 1) + ", got " +
           std::to_string(s.marker.id));
    return;
  }
  const Footprint target = marker_square(s.marker.position, s.marker.yaw_deg, s.marker.size, dict.bits);
  for (std::size_t i = 0; i < s.distractors.size(); ++i) {
    const Distractor& d = s.distractors[i];
    if (d.kind == DistractorKind::WrongId) {
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
    if (d.kind == DistractorKind::Lookalike && d.flipped_bits > dict.bits * dict.bits) {
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

// ---- public: table --------------------------------------------------------------------

const std::vector<PropertyBound>& property_bounds() {
  static const std::vector<PropertyBound> kRows = make_bounds();
  return kRows;
}

const PropertyBound& property_bound(std::string_view key) {
  if (const PropertyBound* b = find_bound(key)) return *b;
  throw InvalidArgument("property_bound: unknown key '" + std::string(key) + "'");
}

// ---- public: validate -----------------------------------------------------------------

bool Scenario::validate(std::string* why) const {
  Checker c;
  if (static_cast<std::size_t>(map) >= EnumNames<MapKind>::names.size()) c.fail("map: unknown map kind");
  // Compared as integers: 2^53 + 1 would round to 2^53 as a double.
  if (seed > kMaxSeedInteger) {
    c.fail("seed: must be an integer in [0, " + num(kMaxSeed) + "], got " + std::to_string(seed));
  }
  c.value("time_limit", "time_limit", time_limit);

  const auto* dict = pose::find_aruco_dictionary(marker.dictionary);
  if (!c.failed() && !dict) c.fail("marker.dictionary: unknown " + pose::unknown_aruco_dictionary(marker.dictionary));
  c.value("marker.id", "marker.id", marker.id);
  c.value("marker.size", "marker.size", marker.size);
  c.vec2("marker.position", "marker.position", marker.position);
  c.value("marker.yaw_deg", "marker.yaw_deg", marker.yaw_deg);

  c.count("distractors", distractors.size());
  for (std::size_t i = 0; i < distractors.size(); ++i) {
    const Distractor& d = distractors[i];
    if (!c.failed() && static_cast<std::size_t>(d.kind) >= EnumNames<DistractorKind>::names.size()) {
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
    if (!c.failed() && static_cast<std::size_t>(o.kind) >= EnumNames<StaticKind>::names.size()) {
      c.fail(indexed("static_objects", i, "kind") + ": unknown static object kind");
    }
    const std::string_view kind = to_string(o.kind);
    c.element("static_objects", i, kind, "position", o.position.data(), 2);
    c.element("static_objects", i, kind, "yaw_deg", &o.yaw_deg, 1);
    c.element("static_objects", i, kind, "size", o.size.data(), 3);
    if (!c.failed() && o.kind == StaticKind::Pole && o.size.y() != o.size.x()) {
      c.fail(indexed("static_objects", i, "size") + ": a pole is round: size[1] must equal size[0], got " +
             numbers_text(o.size.data(), 3));
    }
    if (!c.failed() && o.kind == StaticKind::Tree && !(o.size.y() < o.size.x())) {
      c.fail(indexed("static_objects", i, "size") + ": a tree's trunk (size[1]) must be thinner than its crown " +
             "(size[0]), got " + numbers_text(o.size.data(), 3));
    }
  }

  c.count("dynamic_objects", dynamic_objects.size());
  for (std::size_t i = 0; i < dynamic_objects.size(); ++i) {
    const DynamicObject& o = dynamic_objects[i];
    if (!c.failed() && static_cast<std::size_t>(o.kind) >= EnumNames<DynamicKind>::names.size()) {
      c.fail(indexed("dynamic_objects", i, "kind") + ": unknown dynamic object kind");
    }
    if (!c.failed() && static_cast<std::size_t>(o.motion) >= EnumNames<MotionKind>::names.size()) {
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

// ---- public: the target ---------------------------------------------------------------

void set_target(Scenario& s, const std::string& dictionary, int id) {
  const auto* dict = pose::find_aruco_dictionary(dictionary);
  if (!dict) throw InvalidArgument("marker: unknown dictionary " + dictionary);
  if (id < 0 || id >= dict->codes)
    throw InvalidArgument("marker: " + dictionary + " has ids 0.." + std::to_string(dict->codes - 1) + ", got " +
                          std::to_string(id));
  s.marker.dictionary = dictionary;
  s.marker.id = id;
  for (Distractor& d : s.distractors) {
    if (d.kind != DistractorKind::WrongId) continue;
    d.id %= dict->codes;
    if (d.id == id) d.id = (d.id + 1) % dict->codes;
  }
}

// ---- public: the dominant weather ----------------------------------------------------

std::string dominant_weather(const Weather& w) {
  const std::array<std::pair<double, const char*>, 9> levels{{
      {w.fog / 0.1, "fog"},
      {w.rain / 0.5, "rain"},
      {w.snow / 0.5, "snowfall"},
      {w.dust / 0.5, "dust"},
      {w.leaves / 0.5, "falling leaves"},
      {w.ground_wetness / 0.7, "wet ground"},
      {w.ground_snow / 0.5, "ground snow"},
      {w.ground_leaves / 0.5, "ground leaves"},
      {(1 - w.ambient) / 0.5, "low light"},
  }};
  double best = 1;
  const char* name = "clear";
  for (const auto& [level, label] : levels) {
    if (level >= best) best = level, name = label;
  }
  return name;
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

}  // namespace touchdown::scenario
