// Airframes without landing gear (issue 11, item 2): they stand on the
// bottom face of their body box. Oracle tests: the support polygon is the
// body's bottom face, the tip-over threshold is atan(half width / CoM height)
// and physics agrees with it, a landing on level ground rests on the body
// with no strike, and geometry that would rest on propellers is refused.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <filesystem>
#include <string>

#include "sweep_golden.hpp"
#include "test_util.hpp"
#include "touchdown/core/units.hpp"
#include "touchdown/twin/airframe.hpp"
#include "touchdown/twin/landing.hpp"
#include "touchdown/twin/sweep.hpp"
#include "touchdown/twin/threshold.hpp"
#include "twin_test_util.hpp"

namespace tw = touchdown::twin;
using touchdown::kRadPerDeg;

namespace {

using touchdown::test::replace;

const std::filesystem::path kYamlPath =
    std::filesystem::path(TOUCHDOWN_SOURCE_DIR) / "data/airframes/gearless_quad.yaml";

tw::Airframe gearless() { return tw::load_airframe(kYamlPath); }

std::string gearless_error(const std::string& yaml) {
  return touchdown::test::error_of([&] { (void)tw::parse_airframe(yaml, "gearless.yaml"); });
}

}  // namespace

TEST(Gearless, StandsOnTheBottomCornersOfItsBody) {
  const auto a = gearless();
  EXPECT_FALSE(a.has_landing_gear());
  EXPECT_TRUE(a.legs.empty());
  EXPECT_DOUBLE_EQ(a.ground_z(), -0.025);
  const auto s = a.support_points();
  ASSERT_EQ(s.size(), 4U);
  for (const auto& p : s) {
    EXPECT_DOUBLE_EQ(std::abs(p.x()), 0.06);
    EXPECT_DOUBLE_EQ(std::abs(p.y()), 0.04);
    EXPECT_DOUBLE_EQ(p.z(), -0.025);
  }
  EXPECT_DOUBLE_EQ(a.support_radius(), 0.0);
  // No gear mass: body plus four motors.
  EXPECT_NEAR(a.total_mass(), 0.30 + 4 * 0.03, 1e-12);
  // Square motor layout on a 0.12 × 0.08 body: a half turn maps it onto itself.
  EXPECT_EQ(a.symmetry_order(), 2);
}

TEST(Gearless, TipThresholdIsAtanOfHalfWidthOverCentreOfMassHeight) {
  const auto a = gearless();
  const auto t = tw::compute_safety_threshold(a);
  const double h = a.centre_of_mass().z() - a.ground_z();
  // The narrow side: the bottom edges at y = ±0.04.
  EXPECT_NEAR(t.tip_rad, std::atan2(0.04, h), 1e-12);
  const auto s = a.support_points();
  EXPECT_NEAR(std::abs(s[t.tip_foot_a].y()), 0.04, 1e-12);
  EXPECT_NEAR(s[t.tip_foot_a].y(), s[t.tip_foot_b].y(), 1e-12);
  EXPECT_GT(t.prop_strike_rad, 0.0);
}

// Released tilted about the tip edge by threshold − 2° it rocks back onto
// its bottom face; by threshold + 2° it falls over. A taller, narrower body
// than the bundled one, so that tipping (not a propeller) sets the threshold.
TEST(Gearless, PhysicsRocksBackBelowTheThresholdAndFallsAbove) {
  auto a = gearless();
  a.body_size = {0.12, 0.05, 0.10};
  a.motor_z = 0.04;
  std::string why;
  ASSERT_TRUE(a.validate(&why)) << why;
  const auto t = tw::compute_safety_threshold(a);
  ASSERT_LT(t.tip_rad, t.prop_strike_rad);
  tw::SimulationOptions opt;
  opt.tip_nutation = t.tip_rad;
  const tw::LandingSimulator sim(a, touchdown::test::flat_terrain(0.0), opt);
  const double deg = kRadPerDeg;
  const auto below = sim.release(tw::pose_tilted_about_edge(a, t.tip_foot_a, t.tip_foot_b, t.value() - 2 * deg), 1.0);
  ASSERT_EQ(below.status, tw::RunStatus::Settled);
  EXPECT_LT(below.nutation, 0.02);
  EXPECT_TRUE(below.all_feet_in_contact) << "resting on its bottom face";
  EXPECT_FALSE(below.strike()) << "the body is what it stands on" << below.prop_strike << below.arm_strike
                               << below.body_strike;
  const auto above = sim.release(tw::pose_tilted_about_edge(a, t.tip_foot_a, t.tip_foot_b, t.value() + 2 * deg), 1.0);
  ASSERT_EQ(above.status, tw::RunStatus::Settled);
  EXPECT_GT(above.nutation, t.value() + 0.1);
  EXPECT_TRUE(above.tipped);
  EXPECT_FALSE(above.all_feet_in_contact) << "lying on its side, not its bottom";
}

// The bundled airframe's threshold is its propeller strike: tilted about
// the narrow edge to 2° short of it, no propeller touches and it rocks back.
TEST(Gearless, PropellersClearTheGroundJustBelowTheStrikeAngle) {
  const auto a = gearless();
  const auto t = tw::compute_safety_threshold(a);
  ASSERT_LT(t.prop_strike_rad, t.tip_rad);
  tw::SimulationOptions opt;
  opt.tip_nutation = t.tip_rad;
  const tw::LandingSimulator sim(a, touchdown::test::flat_terrain(0.0), opt);
  const auto r =
      sim.release(tw::pose_tilted_about_edge(a, t.tip_foot_a, t.tip_foot_b, t.prop_strike_rad - 2 * kRadPerDeg), 1.0);
  ASSERT_EQ(r.status, tw::RunStatus::Settled);
  EXPECT_FALSE(r.strike()) << r.prop_strike << r.arm_strike << r.body_strike;
  EXPECT_LT(r.nutation, 0.02);
}

