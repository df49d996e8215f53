// The chromosome (chromosome.hpp; RLaGA Fig. 3): gene list, exact round
// trip at every bound, the fit checks of encode, the range checks and the
// repair rules of decode, and that random chromosomes always decode to
// valid scenarios.
#include "touchdown/search/chromosome.hpp"

#include <gtest/gtest.h>

#include <cmath>
#include <functional>

#include "touchdown/core/error.hpp"
#include "touchdown/core/random.hpp"

namespace touchdown::search {
namespace {

using scenario::DistractorKind;
using scenario::DynamicKind;
using scenario::MotionKind;
using scenario::Scenario;
using scenario::StaticKind;

Scenario base_scenario() {
  Scenario s;
  s.marker.dictionary = "4X4_50";
  s.marker.id = 5;
  s.drone.position = {-8, 0, 12};
  return s;
}

const NuclearGene& gene(const ChromosomeLayout& l, std::string_view name) {
  for (const NuclearGene& g : l.genes()) {
    if (g.name == name) return g;
  }
  throw InvalidArgument("no gene " + std::string(name));
}

double bound(std::string_view key, bool max) {
  const auto& b = scenario::property_bound(key);
  return max ? b.max : b.min;
}

// Every gene-carrying property at its min (max = false) or max; objects of
// every kind at their per-kind bounds.
Scenario extreme_scenario(bool max) {
  Scenario s = base_scenario();
  s.seed = max ? (std::uint64_t{1} << 53) : 0;
  scenario::Weather& w = s.weather;
  w.fog = bound("weather.fog", max);
  w.rain = bound("weather.rain", max);
  w.snow = bound("weather.snow", max);
  w.dust = bound("weather.dust", max);
  w.leaves = bound("weather.leaves", max);
  w.ground_wetness = bound("weather.ground_wetness", max);
  w.ground_snow = bound("weather.ground_snow", max);
  w.ground_leaves = bound("weather.ground_leaves", max);
  w.sun_elevation_deg = bound("weather.sun_elevation_deg", max);
  w.sun_azimuth_deg = bound("weather.sun_azimuth_deg", max);
  w.ambient = bound("weather.ambient", max);
  const double edge = bound("marker.position", max);
  s.marker.position = {edge, edge};
  const double angle = max ? 180 : -180;
  int motion = 0;
  for (const DynamicKind kind : {DynamicKind::Person, DynamicKind::Dog, DynamicKind::Bird}) {
    scenario::DynamicObject o;
    o.kind = kind;
    const std::string k = "dynamic_objects[" + std::string(scenario::to_string(kind)) + "].";
    for (int j = 0; j < 3; ++j) o.size[j] = bound(k + "size[" + std::to_string(j) + "]", max);
    o.speed = bound(k + "speed", max);
    o.altitude = bound(k + "altitude", max);
    o.position = {edge, -edge};
    o.heading_deg = angle;
    o.motion = static_cast<MotionKind>(motion++);
    o.extent = bound("dynamic_objects[].extent", max);
    s.dynamic_objects.push_back(o);
  }
  for (const StaticKind kind : {StaticKind::Box, StaticKind::Chair, StaticKind::Pole, StaticKind::Tree}) {
    scenario::StaticObject o;
    o.kind = kind;
    const std::string k = "static_objects[" + std::string(scenario::to_string(kind)) + "].size";
    for (int j = 0; j < 3; ++j) {
      o.size[j] = kind == StaticKind::Box ? bound(k, max) : bound(k + "[" + std::to_string(j) + "]", max);
    }
    o.position = {-edge, edge};  // the far corner from the drone
    o.yaw_deg = angle;
    s.static_objects.push_back(o);
  }
  // Distractors on the corners away from the marker, at their bounds.
  const std::array<Eigen::Vector2d, 3> spots{Eigen::Vector2d(-edge, -edge), Eigen::Vector2d(edge, -edge),
                                             Eigen::Vector2d(-edge, edge)};
  const std::array<DistractorKind, 3> kinds{DistractorKind::WrongId, DistractorKind::Lookalike,
                                            DistractorKind::Pattern};
  for (std::size_t i = 0; i < 3; ++i) {
    scenario::Distractor d;
    d.kind = kinds[i];
    d.position = spots[i];
    d.yaw_deg = angle;
    d.size = bound("distractors[].size", max);
    d.id = kinds[i] == DistractorKind::WrongId ? (max ? 49 : 0) : static_cast<int>(bound("distractors[].id", max));
    d.flipped_bits = static_cast<int>(bound("distractors[].flipped_bits", max));
    s.distractors.push_back(d);
  }
  return s;
}

TEST(Chromosome, GeneListFollowsFig3) {
  const ChromosomeLayout source(base_scenario(), ChromosomeOptions::source());
  // seed + 11 weather genes + marker + 6 dynamic slots of 8 genes.
  ASSERT_EQ(source.genes().size(), 1u + 11u + 1u + 6u * 8u);
  EXPECT_EQ(source.values(), 14 + 6 * 11);
  EXPECT_EQ(source.genes()[0].name, "seed");
  EXPECT_TRUE(source.genes()[0].integer);
  EXPECT_EQ(source.genes()[1].name, "weather.fog");
  EXPECT_EQ(source.genes()[11].name, "weather.ambient");
  const NuclearGene& marker = gene(source, "marker.position");
  EXPECT_EQ(marker.group, GeneGroup::Marker);
  EXPECT_EQ(marker.size, 2);
  EXPECT_EQ(marker.offset, 12);
  const NuclearGene& speed = gene(source, "dynamic_objects[2].speed");
  EXPECT_EQ(speed.slot, 2);
  EXPECT_EQ(speed.min, 0);
  EXPECT_EQ(speed.max, 12);  // the envelope; per-kind rows clamp in decode
  EXPECT_EQ(gene(source, "dynamic_objects[5].kind").max, 3);
  EXPECT_EQ(gene(source, "dynamic_objects[0].size").size, 3);
  int offset = 0;
  for (const NuclearGene& g : source.genes()) {
    EXPECT_EQ(g.offset, offset) << g.name;
    offset += g.size;
  }
  const ChromosomeLayout full(base_scenario());
  EXPECT_EQ(full.genes().size(), source.genes().size() + 12u * 4u + 4u * 6u);
  EXPECT_EQ(gene(full, "static_objects[11].kind").max, 4);
  EXPECT_TRUE(gene(full, "distractors[3].flipped_bits").integer);
  EXPECT_EQ(to_string(GeneGroup::DynamicObject), "dynamic_object");
  EXPECT_EQ(from_string<GeneGroup>("static_object"), GeneGroup::StaticObject);
}

TEST(Chromosome, RoundTripsEveryBoundExactly) {
  const ChromosomeLayout layout(base_scenario());
  for (const bool max : {false, true}) {
    const Scenario s = extreme_scenario(max);
    std::string why;
    ASSERT_TRUE(s.validate(&why)) << why;
    const Chromosome c = layout.encode(s);
    for (const NuclearGene& g : layout.genes()) {
      for (int j = 0; j < g.size; ++j) {
        const double v = c[static_cast<std::size_t>(g.offset + j)];
        EXPECT_TRUE(v >= g.min && v <= g.max) << g.name;
        if (g.integer) {
          EXPECT_EQ(v, std::floor(v)) << g.name;
        }
      }
    }
    EXPECT_EQ(c[0], max ? 9007199254740992.0 : 0.0);  // 2^53 exactly
    const Scenario back = layout.decode(c);
    EXPECT_TRUE(back == s) << "max = " << max;
    EXPECT_EQ(back.seed, s.seed);
    EXPECT_EQ(layout.encode(back), c);
    EXPECT_EQ(layout.dynamic_counts(c), (std::array<int, 3>{1, 1, 1}));
  }
}

TEST(Chromosome, DrivenObjectsRoundTripWithExternalMotion) {
  ChromosomeOptions o = ChromosomeOptions::source();
  o.drive_objects = true;
  const ChromosomeLayout layout(base_scenario(), o);
  Scenario s = base_scenario();
  s.dynamic_objects.resize(2);
  for (auto& d : s.dynamic_objects) d.motion = MotionKind::External;
  s.dynamic_objects[1].position = {3, 4};
  EXPECT_TRUE(layout.decode(layout.encode(s)) == s);
  s.dynamic_objects[0].motion = MotionKind::Line;
  EXPECT_THROW((void)layout.encode(s), InvalidArgument);
}

void expect_throw_naming(const std::function<void()>& f, const std::string& field) {
  try {
    f();
    ADD_FAILURE() << "no exception, expected one naming " << field;
  } catch (const InvalidArgument& e) {
    EXPECT_NE(std::string(e.what()).find(field), std::string::npos) << e.what();
  }
}

TEST(Chromosome, EncodeRejectsScenariosThatDoNotFit) {
  const ChromosomeLayout source(base_scenario(), ChromosomeOptions::source());
  Scenario s = base_scenario();
  s.marker.size = 1.5;
  expect_throw_naming([&] { (void)source.encode(s); }, "marker.size");
  s = base_scenario();
  s.static_objects.resize(1);
  s.static_objects[0].position = {10, 10};
  expect_throw_naming([&] { (void)source.encode(s); }, "static_objects");  // group off
  s = base_scenario();
  s.dynamic_objects.resize(1);
  s.dynamic_objects[0].motion = MotionKind::External;
  expect_throw_naming([&] { (void)source.encode(s); }, "dynamic_objects[0].motion");
  ChromosomeOptions two;
  two.dynamic_slots = 2;
  const ChromosomeLayout small(base_scenario(), two);
  s = base_scenario();
  s.dynamic_objects.resize(3);
  expect_throw_naming([&] { (void)small.encode(s); }, "dynamic_objects");
  s = base_scenario();
  s.drone.yaw_deg = 10;
  expect_throw_naming([&] { (void)small.encode(s); }, "drone");
}

TEST(Chromosome, GroupSwitchedOffKeepsTheBasesObjects) {
  Scenario base = base_scenario();
  base.static_objects.resize(1);
  base.static_objects[0].position = {10, 10};
  const ChromosomeLayout source(base, ChromosomeOptions::source());
  const Chromosome c = source.encode(base);
  EXPECT_TRUE(source.decode(c) == base);
  EXPECT_EQ(source.decode(c).static_objects.size(), 1u);
}

TEST(Chromosome, DecodeRejectsMalformedChromosomes) {
  const ChromosomeLayout layout(base_scenario());
  const Chromosome good = layout.encode(base_scenario());
  Chromosome c = good;
  c.pop_back();
  expect_throw_naming([&] { (void)layout.decode(c); }, "values");
  c = good;
  c[static_cast<std::size_t>(gene(layout, "weather.rain").offset)] = std::nan("");
  expect_throw_naming([&] { (void)layout.decode(c); }, "weather.rain: NaN");
  c = good;
  c[static_cast<std::size_t>(gene(layout, "marker.position").offset + 1)] = 21;
  expect_throw_naming([&] { (void)layout.decode(c); }, "marker.position[1]");
  c = good;
  c[static_cast<std::size_t>(gene(layout, "static_objects[3].kind").offset)] = 1.5;
  expect_throw_naming([&] { (void)layout.decode(c); }, "static_objects[3].kind: must be an integer");
  EXPECT_THROW((void)layout.normalised(c), InvalidArgument);
}

TEST(Chromosome, OptionsValidate) {
  std::string why;
  ChromosomeOptions o;
  EXPECT_TRUE(o.validate(&why));
  o.dynamic_slots = 7;
  EXPECT_FALSE(o.validate(&why));
  EXPECT_NE(why.find("dynamic_slots"), std::string::npos);
  o = {};
  o.static_slots = -1;
  EXPECT_FALSE(o.validate(&why));
  EXPECT_NE(why.find("static_slots"), std::string::npos);
  EXPECT_THROW(ChromosomeLayout(base_scenario(), o), InvalidArgument);
  Scenario bad = base_scenario();
  bad.time_limit = 1;
  EXPECT_THROW(ChromosomeLayout{bad}, InvalidArgument);
}

// Helpers to set a gene's values in a chromosome.
struct Editor {
  const ChromosomeLayout& layout;
  Chromosome c;
  void set(std::string_view name, std::initializer_list<double> v) {
    const NuclearGene& g = gene(layout, name);
    int j = 0;
    for (const double x : v) c[static_cast<std::size_t>(g.offset + j++)] = x;
  }
};

TEST(Chromosome, DecodeRepairsByTheDocumentedRules) {
  const ChromosomeLayout layout(base_scenario());
  Editor e{layout, layout.encode(base_scenario())};
  // Slot 1 present after an absent slot 0: becomes dynamic_objects[0].
  e.set("dynamic_objects[1].kind", {1});  // person
  e.set("dynamic_objects[1].speed", {10});
  e.set("dynamic_objects[1].size", {2, 2, 2});
  e.set("dynamic_objects[1].altitude", {5});
  e.set("dynamic_objects[2].kind", {3});  // bird
  e.set("dynamic_objects[2].altitude", {0});
  // A pole with two diameters, a tree with a trunk as thick as its crown,
  // a tree over the drone's start (-8, 0, 12) reaching within 1 m of it.
  e.set("static_objects[0].kind", {3});
  e.set("static_objects[0].position", {10, 10});
  e.set("static_objects[0].size", {0.2, 0.4, 5});
  e.set("static_objects[1].kind", {4});
  e.set("static_objects[1].position", {-10, 10});
  e.set("static_objects[1].size", {1, 1, 5});
  e.set("static_objects[2].kind", {4});
  e.set("static_objects[2].position", {-8, 0});
  e.set("static_objects[2].size", {4, 0.5, 12});
  // A wrong_id showing the marker's id (5), one beyond the dictionary, and
  // a pattern over the marker (at the origin).
  e.set("distractors[0].kind", {1});
  e.set("distractors[0].position", {5, 5});
  e.set("distractors[0].id", {5});
  e.set("distractors[1].kind", {1});
  e.set("distractors[1].position", {-5, -5});
  e.set("distractors[1].id", {700});
  e.set("distractors[2].kind", {3});
  e.set("distractors[2].position", {0.5, 0});
  const Scenario s = layout.decode(e.c);
  std::string why;
  ASSERT_TRUE(s.validate(&why)) << why;
  ASSERT_EQ(s.dynamic_objects.size(), 2u);
  EXPECT_EQ(s.dynamic_objects[0].kind, DynamicKind::Person);
  EXPECT_EQ(s.dynamic_objects[0].speed, 2.5);
  EXPECT_EQ(s.dynamic_objects[0].size, Eigen::Vector3d(0.6, 0.7, 2));
  EXPECT_EQ(s.dynamic_objects[0].altitude, 0);
  EXPECT_EQ(s.dynamic_objects[1].altitude, 2);
  ASSERT_EQ(s.static_objects.size(), 2u);  // the tree over the drone's start dropped
  EXPECT_EQ(s.static_objects[0].size, Eigen::Vector3d(0.2, 0.2, 5));
  EXPECT_EQ(s.static_objects[1].size, Eigen::Vector3d(1, 0.5, 5));
  ASSERT_EQ(s.distractors.size(), 2u);  // the pattern over the marker dropped
  EXPECT_EQ(s.distractors[0].id, 6);
  EXPECT_EQ(s.distractors[1].id, 49);
  // The repaired scenario encodes to a chromosome without the repairs.
  const Chromosome repaired = layout.encode(s);
  EXPECT_NE(repaired, e.c);
  EXPECT_TRUE(layout.decode(repaired) == s);
  EXPECT_EQ(layout.dynamic_counts(e.c), (std::array<int, 3>{1, 0, 1}));
}

TEST(Chromosome, RandomChromosomesAlwaysDecodeToValidScenarios) {
  const ChromosomeLayout layout(base_scenario());
  Rng rng(32, 1);
  for (int trial = 0; trial < 300; ++trial) {
    Chromosome c(static_cast<std::size_t>(layout.values()));
    for (const NuclearGene& g : layout.genes()) {
      for (int j = 0; j < g.size; ++j) {
        const auto i = static_cast<std::size_t>(g.offset + j);
        c[i] = g.integer ? g.min + static_cast<double>(rng.next() % static_cast<std::uint64_t>(g.max - g.min + 1))
                         : rng.uniform(g.min, g.max);
      }
    }
    const Scenario s = layout.decode(c);
    std::string why;
    ASSERT_TRUE(s.validate(&why)) << "trial " << trial << ": " << why;
    const Chromosome again = layout.encode(s);  // fits the layout
    EXPECT_TRUE(layout.decode(again) == s) << trial;
  }
}

TEST(Chromosome, DrawIsDeterministicAndNeedsNoRepair) {
  const ChromosomeLayout layout(base_scenario());
  const ChromosomeLayout source(base_scenario(), ChromosomeOptions::source());
  for (std::uint64_t seed = 0; seed < 40; ++seed) {
    const Chromosome c = layout.draw(seed);
    EXPECT_EQ(c, layout.draw(seed));
    EXPECT_EQ(layout.encode(layout.decode(c)), c) << seed;
    const Scenario s = source.decode(source.draw(seed));
    EXPECT_TRUE(s.static_objects.empty());
    EXPECT_EQ(s.marker.id, 5);  // from the base
    EXPECT_EQ(s.weather.fog, scenario::random_scenario(seed, s.map).weather.fog);
  }
  EXPECT_NE(layout.draw(1), layout.draw(2));
}

TEST(Chromosome, NormalisedMapsRangesToUnitAndZeroesAbsentSlots) {
  const ChromosomeLayout layout(base_scenario());
  Editor e{layout, layout.encode(base_scenario())};
  e.set("weather.fog", {0.1});
  e.set("marker.position", {-20, 10});
  e.set("dynamic_objects[0].kind", {2});
  e.set("dynamic_objects[0].position", {0, 20});
  e.set("dynamic_objects[1].position", {5, 5});  // slot 1 absent: unused values
  const std::vector<double> n = layout.normalised(e.c);
  const auto at = [&](std::string_view name, int j = 0) {
    return n[static_cast<std::size_t>(gene(layout, name).offset + j)];
  };
  EXPECT_DOUBLE_EQ(at("weather.fog"), 0.25);
  EXPECT_EQ(at("marker.position", 0), 0.0);
  EXPECT_EQ(at("marker.position", 1), 0.75);
  EXPECT_DOUBLE_EQ(at("dynamic_objects[0].kind"), 2.0 / 3.0);
  EXPECT_EQ(at("dynamic_objects[0].position", 1), 1.0);
  EXPECT_EQ(at("dynamic_objects[1].position", 0), 0.0);
  EXPECT_EQ(at("dynamic_objects[1].position", 1), 0.0);
  for (const double v : n) EXPECT_TRUE(v >= 0 && v <= 1);
}

}  // namespace
}  // namespace touchdown::search
