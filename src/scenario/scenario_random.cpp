// Random landing scenarios drawn from the bounds table (docs/formats.md,
// "Landing scenarios").
#include <Eigen/Geometry>
#include <algorithm>
#include <cmath>
#include <cstdint>
#include <numbers>
#include <string>

#include "scenario/scenario_internal.hpp"
#include "touchdown/core/error.hpp"
#include "touchdown/core/random.hpp"
#include "touchdown/pose/sim/aruco_dictionary.hpp"
#include "touchdown/scenario/scenario.hpp"

namespace touchdown::scenario {

using namespace detail;  // NOLINT(google-build-using-namespace): the module's own private helpers

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
  for (int j = 0; j < 3; ++j) {
    const PropertyBound* b = find_kind_bound(list, kind, "size", j);
    TD_ASSERT(b);  // every kind has its size rows
    size[j] = d.uniform(b->min, b->max, 100);
  }
  return size;
}

void draw_distractors(Drawer& d, Scenario& s, const pose::ArucoDictionaryInfo& dict) {
  const int n = d.integer(0, 3);
  const Footprint target = marker_square(s.marker.position, s.marker.yaw_deg, s.marker.size, dict.bits);
  for (int k = 0; k < n; ++k) {
    Distractor x;
    const double kind = d.fraction();
    x.kind = kind < 0.4 ? DistractorKind::WrongId : kind < 0.7 ? DistractorKind::Lookalike : DistractorKind::Pattern;
    if (x.kind == DistractorKind::WrongId) {
      x.id = d.integer(0, dict.codes - 2);
      if (x.id >= s.marker.id) ++x.id;  // every id but the marker's
    } else {
      x.id = d.integer(0, static_cast<int>(kMaxMarkerId));
    }
    x.flipped_bits = x.kind == DistractorKind::Lookalike ? d.integer(1, 4) : 1;
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
    o.kind = static_cast<StaticKind>(d.integer(0, static_cast<int>(EnumNames<StaticKind>::names.size()) - 1));
    o.position = {d.uniform(-12, 12, 100), d.uniform(-12, 12, 100)};
    o.yaw_deg = d.angle();
    o.size = draw_size(d, "static_objects", to_string(o.kind));
    if (o.kind == StaticKind::Pole) o.size.y() = o.size.x();
    // A tree's trunk is at most half its crown (both rounded to 1 cm, the
    // crown at least 1 m: the trunk stays thinner).
    if (o.kind == StaticKind::Tree) o.size.y() = std::min(o.size.y(), std::round(o.size.x() * 50) / 100);
    s.static_objects.push_back(o);
  }
}

void draw_dynamic_objects(Drawer& d, Scenario& s) {
  const int n = d.integer(0, 3);
  for (int k = 0; k < n; ++k) {
    DynamicObject o;
    const double kind = d.fraction();
    o.kind = kind < 0.5 ? DynamicKind::Person : kind < 0.75 ? DynamicKind::Dog : DynamicKind::Bird;
    const std::string_view name = to_string(o.kind);
    o.size = draw_size(d, "dynamic_objects", name);
    o.position = {d.uniform(-12, 12, 100), d.uniform(-12, 12, 100)};
    o.altitude = d.in_row(kind_key("dynamic_objects", name, "altitude"), 100);
    o.heading_deg = d.angle();
    // From a stroll to the kind's top speed.
    o.speed = d.uniform(0.2 * property_bound(kind_key("dynamic_objects", name, "speed")).max,
                        property_bound(kind_key("dynamic_objects", name, "speed")).max, 100);
    // Scripted motions only: `external` needs a controller.
    o.motion = o.kind == DynamicKind::Bird ? (d.chance(0.5) ? MotionKind::Line : MotionKind::Circle)
                                           : static_cast<MotionKind>(d.integer(0, 3));
    o.extent = d.uniform(2, 10, 100);
    s.dynamic_objects.push_back(o);
  }
}

void draw_weather(Drawer& d, Scenario& s) {
  Weather& w = s.weather;
  const bool lawn = s.map == MapKind::Lawn;
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
  const auto* dict = pose::find_aruco_dictionary(s.marker.dictionary);
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
  return random_scenario(seed, (rng.next() >> 63) ? MapKind::Lawn : MapKind::Ground);
}

}  // namespace touchdown::scenario
