// The diversity option's covering seed pool (cover_pool.hpp). A covering
// design in the sense of one-factor-at-a-time boundary-value testing
// (Myers, "The Art of Software Testing", ch. 4: boundary values; the
// combinatorial-testing literature's base choice coverage): every factor
// the search varies is met once at its severe end with the others benign,
// so a defect that lives at one factor's extreme is in the first
// generation, whatever the seed.
#include "cover_pool.hpp"

#include <algorithm>
#include <array>
#include <cmath>
#include <numbers>
#include <string_view>

#include "touchdown/core/random.hpp"
#include "touchdown/pose/sim/aruco_dictionary.hpp"
#include "touchdown/scenario/footprint.hpp"

namespace touchdown::search::detail {

namespace {

using scenario::DistractorKind;
using scenario::DynamicKind;
using scenario::MotionKind;
using scenario::StaticKind;

// The pool's own stream: never random sampling's (kDrawStream = 2^40) nor
// the spread pool's (2^41).
constexpr std::uint64_t kCoverStream = std::uint64_t{3} << 40;
constexpr double kSevere = 0.1;  // the severe tenth of a range

// A weather condition: the field and which end of its row is severe.
struct WeatherCondition {
  std::string_view name;
  std::string_view key;
  double scenario::Weather::*field;
  bool low_is_severe;
};

constexpr std::array<WeatherCondition, 10> kWeather{{
    {"fog", "weather.fog", &scenario::Weather::fog, false},
    {"rain", "weather.rain", &scenario::Weather::rain, false},
    {"snowfall", "weather.snow", &scenario::Weather::snow, false},
    {"dust", "weather.dust", &scenario::Weather::dust, false},
    {"falling leaves", "weather.leaves", &scenario::Weather::leaves, false},
    {"wet ground", "weather.ground_wetness", &scenario::Weather::ground_wetness, false},
    {"ground snow", "weather.ground_snow", &scenario::Weather::ground_snow, false},
    {"ground leaves", "weather.ground_leaves", &scenario::Weather::ground_leaves, false},
    {"low sun", "weather.sun_elevation_deg", &scenario::Weather::sun_elevation_deg, true},
    {"low light", "weather.ambient", &scenario::Weather::ambient, true},
}};

constexpr std::array<std::string_view, 3> kDistractors{"wrong_id", "lookalike", "pattern"};
constexpr std::array<std::string_view, 3> kDynamic{"person", "dog", "bird"};
constexpr std::array<std::string_view, 4> kStatic{"box", "chair", "pole", "tree"};

enum class Kind { Weather, Distractor, Dynamic, Static };
struct Condition {
  Kind kind;
  std::size_t index;  // into the array of its kind
};

std::vector<Condition> conditions(const ChromosomeOptions& o) {
  std::vector<Condition> objects;
  // Distractors first: a look-alike accepted is the worst outcome (Type I).
  if (o.distractor_slots > 0) {
    for (std::size_t i = 0; i < kDistractors.size(); ++i) objects.push_back({Kind::Distractor, i});
  }
  if (o.dynamic_slots > 0) {
    for (std::size_t i = 0; i < kDynamic.size(); ++i) objects.push_back({Kind::Dynamic, i});
  }
  if (o.static_slots > 0) {
    for (std::size_t i = 0; i < kStatic.size(); ++i) objects.push_back({Kind::Static, i});
  }
  std::vector<Condition> out;
  for (std::size_t i = 0; i < std::max(kWeather.size(), objects.size()); ++i) {
    if (i < kWeather.size()) out.push_back({Kind::Weather, i});
    if (i < objects.size()) out.push_back(objects[i]);
  }
  return out;
}

std::string name_of(const Condition& c) {
  switch (c.kind) {
    case Kind::Weather:
      return std::string(kWeather[c.index].name);
    case Kind::Distractor:
      return std::string(kDistractors[c.index]) + " near the marker";
    case Kind::Dynamic:
      return std::string(kDynamic[c.index]) + " at the marker";
    case Kind::Static:
      return std::string(kStatic[c.index]) + " beside the marker";
  }
  return {};
}

// [min, max] of component j of list[kind].prop: its per-kind row, else the
// envelope row (the bounds table's rule, scenario.cpp).
std::pair<double, double> range_of(std::string_view list, std::string_view kind, std::string_view prop, int j) {
  const scenario::PropertyBound* b = scenario::find_kind_bound(list, kind, prop, j);
  if (!b) b = &scenario::property_bound(std::string(list) + "[]." + std::string(prop));
  return {b->min, b->max};
}

double severe(std::pair<double, double> r, bool low, Rng& rng) {
  const double width = r.second - r.first;
  return low ? rng.uniform(r.first, r.first + kSevere * width) : rng.uniform(r.second - kSevere * width, r.second);
}

Eigen::Vector2d around(const Eigen::Vector2d& centre, double r, Rng& rng) {
  const double a = rng.uniform(-std::numbers::pi, std::numbers::pi);
  return centre + r * Eigen::Vector2d(std::cos(a), std::sin(a));
}

// The benign scene: the draw's seed, marker and non-gene fields; no
// weather to speak of; no objects.
void make_benign(scenario::Scenario& s, Rng& rng) {
  const double azimuth = s.weather.sun_azimuth_deg;
  s.weather = scenario::Weather{};
  s.weather.sun_azimuth_deg = azimuth;
  s.weather.sun_elevation_deg = rng.uniform(45, 90);
  s.weather.ambient = rng.uniform(0.85, 1);
  s.dynamic_objects.clear();
  s.static_objects.clear();
  s.distractors.clear();
}

void add_distractor(scenario::Scenario& s, std::size_t i, Rng& rng) {
  scenario::Distractor d;
  d.kind = static_cast<DistractorKind>(i);
  d.size = severe(range_of("distractors", kDistractors[i], "size", 0), false, rng);
  d.yaw_deg = rng.uniform(-180, 180);
  // Moved out along a random direction until its square (with its white
  // margin) clears the marker's — decode() drops a distractor over the
  // marker — then 0–1 m farther: near enough that both are in one view
  // while the drone confirms the marker from a few metres up.
  const double a = rng.uniform(-std::numbers::pi, std::numbers::pi);
  const Eigen::Vector2d u(std::cos(a), std::sin(a));
  const int bits = pose::find_aruco_dictionary(s.marker.dictionary)->bits;  // the draw's base is valid
  const scenario::Footprint target = scenario::marker_square(s.marker.position, s.marker.yaw_deg, s.marker.size, bits);
  double r = 0;
  while (scenario::overlap(target, scenario::marker_square(s.marker.position + r * u, d.yaw_deg, d.size, bits))) {
    r += 0.01;
  }
  d.position = s.marker.position + (r + 0.01 + rng.uniform(0, 1)) * u;
  // decode() takes it modulo the dictionary's size and off marker.id.
  const auto ids = scenario::property_bound("distractors[].id");
  d.id = static_cast<int>(std::floor(rng.uniform(ids.min, ids.max + 1)));
  d.flipped_bits = 1 + static_cast<int>(rng.next() % 4);
  s.distractors.insert(s.distractors.begin(), d);
}

// A walk-in timed to reach the landing spot while the drone lands: it
// starts 3–8 m from the marker heading for it at the speed that takes it
// there 15–50 % into the run (9–30 s of a 60 s run: a landing system's
// usual descent, after its climb, transit and confirmation), within its
// kind's speed range; scripted, it walks a line through the spot and 3 m
// beyond, and back; for rlaga the DQN drives it from there at that speed
// (along the axes, so no sooner). Sooner, the DQN parks it on the marker
// before the system has seen it (eq. 5 rewards occlusion): an unfair run
// ("target hidden by") that the diversity option scores 0, and the
// collision hazard of an object entering the landing column is never met.
void add_dynamic(scenario::Scenario& s, std::size_t i, Rng& rng) {
  scenario::DynamicObject o;
  o.kind = static_cast<DynamicKind>(i);
  for (int j = 0; j < 3; ++j) {
    const auto r = range_of("dynamic_objects", kDynamic[i], "size", j);
    o.size[j] = rng.uniform(0.5 * (r.first + r.second), r.second);
  }
  const double distance = rng.uniform(3, 8);
  o.position = around(s.marker.position, distance, rng);
  const Eigen::Vector2d to_marker = s.marker.position - o.position;
  o.heading_deg = std::atan2(to_marker.y(), to_marker.x()) * 180 / std::numbers::pi;
  const auto speed = range_of("dynamic_objects", kDynamic[i], "speed", 0);
  const double arrival = rng.uniform(0.15, 0.5) * s.time_limit;
  o.speed = std::clamp(distance / arrival, speed.first, speed.second);
  o.motion = MotionKind::Line;  // decode() makes it External for rlaga
  o.extent = distance + 3;
  o.altitude = o.kind == DynamicKind::Bird ? rng.uniform(3, 8) : 0.0;
  s.dynamic_objects.insert(s.dynamic_objects.begin(), o);
}

void add_static(scenario::Scenario& s, std::size_t i, Rng& rng) {
  scenario::StaticObject o;
  o.kind = static_cast<StaticKind>(i);
  for (int j = 0; j < 3; ++j) o.size[j] = severe(range_of("static_objects", kStatic[i], "size", j), false, rng);
  // Its footprint's edge 0.3–1.5 m beyond the marker's half diagonal, on
  // the side away from the drone's start (within ±90°): decode() drops an
  // object the drone would start inside (a tall tree's crown).
  // A pole is round (decode()'s repair 2) and a tree's footprint is its crown.
  const bool round = o.kind == StaticKind::Pole || o.kind == StaticKind::Tree;
  if (o.kind == StaticKind::Pole) o.size[1] = o.size[0];
  const double reach = round ? 0.5 * o.size[0] : 0.5 * std::hypot(o.size[0], o.size[1]);
  const Eigen::Vector2d away = s.marker.position - s.drone.position.head<2>();
  const double a = std::atan2(away.y(), away.x()) + rng.uniform(-0.5, 0.5) * std::numbers::pi;
  o.position = s.marker.position +
               (0.75 * s.marker.size + reach + rng.uniform(0.3, 1.5)) * Eigen::Vector2d(std::cos(a), std::sin(a));
  o.yaw_deg = rng.uniform(-180, 180);
  s.static_objects.insert(s.static_objects.begin(), o);
}

}  // namespace

std::vector<std::string> cover_conditions(const ChromosomeOptions& options) {
  std::vector<std::string> out;
  for (const Condition& c : conditions(options)) out.push_back(name_of(c));
  return out;
}

std::vector<CoverMember> cover_pool(const ChromosomeLayout& layout, std::uint64_t seed, int first, int n,
                                    Background background) {
  const std::vector<Condition> list = conditions(layout.options());
  std::vector<CoverMember> out;
  for (int k = first; k < first + n; ++k) {
    Rng rng(seed, kCoverStream + static_cast<std::uint64_t>(k));
    scenario::Scenario s = layout.decode(layout.draw(rng.next() >> 11));
    const Condition& c = list[static_cast<std::size_t>(k) % list.size()];
    if (background == Background::Benign || (background == Background::Mixed && c.kind == Kind::Dynamic)) {
      make_benign(s, rng);
    }
    switch (c.kind) {
      case Kind::Weather: {
        const WeatherCondition& w = kWeather[c.index];
        const scenario::PropertyBound& b = scenario::property_bound(w.key);
        s.weather.*w.field = severe({b.min, b.max}, w.low_is_severe, rng);
        break;
      }
      case Kind::Distractor:
        add_distractor(s, c.index, rng);
        break;
      case Kind::Dynamic:
        add_dynamic(s, c.index, rng);
        break;
      case Kind::Static:
        add_static(s, c.index, rng);
        break;
    }
    out.push_back({name_of(c), std::move(s)});
  }
  return out;
}

}  // namespace touchdown::search::detail