TEST(Gearless, LandsOnLevelGroundOnItsBodyWithoutStrikes) {
  const auto a = gearless();
  tw::SimulationOptions opt;
  opt.tip_nutation = tw::compute_safety_threshold(a).tip_rad;
  const tw::LandingSimulator sim(a, touchdown::test::flat_terrain(0.0), opt);
  for (double h : {0.0, 30.0, 77.0, 135.0}) {
    tw::LandingConditions c;
    c.heading = h * kRadPerDeg;
    const auto r = sim.land(c);
    ASSERT_EQ(r.status, tw::RunStatus::Settled) << h << " " << r.message;
    EXPECT_LT(r.nutation, 0.02) << h;
    EXPECT_TRUE(r.all_feet_in_contact) << h;
    EXPECT_FALSE(r.strike()) << h;
    // The body's bottom rests on the ground.
    EXPECT_NEAR(r.final_position.z(), a.centre_of_mass().z() - a.ground_z(), 0.003) << h;
  }
}

// A flat bottom face on a plane rests at the plane's angle at any heading.
TEST(Gearless, InclineGivesItsAngle) {
  const auto a = gearless();
  tw::SimulationOptions opt;
  opt.tip_nutation = tw::compute_safety_threshold(a).tip_rad;
  for (double alpha : {5.0, 10.0}) {
    const tw::LandingSimulator sim(a, touchdown::test::incline_terrain(alpha * kRadPerDeg), opt);
    for (double h : {0.0, 45.0, 90.0}) {
      tw::LandingConditions c;
      c.heading = h * kRadPerDeg;
      c.ground_z = std::tan(alpha * kRadPerDeg) * 0.1;
      const auto r = sim.land(c);
      ASSERT_EQ(r.status, tw::RunStatus::Settled) << alpha << " " << h << " " << r.message;
      EXPECT_NEAR(r.nutation, alpha * kRadPerDeg, 0.02) << "incline " << alpha << " deg, heading " << h;
      EXPECT_TRUE(r.all_feet_in_contact) << alpha << " " << h;
      EXPECT_FALSE(r.strike()) << alpha << " " << h;
    }
  }
}

TEST(Gearless, SweepOnLevelGroundIsSafeAndOverAStepEdgeIsNot) {
  const auto a = gearless();
  tw::SweepOptions o;
  o.headings = 6;
  o.runs = 4;
  o.seed = 3;
  const auto flat = tw::run_sweep(a, touchdown::test::flat_terrain(0.0), o);
  ASSERT_TRUE(flat.ok()) << flat.message;
  touchdown::test::check_golden("gearless_test_flat", flat);
  for (const auto& h : flat.headings) {
    EXPECT_EQ(h.invalid_runs, 0) << h.yaw;
    EXPECT_LT(h.score, 0.05) << h.yaw;
    EXPECT_EQ(h.body_strike_runs, 0) << h.yaw;
  }
  // A 6 cm step under the middle of the body: the body lands on the step's
  // edge, half of it over the drop, and tips towards it.
  const auto step = touchdown::test::analytic_terrain([](double x, double) { return x > 0 ? 0.06 : 0.0; }, 1.0, 0.01);
  o.landing_point = {0.0, 0.0};
  const auto edge = tw::run_sweep(a, step, o);
  ASSERT_TRUE(edge.ok()) << edge.message;
  touchdown::test::check_golden("gearless_test_step_edge", edge);
  const bool any_tilted = std::any_of(edge.headings.begin(), edge.headings.end(),
                                      [](const tw::HeadingScore& h) { return h.score > 0.2 || h.invalid_runs > 0; });
  EXPECT_TRUE(any_tilted);
}

TEST(Gearless, AirframesThatWouldRestOnPropellersOrArmsAreRefused) {
  const std::string y = touchdown::test::read_text(kYamlPath);
  ASSERT_EQ(gearless_error(y), "<no error>");
  // Motors hung below the body: the props' underside is below its bottom.
  const auto low = gearless_error(replace(y, "  motor_z: 0.0", "  motor_z: -0.06"));
  EXPECT_NE(low.find("landing_gear: none"), std::string::npos) << low;
  EXPECT_NE(low.find("would rest on it"), std::string::npos) << low;
  // Anything but a mapping or `none`.
  const auto word = gearless_error(replace(y, "landing_gear: none", "landing_gear: skids"));
  EXPECT_NE(word.find("landing_gear"), std::string::npos) << word;
  EXPECT_NE(word.find("none"), std::string::npos) << word;
  // Motors bunched at the front (arms at 10°, 100°, 260°, 350°, heavy
  // motors): the centre of mass leaves the body's bottom face.
  auto front_heavy = gearless();
  front_heavy.arm_angles_deg = {10, 100, 260, 350};
  front_heavy.motor_radius = 0.4;
  front_heavy.motor_mass = 0.2;
  std::string why;
  EXPECT_GT(front_heavy.centre_of_mass().x(), 0.06);
  EXPECT_FALSE(front_heavy.validate(&why));
  EXPECT_NE(why.find("centre of mass"), std::string::npos) << why;
  EXPECT_NE(why.find("body.size"), std::string::npos) << why;
}
