// The sweep's decisions, frozen (issue 35): on every bundled terrain and on
// the terrains of the sweep tests, the safe/unsafe verdict and the reason per
// heading and the chosen heading must stay what they were before the twin
// was made faster. tests/twin/golden/sweep_decisions.txt holds them, written
// by this test from the code before the change:
//
//   TOUCHDOWN_GOLDEN_WRITE=1 build/tests/twin_golden_tests
//
// rewrites the file (only do that when a change is meant to alter
// decisions, and say why in docs/benchmarks.md). Scores are kept too and
// the test prints how far each heading's S moved, without failing on it.
#include <gtest/gtest.h>

#include <cmath>
#include <cstdlib>
#include <fstream>
#include <iomanip>
#include <iostream>
#include <map>
#include <sstream>
#include <string>

#include "touchdown/core/units.hpp"
#include "touchdown/terrain/extrinsics.hpp"
#include "touchdown/twin/sweep.hpp"
#include "twin_test_util.hpp"

namespace td = touchdown;
namespace tw = touchdown::twin;

namespace {

const std::string kGolden = std::string(TOUCHDOWN_SOURCE_DIR) + "/tests/twin/golden/sweep_decisions.txt";

// A heading's decision as one word: "safe", or the reason with '_' for spaces.
std::string verdict(const tw::HeadingScore& h) {
  if (h.safe) return "safe";
  std::string r(tw::to_string(h.reason));
  for (char& c : r) c = c == ' ' ? '_' : c;
  return r;
}

// "name best_index n  verdict:score ..." (scores to 1e-6 rad).
std::string line_of(const std::string& name, const tw::SweepResult& r) {
  std::ostringstream s;
  s << name << ' ' << r.best << ' ' << r.headings.size();
  for (const auto& h : r.headings) s << ' ' << verdict(h) << ':' << std::fixed << std::setprecision(6) << h.score;
  return s.str();
}

struct Decisions {
  int best = -1;
  std::vector<std::string> verdicts;
  std::vector<double> scores;
};

Decisions parse(const std::string& line) {
  std::istringstream s(line);
  std::string name;
  std::size_t n = 0;
  Decisions d;
  s >> name >> d.best >> n;
  for (std::size_t k = 0; k < n; ++k) {
    std::string item;
    s >> item;
    const auto colon = item.rfind(':');
    d.verdicts.push_back(item.substr(0, colon));
    d.scores.push_back(std::stod(item.substr(colon + 1)));
  }
  return d;
}

std::map<std::string, std::string> read_golden() {
  std::map<std::string, std::string> lines;
  std::ifstream in(kGolden);
  for (std::string line; std::getline(in, line);) {
    if (line.empty() || line[0] == '#') continue;
    lines[line.substr(0, line.find(' '))] = line;
  }
  return lines;
}

// Compares (or, with TOUCHDOWN_GOLDEN_WRITE set, records) one case.
void check(const std::string& name, const tw::SweepResult& r) {
  ASSERT_TRUE(r.ok()) << r.message;
  const std::string now = line_of(name, r);
  if (std::getenv("TOUCHDOWN_GOLDEN_WRITE") != nullptr) {
    auto lines = read_golden();
    lines[name] = now;
    std::ofstream out(kGolden);
    out << "# case best_heading_index headings  verdict:S[rad] per heading (tests/twin/sweep_golden_test.cpp)\n";
    for (const auto& [key, line] : lines) out << line << '\n';
    GTEST_SKIP() << "wrote " << name << " to " << kGolden;
  }
  const auto lines = read_golden();
  const auto it = lines.find(name);
  ASSERT_NE(it, lines.end()) << name << " is not in " << kGolden;
  const Decisions was = parse(it->second), is = parse(now);
  ASSERT_EQ(was.verdicts.size(), is.verdicts.size()) << name;
  double moved = 0;
  std::size_t where = 0;
  for (std::size_t k = 0; k < is.verdicts.size(); ++k) {
    EXPECT_EQ(was.verdicts[k], is.verdicts[k]) << name << ": heading " << k;
    if (std::isfinite(was.scores[k]) && std::isfinite(is.scores[k]) && std::abs(was.scores[k] - is.scores[k]) > moved) {
      moved = std::abs(was.scores[k] - is.scores[k]);
      where = k;
    }
  }
  EXPECT_EQ(was.best, is.best) << name << ": the chosen heading";
  std::cout << name << ": largest change of S " << moved << " rad (heading " << where << ")\n";
}

tw::SweepResult bundled(const std::string& terrain, double x = 0.0, const std::string& airframe = "") {
  const std::string base = std::string(TOUCHDOWN_SOURCE_DIR) + "/data/terrains/" + terrain;
  const auto e = td::terrain::load_extrinsics(base + ".extrinsics.yaml");
  td::terrain::TerrainOptions cloud;
  cloud.T_world_camera = e.T_world_camera;
  cloud.T_body_camera = e.T_body_camera;
  tw::SweepOptions o;  // the app's defaults: 20 headings x 10 runs, seed 1
  o.landing_point = Eigen::Vector2d(x, 0.0);
  o.threads = 2;
  const tw::Airframe af =
      airframe.empty() ? tw::Airframe::f450()
                       : tw::load_airframe(std::string(TOUCHDOWN_SOURCE_DIR) + "/data/airframes/" + airframe + ".yaml");
  return tw::run_sweep(af, tw::load_terrain_model(base + ".pcd", cloud), o);
}

tw::SweepResult small(const std::shared_ptr<const tw::TerrainModel>& terrain, int headings, int runs) {
  tw::SweepOptions o;
  o.headings = headings;
  o.runs = runs;
  o.threads = 2;
  return tw::run_sweep(tw::Airframe::f450(), terrain, o);
}

}  // namespace

