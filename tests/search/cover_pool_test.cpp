// The diversity option's covering seed pools (src/search/cover_pool.hpp):
// each member, after the chromosome's round trip (fit, decode), has its one
// condition at the severe end of its range, on a benign scene (nothing else)
// or on a randomly drawn one (everything else kept).
#include "search/cover_pool.hpp"

#include <gtest/gtest.h>

#include <cmath>
#include <numbers>
#include <set>

#include "touchdown/search/search.hpp"

namespace touchdown::search {
namespace {

using scenario::Scenario;
using scenario::Weather;

// The weather intensities (0 when benign) and their condition names.
const std::vector<std::pair<std::string, double Weather::*>>& intensities() {
  static const std::vector<std::pair<std::string, double Weather::*>> kIntensities{
      {"fog", &Weather::fog},
      {"rain", &Weather::rain},
      {"snowfall", &Weather::snow},
      {"dust", &Weather::dust},
      {"falling leaves", &Weather::leaves},
      {"wet ground", &Weather::ground_wetness},
      {"ground snow", &Weather::ground_snow},
      {"ground leaves", &Weather::ground_leaves}};
  return kIntensities;
}

double upper(const char* key) { return scenario::property_bound(key).max; }

std::size_t objects(const Scenario& s) {
  return s.dynamic_objects.size() + s.static_objects.size() + s.distractors.size();
}

// Every member of a pool on the given background, through the chromosome:
// its condition at its severe end; on a benign background, nothing else; on
// a drawn one, the condition's object first in its list; on a mixed one, a
// moving object's member as on a benign one, the others as on a drawn one.
void check_pool(detail::Background background) {
  for (bool drive : {false, true}) {
    ChromosomeOptions o;
    o.drive_objects = drive;
    const ChromosomeLayout layout(Scenario{}, o);
    const std::vector<std::string> names = detail::cover_conditions(o);
    ASSERT_EQ(names.size(), 20u);  // 10 weather and light, 3 distractor, 3 moving and 4 static kinds
    EXPECT_EQ(std::set<std::string>(names.begin(), names.end()).size(), 20u);
    EXPECT_EQ(names[0], "fog");  // alternating, the environment first
    EXPECT_EQ(names[1], "wrong_id near the marker");
    for (std::uint64_t seed : {1u, 2u, 3u}) {
      const auto pool = detail::cover_pool(layout, seed, 0, 20, background);
      ASSERT_EQ(pool.size(), 20u);
      for (std::size_t k = 0; k < pool.size(); ++k) {
        ASSERT_EQ(pool[k].condition, names[k]);
        // What the search runs: the member through the chromosome.
        const Scenario s = layout.decode(layout.fit(pool[k].scenario));
        const std::string& c = names[k];
        const Weather& w = s.weather;
        // Mixed: a moving object's member is on the benign background.
        const bool benign = background == detail::Background::Benign ||
                            (background == detail::Background::Mixed && c.ends_with(" at the marker"));
        SCOPED_TRACE(c + ", seed " + std::to_string(seed) + (benign ? ", benign" : ", drawn"));
        for (const auto& [name, field] : intensities()) {
          const std::string key = name == "snowfall"         ? "weather.snow"
                                  : name == "falling leaves" ? "weather.leaves"
                                  : name == "wet ground"     ? "weather.ground_wetness"
                                  : name == "ground snow"    ? "weather.ground_snow"
                                  : name == "ground leaves"  ? "weather.ground_leaves"
                                                             : "weather." + name;
          if (c == name) {
            EXPECT_GE(w.*field, 0.9 * upper(key.c_str()));
          } else if (benign) {
            EXPECT_EQ(w.*field, 0.0) << name;
          }
        }
        if (c == "low light") {
          EXPECT_LE(w.ambient, 0.15 + 0.1 * 0.85);
        } else if (benign) {
          EXPECT_GE(w.ambient, 0.85);
        }
        if (c == "low sun") {
          EXPECT_LE(w.sun_elevation_deg, 5 + 0.1 * 85);
        } else if (benign) {
          EXPECT_GE(w.sun_elevation_deg, 45);
        }
        const bool object = c.find(" the marker") != std::string::npos;
        if (benign) {
          EXPECT_EQ(objects(s), object ? 1u : 0u);
        }
        if (!object) continue;
        const std::string kind = c.substr(0, c.find(' '));
        if (c.ends_with(" near the marker")) {
          ASSERT_FALSE(s.distractors.empty());
          const auto& d = s.distractors[0];
          EXPECT_EQ(scenario::to_string(d.kind), kind);
          EXPECT_GE(d.size, 2 - 0.1 * 1.7);  // the top tenth of 0.3–2 m
          // Clear of the marker (with both white margins: 4X4 codes span 6
          // cells, the margins add 2) by at most 1 m: its centre no farther
          // than the two half diagonals and 1 m.
          const double r = (d.position - s.marker.position).norm();
          const double half_diagonal = 0.5 * std::sqrt(2.0) * 8.0 / 6.0;
          EXPECT_GE(r, 0.5 * 8.0 / 6.0 * (s.marker.size + d.size));  // not overlapping, even when aligned
          EXPECT_LE(r, half_diagonal * (s.marker.size + d.size) + 1.02);
        } else if (c.ends_with(" at the marker")) {
          ASSERT_FALSE(s.dynamic_objects.empty());
          const auto& d = s.dynamic_objects[0];
          EXPECT_EQ(scenario::to_string(d.kind), kind);
          // Walking in: 3–8 m out, heading for the marker, its line through it.
          const Eigen::Vector2d to_marker = s.marker.position - d.position;
          EXPECT_GE(to_marker.norm(), 3 - 1e-9);
          EXPECT_LE(to_marker.norm(), 8 + 1e-9);
          const double h = d.heading_deg * std::numbers::pi / 180;
          EXPECT_NEAR(to_marker.normalized().dot(Eigen::Vector2d(std::cos(h), std::sin(h))), 1.0, 1e-9);
          EXPECT_GE(d.extent, to_marker.norm());
          // It reaches the spot 15–50 % into the run: while a system lands.
          ASSERT_GT(d.speed, 0);
          const double arrival = to_marker.norm() / d.speed / s.time_limit;
          EXPECT_GE(arrival, 0.15 - 1e-6);
          EXPECT_LE(arrival, 0.5 + 1e-6);
          EXPECT_EQ(d.motion, drive ? scenario::MotionKind::External : scenario::MotionKind::Line);
          if (d.kind == scenario::DynamicKind::Bird) {
            EXPECT_GE(d.altitude, 3);
            EXPECT_LE(d.altitude, 8);
          }
        } else {
          ASSERT_TRUE(c.ends_with(" beside the marker"));
          ASSERT_FALSE(s.static_objects.empty());
          const auto& t = s.static_objects[0];
          EXPECT_EQ(scenario::to_string(t.kind), kind);
          const bool round = t.kind == scenario::StaticKind::Pole || t.kind == scenario::StaticKind::Tree;
          const double reach = round ? 0.5 * t.size[0] : 0.5 * std::hypot(t.size[0], t.size[1]);
          const double r = (t.position - s.marker.position).norm();
          EXPECT_GE(r, 0.75 * s.marker.size + reach + 0.3 - 1e-9);
          EXPECT_LE(r, 0.75 * s.marker.size + reach + 1.5 + 1e-9);
          const std::string row = "static_objects[" + kind + "].size";
          const auto* found = scenario::find_property_bound(row);  // a box's row is for every extent
          const auto h = found ? *found : scenario::property_bound(row + "[2]");
          EXPECT_GE(t.size[2], h.max - 0.1 * (h.max - h.min) - 1e-9);  // the top tenth of its heights
        }
      }
    }
  }
}

TEST(CoverPool, EachMemberIsBenignButForItsOneConditionAtItsSevereEnd) { check_pool(detail::Background::Benign); }

TEST(CoverPool, OnADrawnBackgroundEachMemberStillHasItsConditionAtItsSevereEnd) {
  check_pool(detail::Background::Drawn);
}

TEST(CoverPool, OnAMixedBackgroundEachMemberStillHasItsConditionAtItsSevereEnd) {
  check_pool(detail::Background::Mixed);
}

// Mixed: a moving object's member on the benign background (where the
// system descends, so a walk-in can meet it), every other on the drawn one.
TEST(CoverPool, AMixedBackgroundIsBenignForAMovingObjectAndDrawnForEveryOtherCondition) {
  const ChromosomeLayout layout(Scenario{});
  int moving = 0;
  for (std::uint64_t seed : {1u, 2u, 3u}) {
    const auto benign = detail::cover_pool(layout, seed, 0, 20, detail::Background::Benign);
    const auto drawn = detail::cover_pool(layout, seed, 0, 20, detail::Background::Drawn);
    const auto mixed = detail::cover_pool(layout, seed, 0, 20, detail::Background::Mixed);
    ASSERT_EQ(mixed.size(), 20u);
    for (std::size_t k = 0; k < mixed.size(); ++k) {
      SCOPED_TRACE(mixed[k].condition + ", seed " + std::to_string(seed));
      ASSERT_EQ(mixed[k].condition, drawn[k].condition);
      const std::string& c = mixed[k].condition;
      const bool walker = c == "person at the marker" || c == "dog at the marker" || c == "bird at the marker";
      moving += walker ? 1 : 0;
      const auto& same = walker ? benign[k] : drawn[k];
      const auto& other = walker ? drawn[k] : benign[k];
      EXPECT_EQ(layout.fit(mixed[k].scenario), layout.fit(same.scenario));
      EXPECT_NE(layout.fit(mixed[k].scenario), layout.fit(other.scenario));
    }
  }
  EXPECT_EQ(moving, 9);  // person, dog and bird on each of the 3 seeds
}

TEST(CoverPool, ADrawnBackgroundIsTheBenignMembersDrawWithItsWeatherAndObjectsKept) {
  const ChromosomeLayout layout(Scenario{});
  int other_weather = 0, other_objects = 0;
  for (std::uint64_t seed : {1u, 2u, 3u}) {
    const auto benign = detail::cover_pool(layout, seed, 0, 20, detail::Background::Benign);
    const auto drawn = detail::cover_pool(layout, seed, 0, 20, detail::Background::Drawn);
    for (std::size_t k = 0; k < drawn.size(); ++k) {
      const Scenario b = layout.decode(layout.fit(benign[k].scenario));
      const Scenario d = layout.decode(layout.fit(drawn[k].scenario));
      SCOPED_TRACE(drawn[k].condition + ", seed " + std::to_string(seed));
      // The same draw: its scene seed and marker.
      EXPECT_EQ(d.seed, b.seed);
      EXPECT_EQ(d.marker.position, b.marker.position);
      EXPECT_NE(layout.fit(d), layout.fit(b));
      const bool weather_condition = drawn[k].condition.find(" the marker") == std::string::npos;
      for (const auto& [name, field] : intensities()) {
        if (name != drawn[k].condition && d.weather.*field > 0) {
          ++other_weather;
          break;
        }
      }
      other_objects += objects(d) > (weather_condition ? 0u : 1u) ? 1 : 0;
    }
  }
  // Random sampling's draws have weather and objects in most scenes: so
  // must most drawn backgrounds (60 members), where benign ones have none.
  EXPECT_GE(other_weather, 40);
  EXPECT_GE(other_objects, 30);
}

TEST(CoverPool, KindRowsAreTheWholePropertysOrTheComponentsOrNone) {
  // A box's row covers every extent; a tree's are per component; a
  // distractor's size has only the envelope row.
  EXPECT_EQ(scenario::find_kind_bound("static_objects", "box", "size", 2),
            scenario::find_property_bound("static_objects[box].size"));
  EXPECT_EQ(scenario::find_kind_bound("static_objects", "tree", "size", 2),
            scenario::find_property_bound("static_objects[tree].size[2]"));
  EXPECT_EQ(scenario::find_kind_bound("static_objects", "tree", "size", 2)->max, 12);
  EXPECT_EQ(scenario::find_kind_bound("distractors", "lookalike", "size", 0), nullptr);
}

TEST(CoverPool, IsDeterministicPerSeedAndDiffersBetweenSeeds) {
  const ChromosomeLayout layout(Scenario{});
  const auto a = detail::cover_pool(layout, 5, 0, 20);
  const auto b = detail::cover_pool(layout, 5, 0, 20);
  const auto c = detail::cover_pool(layout, 6, 0, 20);
  for (std::size_t k = 0; k < a.size(); ++k) {
    EXPECT_EQ(layout.fit(a[k].scenario), layout.fit(b[k].scenario)) << k;
    EXPECT_NE(layout.fit(a[k].scenario), layout.fit(c[k].scenario)) << k;
  }
  // Members are indexed: a later slice is the same as the whole pool's tail.
  const auto tail = detail::cover_pool(layout, 5, 7, 3);
  for (std::size_t k = 0; k < tail.size(); ++k) EXPECT_EQ(layout.fit(tail[k].scenario), layout.fit(a[7 + k].scenario));
}

TEST(CoverPool, TheSourceChromosomeCoversWeatherAndMovingObjectsOnly) {
  const std::vector<std::string> names = detail::cover_conditions(ChromosomeOptions::source());
  ASSERT_EQ(names.size(), 13u);
  for (const std::string& n : names) {
    EXPECT_EQ(n.find("near the marker"), std::string::npos) << n;
    EXPECT_EQ(n.find("beside the marker"), std::string::npos) << n;
  }
  ChromosomeOptions none;
  none.dynamic_slots = none.static_slots = none.distractor_slots = 0;
  EXPECT_EQ(detail::cover_conditions(none).size(), 10u);
}

}  // namespace
}  // namespace touchdown::search
