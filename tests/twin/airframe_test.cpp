#include "touchdown/twin/airframe.hpp"

#include <gtest/gtest.h>

#include <fstream>
#include <sstream>

#include "sweep_golden.hpp"
#include "test_util.hpp"
#include "touchdown/core/error.hpp"
#include "touchdown/core/units.hpp"
#include "touchdown/twin/sweep.hpp"
#include "twin_test_util.hpp"

namespace td = touchdown;
namespace tw = touchdown::twin;

namespace {

std::string f450_yaml() {
  return td::test::read_text(std::filesystem::path(TOUCHDOWN_SOURCE_DIR) / "data/airframes/f450.yaml");
}

std::string error_of(const std::string& yaml) {
  return td::test::error_of([&] { tw::parse_airframe(yaml, "af.yaml"); });
}

using td::test::replace;

}  // namespace

TEST(Airframe, RepeatedKeyIsAnError) {
  td::test::TempDir dir;
  const auto f = td::test::with_repeated_key(std::filesystem::path(TOUCHDOWN_SOURCE_DIR) / "data/airframes/f450.yaml",
                                             dir / "af.yaml", "name", "other");
  EXPECT_EQ(td::test::error_of([&] { (void)tw::load_airframe(f.path); }), f.expected);
  EXPECT_THROW((void)tw::load_airframe(f.path), td::ParseError);
}

TEST(Airframe, BundledF450MatchesTheBuiltInDefault) {
  const auto a = tw::parse_airframe(f450_yaml(), "f450.yaml");
  const auto b = tw::Airframe::f450();
  EXPECT_EQ(a.body_size, b.body_size);
  EXPECT_EQ(a.legs, b.legs);
  EXPECT_EQ(a.arm_angles_deg, b.arm_angles_deg);
  EXPECT_EQ(a.spin, b.spin);
  EXPECT_DOUBLE_EQ(a.total_mass(), b.total_mass());
  EXPECT_TRUE(a.centre_of_mass().isApprox(b.centre_of_mass()));
  EXPECT_TRUE(a.inertia_about_com().isApprox(b.inertia_about_com()));
}

TEST(Airframe, BundledQuad180MatchesTheBuiltIn) {
  const auto a = tw::load_airframe(std::filesystem::path(TOUCHDOWN_SOURCE_DIR) / "data/airframes/quad180.yaml");
  const auto b = tw::Airframe::quad180();
  EXPECT_EQ(a.name, b.name);
  EXPECT_EQ(a.body_size, b.body_size);
  EXPECT_EQ(a.legs, b.legs);
  EXPECT_EQ(a.motor_radius, b.motor_radius);
  EXPECT_EQ(a.prop_radius, b.prop_radius);
  EXPECT_EQ(a.max_thrust, b.max_thrust);
  EXPECT_EQ(a.foot_z, b.foot_z);
  EXPECT_DOUBLE_EQ(a.total_mass(), b.total_mass());
  EXPECT_TRUE(a.centre_of_mass().isApprox(b.centre_of_mass()));
  EXPECT_TRUE(a.inertia_about_com().isApprox(b.inertia_about_com()));
  std::string why;
  EXPECT_TRUE(b.validate(&why)) << why;
}

TEST(Airframe, MassCentreAndInertiaFromTheParts) {
  const auto a = tw::Airframe::f450();
  EXPECT_NEAR(a.total_mass(), 1.50, 1e-12);
  // Body box at z = 0, motors at z = 0.03, legs centred at z = -0.10.
  const double zc = (0.95 * 0 + 0.2 * 0.03 + 0.35 * -0.10) / 1.5;
  EXPECT_TRUE(a.centre_of_mass().isApprox(Eigen::Vector3d(0, 0, zc), 1e-12)) << a.centre_of_mass().transpose();
  const Eigen::Matrix3d I = a.inertia_about_com();
  EXPECT_TRUE(I.isApprox(I.transpose()));
  // Positive definite (Sylvester: every leading principal minor positive).
  // Not I.eigenvalues(): Eigen's general eigensolver costs ~10 s to compile.
  EXPECT_GT(I(0, 0), 0);
  EXPECT_GT((I.topLeftCorner<2, 2>().determinant()), 0);
  EXPECT_GT(I.determinant(), 0);
  // Iz: box (0.95/12 (0.14² + 0.14²)) + motors 4·0.05·0.225² + legs 0.35·(0.15² + 0.08²).
  const double iz = 0.95 / 12 * (2 * 0.14 * 0.14) + 4 * 0.05 * 0.225 * 0.225 + 0.35 * (0.15 * 0.15 + 0.08 * 0.08);
  EXPECT_NEAR(I(2, 2), iz, 1e-12);
  EXPECT_TRUE(a.symmetric_under_half_turn());
  EXPECT_NEAR(a.ground_z(), -0.18, 1e-12);
}

