// The search's view of a run (evaluation.hpp): eq. 5 per frame, its sum,
// and the coverage cells of a hand-made trajectory.
#include "touchdown/search/evaluation.hpp"

#include <gtest/gtest.h>

namespace touchdown::search {
namespace {

TEST(FrameReward, IsEq5) {
  EXPECT_DOUBLE_EQ(frame_reward(400, 100), 4.0);  // three quarters hidden
  EXPECT_DOUBLE_EQ(frame_reward(400, 200), 2.0);
  EXPECT_EQ(frame_reward(400, 400), 0.0);  // nothing hides it
  EXPECT_EQ(frame_reward(400, 0), 0.0);    // wholly hidden or out of view
  EXPECT_EQ(frame_reward(0, 0), 0.0);
}

TEST(EvaluateResult, SumsRewardsAndListsVisitedCellsOnce) {
  scenario::ScenarioResult r;
  r.status = scenario::Violation::TypeII;
  r.dtl = 3.5;
  r.ttl = 60;
  r.frame_count = 3;
  r.frames.resize(3);
  r.frames[0].marker_area_truth_px = 100;
  r.frames[0].marker_area_visible_px = 50;  // 2
  r.frames[1].marker_area_truth_px = 100;
  r.frames[1].marker_area_visible_px = 100;  // 0
  r.frames[2].marker_area_truth_px = 90;
  r.frames[2].marker_area_visible_px = 30;  // 3
  for (const Eigen::Vector3d& p :
       {Eigen::Vector3d(0.5, 0.5, 9.9), Eigen::Vector3d(1.9, 0.1, 8.1), Eigen::Vector3d(2.1, 0.1, 8.1),
        Eigen::Vector3d(-0.1, 0.5, 9.9), Eigen::Vector3d(0.5, 0.5, 9.0)}) {
    scenario::TrajectorySample s;
    s.position = p;
    r.trajectory.push_back(s);
  }
  const Evaluation e = evaluate_result(r, 60);
  EXPECT_EQ(e.violation, scenario::Violation::TypeII);
  EXPECT_TRUE(e.violation_found());
  EXPECT_DOUBLE_EQ(e.reward_sum, 5.0);
  EXPECT_EQ(e.dtl, 3.5);
  EXPECT_EQ(e.frames, 3);
  const std::vector<std::array<int, 3>> expected{{-1, 0, 4}, {0, 0, 4}, {1, 0, 4}};
  EXPECT_EQ(e.cells, expected);
}

}  // namespace
}  // namespace touchdown::search
