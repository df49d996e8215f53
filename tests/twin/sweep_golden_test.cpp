// The sweep's decisions on every bundled terrain (the app's default options;
// the decision mode's against the full sweep's) and on a perturbed variant
// of a sweep-test terrain, with each contact, against its golden file
// (sweep_golden.hpp says which and how to re-record). The twin's own tests
// check their sweeps against the default contact's file.
#include "sweep_golden.hpp"

#include <gtest/gtest.h>

#include <iostream>
#include <string>

#include "test_util.hpp"
#include "touchdown/core/units.hpp"
#include "touchdown/terrain/extrinsics.hpp"
#include "touchdown/twin/sweep.hpp"
#include "twin_test_util.hpp"

namespace td = touchdown;
namespace tw = touchdown::twin;

namespace {

using td::test::check_golden;

tw::SweepResult bundled(tw::TerrainContact contact, const std::string& terrain, double x = 0.0,
                        const std::string& airframe = "") {
  const std::string base = std::string(TOUCHDOWN_SOURCE_DIR) + "/data/terrains/" + terrain;
  const auto e = td::terrain::load_extrinsics(base + ".extrinsics.yaml");
  td::terrain::TerrainOptions cloud;
  cloud.T_world_camera = e.T_world_camera;
  cloud.T_body_camera = e.T_body_camera;
  tw::SweepOptions o;  // the app's defaults: 20 headings x 10 runs, seed 1
  o.landing_point = Eigen::Vector2d(x, 0.0);
  o.threads = 2;
  o.simulation.contact = contact;
  const tw::Airframe af =
      airframe.empty() ? tw::Airframe::f450()
                       : tw::load_airframe(std::string(TOUCHDOWN_SOURCE_DIR) + "/data/airframes/" + airframe + ".yaml");
  const auto model = tw::load_terrain_model(base + ".pcd", cloud);
  tw::SweepResult full = tw::run_sweep(af, model, o);
  // Issue 57: the decision mode decides the same, bit for bit.
  o.decide = true;
  const tw::SweepResult d = tw::run_sweep(af, model, o);
  EXPECT_EQ(d.safe, full.safe) << terrain;
  EXPECT_EQ(d.best, full.best) << terrain;
  if (d.best >= 0 && d.best == full.best) {
    EXPECT_EQ(d.headings[static_cast<std::size_t>(d.best)].score,
              full.headings[static_cast<std::size_t>(full.best)].score)
        << terrain;
  }
  EXPECT_LE(d.landings(), full.landings());
  std::cout << terrain << " x " << x << ": the decision mode flew " << d.landings() << " of " << full.landings()
            << " landings\n";
  return full;
}

tw::SweepResult small(tw::TerrainContact contact, const std::shared_ptr<const tw::TerrainModel>& terrain, int headings,
                      int runs) {
  tw::SweepOptions o;
  o.simulation.contact = contact;
  o.headings = headings;
  o.runs = runs;
  o.threads = 2;
  return tw::run_sweep(tw::Airframe::f450(), terrain, o);
}

// Each case with both contacts (issue 57): the default height field against
// sweep_decisions.txt, the trimesh against sweep_decisions_trimesh.txt.
class SweepGolden : public ::testing::TestWithParam<tw::TerrainContact> {
 protected:
  [[nodiscard]] std::string file() const {
    return GetParam() == tw::TerrainContact::Trimesh ? td::test::kGoldenTrimesh : td::test::kGoldenDefault;
  }
  // The trimesh's cases run in the Release tests only (the sanitizer run
  // keeps the default contact's).
  [[nodiscard]] bool reduced_trimesh() const {
    return GetParam() == tw::TerrainContact::Trimesh && td::test::reduced_size();
  }
};

}  // namespace

INSTANTIATE_TEST_SUITE_P(Contacts, SweepGolden,
                         ::testing::Values(tw::TerrainContact::HeightField, tw::TerrainContact::Trimesh),
                         [](const ::testing::TestParamInfo<tw::TerrainContact>& param) {
                           return param.param == tw::TerrainContact::Trimesh ? "trimesh" : "height_field";
                         });

// The bundled terrains with the app's default options (what a user runs).
// At reduced size (the sanitizer run) flat, step and the gearless flat
// landing keep the gear, edge and box contact paths; the others run in the
// Release tests only.
TEST_P(SweepGolden, Flat) {
  if (reduced_trimesh()) GTEST_SKIP() << "TOUCHDOWN_TEST_SIZE=reduced: the trimesh's golden sweeps run in Release";
  check_golden("flat", bundled(GetParam(), "flat"), file());
}
TEST_P(SweepGolden, Incline) {
  TD_FULL_SIZE_ONLY();
  check_golden("incline", bundled(GetParam(), "incline"), file());
}
TEST_P(SweepGolden, Plateau) {
  TD_FULL_SIZE_ONLY();
  check_golden("plateau", bundled(GetParam(), "plateau"), file());
}
TEST_P(SweepGolden, Post) {
  TD_FULL_SIZE_ONLY();
  check_golden("post", bundled(GetParam(), "post"), file());
}
TEST_P(SweepGolden, Rubble) {
  TD_FULL_SIZE_ONLY();
  check_golden("rubble", bundled(GetParam(), "rubble"), file());
}
TEST_P(SweepGolden, SlopeGentle) {
  TD_FULL_SIZE_ONLY();
  check_golden("slope_gentle", bundled(GetParam(), "slope_gentle"), file());
}
TEST_P(SweepGolden, SlopeSteep) {
  TD_FULL_SIZE_ONLY();
  check_golden("slope_steep", bundled(GetParam(), "slope_steep"), file());
}
TEST_P(SweepGolden, Step) {
  if (reduced_trimesh()) GTEST_SKIP() << "TOUCHDOWN_TEST_SIZE=reduced: the trimesh's golden sweeps run in Release";
  check_golden("step", bundled(GetParam(), "step"), file());
}
TEST_P(SweepGolden, StepDemo) {
  TD_FULL_SIZE_ONLY();
  check_golden("step_demo", bundled(GetParam(), "step", 0.12), file());
}
// The airframe without landing gear, which lands on its body box (the box
// contacts' path).
TEST_P(SweepGolden, GearlessFlat) {
  if (reduced_trimesh()) GTEST_SKIP() << "TOUCHDOWN_TEST_SIZE=reduced: the trimesh's golden sweeps run in Release";
  check_golden("gearless_flat", bundled(GetParam(), "flat", 0.0, "gearless_quad"), file());
}
TEST_P(SweepGolden, GearlessStepDemo) {
  TD_FULL_SIZE_ONLY();
  check_golden("gearless_step_demo", bundled(GetParam(), "step", 0.12, "gearless_quad"), file());
}

// The sweep tests check their own sweeps in place (sweep_golden.hpp); this
// is their 15 cm step with the default perturbation, which they fly with
// none.
TEST_P(SweepGolden, StepOfTheSearchTestPerturbed) {
  check_golden("test_step15",
               small(GetParam(),
                     td::test::analytic_terrain([](double x, double) { return x > 0 ? 0.15 : 0.0; }, 1.2, 0.02), 4, 1),
               file());
}
