// The drone's stance (mission/stance.hpp) against closed forms: the strike
// tilt of a "+" quadrotor about its arm axis, the support polygon's
// inradius; and the upset ratio's three limits.
#include "mission/stance.hpp"

#include <gtest/gtest.h>

#include <cmath>
#include <numbers>

#include "touchdown/twin/airframe.hpp"
#include "touchdown/twin/flight_control.hpp"

namespace tdm = touchdown::mission;
namespace tw = touchdown::twin;

namespace {

// Arms along ±x and ±y (motors 0.2 m out at z 0, 0.1 m propellers 0.02 m
// above them), feet under the arms 0.1 m out at z -0.1 (radius 0.01).
tw::Airframe plus_quad() {
  tw::Airframe af;
  af.arm_angles_deg = {0, 90, 180, 270};
  af.motor_radius = 0.2;
  af.motor_z = 0;
  af.arm_radius = 0.005;
  af.prop_radius = 0.1;
  af.prop_height = 0.02;
  af.prop_thickness = 0.004;
  af.body_size = {0.05, 0.05, 0.05};
  af.gear_top_z = -0.025;
  af.foot_z = -0.1;
  af.foot_radius = 0.01;
  af.leg_radius = 0.004;
  af.legs = {{0.1, 0}, {0, 0.1}, {-0.1, 0}, {0, -0.1}};
  return af;
}

}  // namespace

TEST(Stance, StrikeTiltAndInradiusOfAPlusQuadAreTheClosedForms) {
  const tw::Airframe af = plus_quad();
  std::string why;
  ASSERT_TRUE(af.validate(&why)) << why;
  const tdm::detail::Stance s = tdm::detail::stance_of(af);
  // Tilted by θ about y, the front propeller's rim (x 0.3, z 0.02, half
  // thickness 0.002) meets the front foot's plane (x 0.1, z -0.1, radius
  // 0.01): 0.2 sin θ - 0.12 cos θ = 0.008.
  const double closed = std::atan2(0.12, 0.2) + std::asin(0.008 / std::hypot(0.2, 0.12));
  EXPECT_NEAR(s.strike_tilt, closed, 2e-4) << s.strike_tilt * 180 / std::numbers::pi << " deg";
  // The support polygon is the square with corners 0.1 m out on the axes:
  // its edges are 0.1 / sqrt(2) from the centre (a round foot touches
  // below its centre: the tipping edge joins the feet's centres).
  const Eigen::Vector3d com = af.centre_of_mass();
  EXPECT_NEAR(std::hypot(com.x(), com.y()), 0, 1e-12);
  EXPECT_NEAR(s.inradius, 0.1 / std::sqrt(2.0), 1e-12);
  EXPECT_NEAR(s.com_height, com.z() + 0.11, 1e-12);
}

TEST(Stance, TheUpsetRatioIsTheTightestOfSlidingTippingAndStriking) {
  tdm::detail::Stance s;
  s.com_height = 0.1;
  s.inradius = 0.05;
  s.strike_tilt = std::atan(0.5);
  const double m = 1, g = tw::kStandardGravity;
  // Friction 0.8: sliding at 0.8 m g; tipping at m g d / h = 0.5 m g;
  // striking at m g tan(strike) = 0.5 m g: the ratio is side / (0.5 m g).
  EXPECT_NEAR(tdm::detail::upset_ratio(s, 0.25 * g, m, 0.8, 0), 0.5, 1e-12);
  // Magnets of m g double what holds it landed (sliding, tipping), not the
  // tilt it must fly at: striking binds.
  EXPECT_NEAR(tdm::detail::upset_ratio(s, 0.25 * g, m, 0.8, m * g), 0.5, 1e-12);
  s.strike_tilt = std::atan(2.0);
  EXPECT_NEAR(tdm::detail::upset_ratio(s, 0.25 * g, m, 0.8, m * g), 0.25 * g * 0.1 / (2 * m * g * 0.05), 1e-12);
  EXPECT_NEAR(tdm::detail::upset_ratio(s, 0.25 * g, m, 0.1, m * g), 0.25 / 0.2, 1e-12);  // slippery: sliding binds
}
