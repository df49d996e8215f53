#pragma once
/// \file
/// A marker-landing test scenario (RLaGA paper's world, headless): the map,
/// the landing marker and distractors, static and moving objects, weather,
/// and where the drone starts with which approximate (GPS-like) target.
///
/// Every number a search may draw or mutate has its bounds in one table,
/// `property_bounds()`; `Scenario::validate` and the file readers check
/// against it, `random_scenario` draws from it. Files are YAML or JSON
/// (docs/formats.md, "Landing scenarios") and round-trip exactly: angles are
/// kept in degrees as written, numbers are written in the shortest form that
/// reads back to the same double.
///
/// World frame: x east, y north, z up [m]; the ground is the plane z = 0.
/// Yaw and heading angles are counter-clockwise from +x, in degrees.
#include <Eigen/Core>
#include <array>
#include <cstdint>
#include <filesystem>
#include <string>
#include <string_view>
#include <vector>

#include "touchdown/core/enum_names.hpp"

namespace touchdown::scenario {

enum class MapKind { Ground, Lawn };  ///< concrete, city-like / grass, natural
enum class DistractorKind {
  WrongId,    ///< a valid marker of the same dictionary with another id
  Lookalike,  ///< the target's code with `flipped_bits` cells inverted
  Pattern,    ///< a random black-and-white grid with a marker's border
};
enum class StaticKind { Box, Chair, Pole, Tree };
enum class DynamicKind { Person, Dog, Bird };
enum class MotionKind {
  Still,     ///< stays at its start
  Line,      ///< walks `extent` metres along its heading and back, repeatedly
  Circle,    ///< circles with radius `extent`, centre to its left
  Wander,    ///< seeded random walk within `extent` of its start
  External,  ///< moved by an external controller (up/down/left/right/stay)
};

}  // namespace touchdown::scenario

// The spellings of the scenario files (docs/formats.md) and the command line.
template <>
struct touchdown::EnumNames<touchdown::scenario::MapKind> {
  static constexpr std::array<std::string_view, 2> names{"ground", "lawn"};
};
template <>
struct touchdown::EnumNames<touchdown::scenario::DistractorKind> {
  static constexpr std::array<std::string_view, 3> names{"wrong_id", "lookalike", "pattern"};
};
template <>
struct touchdown::EnumNames<touchdown::scenario::StaticKind> {
  static constexpr std::array<std::string_view, 4> names{"box", "chair", "pole", "tree"};
};
template <>
struct touchdown::EnumNames<touchdown::scenario::DynamicKind> {
  static constexpr std::array<std::string_view, 3> names{"person", "dog", "bird"};
};
template <>
struct touchdown::EnumNames<touchdown::scenario::MotionKind> {
  static constexpr std::array<std::string_view, 5> names{"still", "line", "circle", "wander", "external"};
};

namespace touchdown::scenario {

inline std::string_view to_string(MapKind kind) { return enum_name(kind); }
inline std::string_view to_string(DistractorKind kind) { return enum_name(kind); }
inline std::string_view to_string(StaticKind kind) { return enum_name(kind); }
inline std::string_view to_string(DynamicKind kind) { return enum_name(kind); }
inline std::string_view to_string(MotionKind kind) { return enum_name(kind); }

struct Marker {
  std::string dictionary = "4X4_50";  ///< OpenCV ArUco dictionary name
  int id = 0;
  double size = 1.0;  ///< black-border edge [m]; a white margin of one cell surrounds it
  Eigen::Vector2d position{0, 0};
  double yaw_deg = 0;
};

struct Distractor {
  DistractorKind kind = DistractorKind::WrongId;
  int id = 1;            ///< wrong_id: the marker drawn; pattern: seed of the grid
  int flipped_bits = 1;  ///< lookalike: cells inverted in the target's code
  double size = 1.0;
  Eigen::Vector2d position{0, 0};
  double yaw_deg = 0;
};

/// Simple solids: box = its extents; chair = seat width, depth, back height;
/// pole = diameter, diameter, height; tree = crown diameter, trunk diameter,
/// height.
struct StaticObject {
  StaticKind kind = StaticKind::Box;
  Eigen::Vector2d position{0, 0};
  double yaw_deg = 0;
  Eigen::Vector3d size{1, 1, 1};
};

/// A moving object. size = length, width, height [m] (a person's height is
/// its z size); a bird flies at `altitude`, the others walk on the ground.
struct DynamicObject {
  DynamicKind kind = DynamicKind::Person;
  Eigen::Vector3d size{0.5, 0.4, 1.75};
  Eigen::Vector2d position{0, 0};  ///< start
  double altitude = 0;             ///< bird only [m]
  double heading_deg = 0;          ///< start heading
  double speed = 1.0;              ///< [m/s]
  MotionKind motion = MotionKind::Line;
  double extent = 5.0;  ///< line length, circle radius or wander radius [m]
};

/// Weather: every property in [0, 1] is an intensity, unless a unit is given.
struct Weather {
  double fog = 0;  ///< extinction coefficient [1/m] (visibility 3.912/fog)
  double rain = 0;
  double snow = 0;
  double dust = 0;
  double leaves = 0;          ///< falling leaves
  double ground_wetness = 0;  ///< darkens the ground and reflects the sun (glare)
  double ground_snow = 0;     ///< snow cover of the ground (and of the marker)
  double ground_leaves = 0;   ///< leaf cover of the ground (and of the marker)
  double sun_elevation_deg = 50;
  double sun_azimuth_deg = 135;
  double ambient = 1.0;  ///< light level (1 = overcast day; low light adds sensor noise)
};

/// The drone starts hovering at `position`; its landing system is given the
/// target marker.position + gps_error (a GPS-like approximate position).
struct DroneStart {
  Eigen::Vector3d position{-8, 0, 12};
  double yaw_deg = 0;
  Eigen::Vector2d gps_error{0, 0};
};

struct Scenario {
  MapKind map = MapKind::Ground;
  std::uint64_t seed = 1;  ///< place on the map, cover pattern, particles and wandering objects
  double time_limit = 60;  ///< [s]; no landing by then is a violation
  Marker marker;
  std::vector<Distractor> distractors;
  std::vector<StaticObject> static_objects;
  std::vector<DynamicObject> dynamic_objects;
  Weather weather;
  DroneStart drone;