TEST(Airframe, SymmetryOrderCountsContactGeometryNotSpins) {
  auto a = tw::Airframe::f450();
  EXPECT_EQ(a.symmetry_order(), 2);  // legs on a 0.30 x 0.16 m rectangle
  a.legs = {{0.12, 0.0}, {0.0, 0.12}, {-0.12, 0.0}, {0.0, -0.12}};
  EXPECT_EQ(a.symmetry_order(), 4);  // square gear, X arms, square body
  a.body_size.x() = 0.2;
  EXPECT_EQ(a.symmetry_order(), 2);  // an oblong body breaks the quarter turn
  // A hexacopter with alternating spins and six feet under its arms: a half
  // turn maps motor 0 (30°, +1) onto motor 3 (210°, -1). Spins do not count,
  // so 180° is enough (it used to sweep 360°); the square body box is what
  // keeps it from 60°.
  tw::Airframe hexa = tw::Airframe::f450();
  hexa.arm_angles_deg = {30, 90, 150, 210, 270, 330};
  hexa.spin = {1, -1, 1, -1, 1, -1};
  hexa.motor_radius = 0.3;
  hexa.legs.clear();
  for (int k = 0; k < 6; ++k) {
    const double t = touchdown::deg_to_rad(30 + 60 * k);
    hexa.legs.emplace_back(0.14 * std::cos(t), 0.14 * std::sin(t));
  }
  std::string why;
  ASSERT_TRUE(hexa.validate(&why)) << why;
  EXPECT_EQ(hexa.symmetry_order(), 2);
  EXPECT_TRUE(hexa.symmetric_under_half_turn());
}

TEST(Airframe, CoaxialLayoutGetsPerMotorZAndLands) {
  // An X8: four arms, a motor above and one below each arm end, the pair
  // turning opposite ways. Same xy, planes 0.08 m apart: not overlapping.
  const std::string x8 = R"(name: X8 coaxial
body: {size: [0.16, 0.16, 0.06], mass: 1.2}
arms: {angles_deg: [45, 135, 225, 315, 45, 135, 225, 315], motor_radius: 0.3,
       motor_z: [0.06, 0.06, 0.06, 0.06, -0.02, -0.02, -0.02, -0.02], capsule_radius: 0.012}
motors: {mass: 0.06, spin: [1, -1, 1, -1, -1, 1, -1, 1], max_thrust: 8.0, time_constant: 0.04, torque_coefficient: 0.016}
propellers: {radius: 0.15, thickness: 0.01, height: 0.01}
landing_gear: {mass: 0.35, top_z: -0.03, foot_z: -0.22, leg_radius: 0.008, foot_radius: 0.01,
               legs: [[0.18, 0.1], [0.18, -0.1], [-0.18, -0.1], [-0.18, 0.1]]}
)";
  const auto a = tw::parse_airframe(x8, "x8.yaml");
  ASSERT_EQ(a.motor_count(), 8u);
  EXPECT_NEAR(a.motor_position(0).z(), 0.06, 1e-12);
  EXPECT_NEAR(a.motor_position(4).z(), -0.02, 1e-12);
  EXPECT_NEAR((a.motor_position(0) - a.motor_position(4)).head<2>().norm(), 0.0, 1e-12);
  EXPECT_EQ(a.symmetry_order(), 2);
  tw::SweepOptions o;
  o.headings = 2;
  o.runs = 1;
  const auto r = tw::run_sweep(a, td::test::flat_terrain(), o);
  ASSERT_TRUE(r.ok());
  td::test::check_golden("airframe_test_coaxial_flat", r);
  for (const auto& h : r.headings) {
    EXPECT_EQ(h.invalid_runs, 0) << h.invalid_reason;
    EXPECT_LT(h.score, 0.05);
  }
  // The same pairs in one plane overlap.
  std::string flat_x8 = x8;
  flat_x8.replace(flat_x8.find("-0.02, -0.02, -0.02, -0.02"), 26, "0.06, 0.06, 0.06, 0.06");
  try {
    (void)tw::parse_airframe(flat_x8, "x8.yaml");
    ADD_FAILURE() << "overlapping coaxial propellers accepted";
  } catch (const td::ParseError& e) {
    EXPECT_NE(std::string(e.what()).find("propellers of arms 1 and 5 overlap"), std::string::npos) << e.what();
  }
}

TEST(Airframe, AsymmetricGearIsNotHalfTurnSymmetric) {
  auto a = tw::Airframe::f450();
  a.legs = {{0.15, 0.08}, {0.15, -0.08}, {-0.10, -0.08}, {-0.10, 0.08}};
  std::string why;
  EXPECT_TRUE(a.validate(&why)) << why;
  EXPECT_FALSE(a.symmetric_under_half_turn());
}

// One case per malformed airframe: one error naming the key.
class AirframeBadInput : public ::testing::TestWithParam<td::test::BadInput> {};

TEST_P(AirframeBadInput, OneErrorNamingTheKey) {
  touchdown::test::expect_one_line_naming(error_of(GetParam().text), GetParam());
}

