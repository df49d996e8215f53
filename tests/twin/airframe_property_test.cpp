// Property test (issue 11): random airframe YAMLs drawn within the ranges
// documented in docs/formats.md ("Airframe YAML", "Ranges a generator may
// draw from") either load and land on flat ground with S < 0.05 rad and no
// invalid run, or are refused with a ParseError naming the key (exit 2 in
// the apps) — never an abort, never `unstable` on flat ground.
#include <gtest/gtest.h>

#include <array>
#include <cmath>
#include <cstdio>
#include <numbers>
#include <sstream>
#include <utility>

#include "touchdown/core/error.hpp"
#include "touchdown/core/random.hpp"
#include "touchdown/twin/airframe.hpp"
#include "touchdown/twin/sweep.hpp"
#include "twin_test_util.hpp"

namespace td = touchdown;
namespace tw = touchdown::twin;

namespace {

// Without landing gear (`gearless`) the airframe stands on its body box.
std::string random_airframe(td::Rng& rng, bool gearless = false) {
  auto U = [&](double lo, double hi) { return rng.uniform(lo, hi); };
  const int arms = std::array<int, 3>{4, 6, 8}[static_cast<std::size_t>(std::min(2.0, std::floor(U(0, 3))))];
  const bool coaxial = arms == 8 && U(0, 1) < 0.5;
  const double bx = U(0.08, 0.4), by = U(0.08, 0.4), bz = U(0.03, 0.12);
  std::ostringstream y;
  y.precision(6);
  y << "name: random\n";
  y << "body: {size: [" << bx << ", " << by << ", " << bz << "], mass: " << U(0.3, 5) << "}\n";
  y << "arms: {angles_deg: [";
  const int directions = coaxial ? 4 : arms;
  const double offset = U(0, 1) < 0.5 ? 0.0 : 180.0 / directions;
  for (int k = 0; k < arms; ++k) y << (k ? ", " : "") << offset + 360.0 * (k % directions) / directions;
  y << "], motor_radius: " << U(0.15, 0.6) << ", motor_z: ";
  if (coaxial) {
    y << "[";
    for (int k = 0; k < arms; ++k) y << (k ? ", " : "") << (k < directions ? 0.06 : -0.02);
    y << "]";
  } else {
    y << U(0.0, 0.06);
  }
  y << ", capsule_radius: " << U(0.005, 0.02) << "}\n";
  y << "motors: {mass: " << U(0.02, 0.3) << ", spin: [";
  for (int k = 0; k < arms; ++k) y << (k ? ", " : "") << ((k + (coaxial && k >= directions)) % 2 ? -1 : 1);
  y << "], max_thrust: " << U(2, 40) << ", time_constant: " << U(0.02, 0.08)
    << ", torque_coefficient: " << U(0.005, 0.03) << "}\n";
  y << "propellers: {radius: " << U(0.05, 0.25) << ", thickness: " << U(0.005, 0.02) << ", height: " << U(0.01, 0.05)
    << "}\n";
  if (gearless) {
    y << "landing_gear: none\n";
    return y.str();
  }
  y << "landing_gear: {mass: " << U(0.05, 1) << ", top_z: " << -0.5 * bz << ", foot_z: " << U(-0.4, -0.12)
    << ", leg_radius: " << U(0.004, 0.015) << ", foot_radius: " << U(0.005, 0.02) << ", legs: [";
  const int legs = 3 + static_cast<int>(std::floor(U(0, 4)));
  const double rx = U(0.08, 0.3), ry = U(0.08, 0.3), turn = U(0, 2 * std::numbers::pi);
  for (int k = 0; k < legs; ++k) {
    const double t = turn + 2 * std::numbers::pi * k / legs;
    y << (k ? ", " : "") << "[" << rx * std::cos(t) << ", " << ry * std::sin(t) << "]";
  }
  y << "]}\n";
  return y.str();
}

}  // namespace

namespace {

// Draws `count` airframes, lands each that loads on flat ground, returns
// {landed, refused}.
std::pair<int, int> land_random_airframes(td::Rng& rng, int count, bool gearless) {
  const auto flat = td::test::analytic_terrain([](double, double) { return 0.0; }, 1.6, 0.05);
  int landed = 0, refused = 0;
  for (int k = 0; k < count; ++k) {
    const std::string yaml = random_airframe(rng, gearless);
    tw::Airframe af;
    try {
      af = tw::parse_airframe(yaml, "random.yaml");
    } catch (const td::ParseError& e) {
      // Refused: one line naming the file and a documented key.
      const std::string what = e.what();
      EXPECT_EQ(what.find('\n'), std::string::npos) << what;
      EXPECT_EQ(what.rfind("random.yaml", 0), 0u) << what;
      ++refused;
      continue;
    }
    tw::SweepOptions o;
    o.headings = 2;
    o.runs = 1;
    o.threads = 1;
    o.seed = static_cast<std::uint64_t>(k);
    const auto r = tw::run_sweep(af, flat, o);
    EXPECT_TRUE(r.ok()) << r.message << "\n" << yaml;
    for (const auto& h : r.headings) {
      EXPECT_EQ(h.invalid_runs, 0) << h.invalid_reason << "\n" << yaml;
      EXPECT_LT(h.score, 0.05) << yaml;
      EXPECT_EQ(h.tipped_runs, 0) << yaml;
      EXPECT_EQ(h.body_strike_runs, 0) << yaml;
    }
    ++landed;
  }
  return {landed, refused};
}

}  // namespace

TEST(AirframeProperty, RandomAirframesLandOnFlatGroundOrAreRefusedByKey) {
  td::Rng rng(2026, 11);
  const auto [landed, refused] = land_random_airframes(rng, 40, false);
  // Both outcomes occur: the ranges are wide enough to reach the checks.
  EXPECT_GT(landed, 5);
  EXPECT_GT(refused, 5);
  std::printf("random airframes: %d landed, %d refused\n", landed, refused);
}

TEST(AirframeProperty, RandomAirframesWithoutLandingGearLandOnTheirBodyOrAreRefusedByKey) {
  td::Rng rng(2026, 12);
  const auto [landed, refused] = land_random_airframes(rng, 30, true);
  EXPECT_GT(landed, 5);
  EXPECT_GT(refused, 3);
  std::printf("random airframes without landing gear: %d landed, %d refused\n", landed, refused);
}
