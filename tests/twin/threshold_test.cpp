#include "touchdown/twin/threshold.hpp"

#include <gtest/gtest.h>

#include "touchdown/core/units.hpp"
#include "touchdown/twin/landing.hpp"
#include "twin_test_util.hpp"

namespace tw = touchdown::twin;

TEST(SafetyThreshold, TipAngleIsAtanOfHalfTrackOverHeight) {
  const auto a = tw::Airframe::f450();
  const auto t = tw::compute_safety_threshold(a);
  // The narrow side: the feet are ±0.08 m from the centre line.
  const double h = a.centre_of_mass().z() - a.foot_z;
  EXPECT_NEAR(t.tip_rad, std::atan2(0.08, h), 1e-12);
  EXPECT_NEAR(std::abs(a.foot(t.tip_foot_a).centre.y()), 0.08, 1e-12);
  EXPECT_NEAR(a.foot(t.tip_foot_a).centre.y(), a.foot(t.tip_foot_b).centre.y(), 1e-12);
  // Propellers clear the ground until well after the tip-over angle.
  EXPECT_GT(t.prop_strike_rad, t.tip_rad);
  EXPECT_DOUBLE_EQ(t.value(), t.tip_rad);
}

TEST(SafetyThreshold, PropStrikeAngleIsWhereTheDiskTouches) {
  // Pivoting about the tip edge by the strike angle puts a propeller's
  // lowest point within a millimetre of the ground; 1° less clears it.
  const auto a = tw::Airframe::f450();
  auto wide = a;  // wide gear, so the propeller strike comes first
  wide.legs = {{0.05, 0.05}, {0.05, -0.05}, {-0.05, -0.05}, {-0.05, 0.05}};
  wide.gear_top_z = -0.03;
  wide.foot_z = -0.08;
  const auto t = tw::compute_safety_threshold(wide);
  EXPECT_LT(t.prop_strike_rad, t.tip_rad);
  EXPECT_DOUBLE_EQ(t.value(), t.prop_strike_rad);
  auto lowest_prop = [&](double angle) {
    double best = 1e9;
    for (std::size_t e = 0; e < 4; ++e) {
      const auto T = tw::pose_tilted_about_edge(wide, e, (e + 1) % 4, angle);
      for (std::size_t i = 0; i < 4; ++i) {
        const auto d = wide.propeller(i);
        const Eigen::Vector3d c = T * d.centre, n = T.linear() * d.axis;
        best = std::min(best, c.z() - d.radius * std::sqrt(1 - n.z() * n.z()) - d.half_thickness * std::abs(n.z()));
      }
    }
    return best;
  };
  // Edge pivots are one family of the directions searched: at the strike
  // angle no edge pivot puts a propeller below the ground.
  EXPECT_GT(lowest_prop(t.prop_strike_rad - 0.02), 0.0);
}

// Physics validation of the threshold: released at rest on level ground,
// tilted about the tip edge by threshold − 2° the twin rocks back onto its
// feet; by threshold + 2° it falls over.
TEST(SafetyThreshold, PhysicsRocksBackBelowAndFallsAbove) {
  const auto a = tw::Airframe::f450();
  const auto t = tw::compute_safety_threshold(a);
  tw::SimulationOptions opt;
  opt.tip_nutation = t.tip_rad;
  const tw::LandingSimulator sim(a, touchdown::test::flat_terrain(0.0), opt);
  const double deg = touchdown::kRadPerDeg;
  const auto below = sim.release(tw::pose_tilted_about_edge(a, t.tip_foot_a, t.tip_foot_b, t.value() - 2 * deg), 1.0);
  ASSERT_EQ(below.status, tw::RunStatus::Settled);
  EXPECT_LT(below.nutation, 0.02);
  EXPECT_TRUE(below.all_feet_in_contact);
  EXPECT_FALSE(below.tipped);
  const auto above = sim.release(tw::pose_tilted_about_edge(a, t.tip_foot_a, t.tip_foot_b, t.value() + 2 * deg), 1.0);
  ASSERT_EQ(above.status, tw::RunStatus::Settled);
  EXPECT_GT(above.nutation, t.value() + 0.1);
  EXPECT_TRUE(above.tipped);
  EXPECT_TRUE(above.strike());
}