namespace {

std::vector<td::test::BadInput> airframe_cases() {
  const std::string y = f450_yaml();
  // Legs all on one line.
  const std::string collinear = replace(replace(replace(replace(y, "    - [0.15, 0.08]", "    - [0.15, 0.0]"),
                                                        "    - [0.15, -0.08]", "    - [0.05, 0.0]"),
                                                "    - [-0.15, -0.08]", "    - [-0.05, 0.0]"),
                                        "    - [-0.15, 0.08]", "    - [-0.15, 0.0]");
  return {
      {"NegativeMass", replace(y, "  mass: 0.95", "  mass: -0.95"), {"body.mass: must be positive"}},
      {"FeetAboveTheBody", replace(y, "  foot_z: -0.17", "  foot_z: 0.10"), {"landing_gear.foot_z"}},
      {"LegsAboveTheBody",
       replace(y, "  top_z: -0.03", "  top_z: 0.20"),
       {"landing_gear.top_z: the legs start above the body"}},
      // A fifth leg inside the other four.
      {"NonConvexSupport", replace(y, "    - [-0.15, 0.08]", "    - [-0.15, 0.08]\n    - [0.0, 0.02]"), {"not convex"}},
      {"UnknownKey",
       replace(y, "  radius: 0.127", "  radius: 0.127\n  colour: red"),
       {"propellers.colour: unknown key"}},
      {"MissingMaxThrust", replace(y, "  max_thrust: 8.0", ""), {"motors.max_thrust: missing"}},
      {"CannotLift", replace(y, "  max_thrust: 8.0", "  max_thrust: 2.0"), {"motors.max_thrust", "need at least 1.3"}},
      // Issue 11: airframes that aborted ODE (singular mixer) or could not fly.
      {"Tricopter",
       replace(replace(y, "  angles_deg: [45, 135, 225, 315]", "  angles_deg: [60, 180, 300]"),
               "  spin: [1, -1, 1, -1]", "  spin: [1, -1, 1]"),
       {"arms.angles_deg: 3 fixed motors", "yaw servo"}},
      {"ZeroTorqueCoefficient",
       replace(y, "  torque_coefficient: 0.016", "  torque_coefficient: 0"),
       {"motors.torque_coefficient: must be > 0"}},
      {"MotorsOnOneLine",
       replace(y, "  angles_deg: [45, 135, 225, 315]", "  angles_deg: [0, 0, 180, 180]"),
       {"arms.angles_deg", "rank < 4"}},
      {"AllSpinTheSameWay", replace(y, "  spin: [1, -1, 1, -1]", "  spin: [1, 1, 1, 1]"), {"motors.spin: every motor"}},
      {"AnglesInRadians",
       replace(y, "  angles_deg: [45, 135, 225, 315]", "  angles_deg: [0.785, 2.356, 3.927, 5.498]"),
       {"propellers.radius", "overlap", "written in radians?"}},
      {"MassInGrams", replace(y, "  mass: 0.95", "  mass: 950"), {"body.mass: 950 kg is implausible", "grams?"}},
      {"PropellerCutsTheBody",
       replace(replace(y, "  motor_radius: 0.225", "  motor_radius: 0.2"), "  height: 0.02", "  height: 0.0"),
       {"propellers.radius: the propeller of arm 1 cuts into the body"}},
      {"MotorZListTooShort",
       replace(y, "  motor_z: 0.03", "  motor_z: [0.03, 0.03]"),
       {"arms.motor_z: a list needs one z per arm (4), got 2"}},
      {"SpinWithTwoNumbers", replace(y, "  spin: [1, -1, 1, -1]", "  spin: [1, -1]"), {"motors.spin: expected 4"}},
      // Found by fuzz_airframe: 1.4e31 was cast to int (undefined) before the check.
      {"SpinTooLargeForAnInt",
       replace(y, "  spin: [1, -1, 1, -1]", "  spin: [1, -1, 1.4e31, -1]"),
       {"motors.spin: entries must be 1 or -1, got 1.4e+31"}},
      {"SpinAHalf",
       replace(y, "  spin: [1, -1, 1, -1]", "  spin: [1, -1, 0.5, -1]"),
       {"motors.spin: entries must be 1 or -1, got 0.5"}},
      {"NonNumericMass", replace(y, "  mass: 0.35", "  mass: heavy"), {"landing_gear.mass: expected a number"}},
      {"InvalidYaml", "body: [1\n", {"invalid YAML"}},
      {"CollinearLegs", collinear, {"collinear"}},
  };
}

}  // namespace

INSTANTIATE_TEST_SUITE_P(Cases, AirframeBadInput, ::testing::ValuesIn(airframe_cases()), td::test::bad_input_name);

TEST(AirframeBadInput, MissingFile) { EXPECT_THROW(tw::load_airframe("/nonexistent/af.yaml"), td::IoError); }