  /// The approximate target the landing system is given.
  [[nodiscard]] Eigen::Vector2d gps_target() const { return marker.position + drone.gps_error; }
  /// False (with "key: what", e.g. "static_objects[2].size: ...") when a
  /// property is outside its bounds or the scenario is inconsistent.
  [[nodiscard]] bool validate(std::string* why) const;
};

/// One row of the bounds table. Keys name the file's keys; list elements
/// use "[]" (e.g. "static_objects[].size"). A vector property bounds each
/// component.
struct PropertyBound {
  std::string_view key;
  double min = 0;
  double max = 0;
  std::string_view unit;     ///< "m", "deg", "m/s", "1/m", "" (intensity or count)
  std::string_view meaning;  ///< one line for docs and --help
  bool integer = false;
};

/// The one table of realistic bounds (docs/formats.md prints it).
const std::vector<PropertyBound>& property_bounds();
/// The row for `key`; throws InvalidArgument for an unknown key.
const PropertyBound& property_bound(std::string_view key);
/// The row for `key`, or nullptr.
const PropertyBound* find_property_bound(std::string_view key);
/// The per-kind row of component j of LIST[KIND].PROP ("static_objects",
/// "tree", "size", 2): the row of the whole property
/// ("static_objects[box].size") or of the component
/// ("static_objects[tree].size[2]"); nullptr when the envelope row
/// ("static_objects[].size") applies.
const PropertyBound* find_kind_bound(std::string_view list, std::string_view kind, std::string_view prop, int j);
/// "LIST[I].PROP": the key of an element's property, as messages name it.
std::string indexed_key(std::string_view list, std::size_t i, std::string_view prop);

/// Reads a scenario from YAML (JSON is YAML too). Unknown keys, missing
/// keys, NaN and values outside property_bounds() throw ParseError naming
/// "source:line: key: what".
Scenario parse_scenario(std::string_view text, std::string_view source);
Scenario load_scenario(const std::filesystem::path& path);
/// The scenario as YAML or JSON; parse_scenario(to_yaml(s)) == s exactly.
std::string to_yaml(const Scenario& s);
std::string to_json(const Scenario& s);
bool operator==(const Scenario& a, const Scenario& b);

/// Makes `dictionary` id `id` the scenario's target marker; wrong-id
/// distractors keep an id of that dictionary other than `id`. Throws
/// InvalidArgument for an unknown dictionary or an id not in it.
void set_target(Scenario& s, const std::string& dictionary, int id);

/// The scenario's most intense weather condition, each intensity scaled to 1
/// at a level that visibly changes the camera's view (fog 0.1 /m, rain,
/// snowfall, dust and falling leaves 0.5, wet ground 0.7, ground snow and
/// ground leaves 0.5, low light ambient 0.5): "fog", "rain", "snowfall",
/// "dust", "falling leaves", "wet ground", "ground snow", "ground leaves",
/// "low light"; "clear" when none reaches 1.
std::string dominant_weather(const Weather& w);

/// A random valid scenario drawn from property_bounds(): same seed, same
/// scenario. `map` fixes the map (else drawn).
Scenario random_scenario(std::uint64_t seed);
Scenario random_scenario(std::uint64_t seed, MapKind map);

}  // namespace touchdown::scenario
