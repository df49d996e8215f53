// The enum names of the pose libraries (core/enum_names.hpp): LED colours as
// constellation files spell them, statuses as led_pose's JSON writes them,
// trajectories, geometries and profiles as led_pose reads them.
#include <gtest/gtest.h>

#include "enum_names_suite.hpp"
#include "test_util.hpp"
#include "touchdown/pose/calib/calibration.hpp"
#include "touchdown/pose/constellation.hpp"
#include "touchdown/pose/epnp.hpp"
#include "touchdown/pose/gauss_newton.hpp"
#include "touchdown/pose/pose_estimate.hpp"
#include "touchdown/pose/sim/pose_benchmark.hpp"
#include "touchdown/pose/sim/synthetic.hpp"
#include "touchdown/pose/sim/trajectory.hpp"

namespace td = touchdown;
namespace tp = touchdown::pose;

using PoseEnums =
    ::testing::Types<tp::LedColor, tp::TrajectoryKind, tp::CameraGeometry, tp::RenderProfile, tp::PoseStatus,
                     tp::CalibrationStatus, tp::PoseBenchmarkStatus, tp::RefineStatus, tp::EpnpStatus>;
namespace touchdown::test {
INSTANTIATE_TYPED_TEST_SUITE_P(Pose, EnumNamesSuite, PoseEnums);
}  // namespace touchdown::test

TEST(PoseEnumNames, ABadNameListsTheAcceptedNames) {
  td::test::expect_bad_name<tp::TrajectoryKind>("still", "expected one of static, moving; got 'still'");
  td::test::expect_bad_name<tp::CameraGeometry>("Chase", "expected one of facing, chase; got 'Chase'");
  td::test::expect_bad_name<tp::RenderProfile>("dirty", "expected one of clean, harsh; got 'dirty'");
  td::test::expect_bad_name<tp::LedColor>("yellow", "expected one of red, green, blue, white, unknown; got 'yellow'");
}

// Results of hot loops carry no string: their message is the status's text.
TEST(PoseEnumNames, HotLoopResultsGiveTheirStatusAsMessage) {
  tp::PoseEstimate e;
  e.status = tp::PoseStatus::TooFewBlobs;
  EXPECT_FALSE(e.ok());
  EXPECT_EQ(e.message(), "too few blobs");
  e.status = tp::PoseStatus::Ok;
  EXPECT_TRUE(e.ok());
  EXPECT_EQ(e.message(), "ok");
  tp::PoseRefinement r;
  r.status = tp::RefineStatus::MaxIterations;
  EXPECT_TRUE(r.ok());  // a pose, short of the step tolerance
  EXPECT_EQ(r.message(), "max_iterations");
  tp::EpnpResult p;
  EXPECT_FALSE(p.ok());
  EXPECT_EQ(p.message(), "no_solution");
}