// The bundled terrains with the app's default options (what a user runs).
TEST(SweepGolden, Flat) { check("flat", bundled("flat")); }
TEST(SweepGolden, Incline) { check("incline", bundled("incline")); }
TEST(SweepGolden, Plateau) { check("plateau", bundled("plateau")); }
TEST(SweepGolden, Post) { check("post", bundled("post")); }
TEST(SweepGolden, Rubble) { check("rubble", bundled("rubble")); }
TEST(SweepGolden, SlopeGentle) { check("slope_gentle", bundled("slope_gentle")); }
TEST(SweepGolden, SlopeSteep) { check("slope_steep", bundled("slope_steep")); }
TEST(SweepGolden, Step) { check("step", bundled("step")); }
TEST(SweepGolden, StepDemo) { check("step_demo", bundled("step", 0.12)); }
// The airframe without landing gear, which lands on its body box (the box
// contacts' path).
TEST(SweepGolden, GearlessFlat) { check("gearless_flat", bundled("flat", 0.0, "gearless_quad")); }
TEST(SweepGolden, GearlessStepDemo) { check("gearless_step_demo", bundled("step", 0.12, "gearless_quad")); }

// The analytic terrains of tests/twin/sweep_test.cpp, at their sizes there.
TEST(SweepGolden, TestTerrains) {
  using td::kRadPerDeg;
  check("test_flat", small(td::test::flat_terrain(0.0), 6, 2));
  check("test_incline6", small(td::test::incline_terrain(6 * kRadPerDeg), 4, 3));
  check("test_incline32", small(td::test::incline_terrain(32 * kRadPerDeg), 4, 2));
  check("test_ledge",
        small(td::test::analytic_terrain([](double x, double) { return x > -0.12 ? 0.1 : 0.0; }, 1.0, 0.01), 4, 2));
  check("test_step15",
        small(td::test::analytic_terrain([](double x, double) { return x > 0 ? 0.15 : 0.0; }, 1.2, 0.02), 4, 1));
  check("test_incline10", small(td::test::incline_terrain(10 * kRadPerDeg), 5, 2));
}
