// The guidance's replans in a landing do not touch the heap (issue 34:
// the corridor and the solver's work space are kept): a counting global
// operator new, armed after the landing's first plan.
#include <gtest/gtest.h>

#include "counting_new.hpp"
#include "touchdown/mission/guidance.hpp"

TEST(GuidanceAllocation, ReplansAtTenHertzDoNotAllocate) {
  namespace tdm = touchdown::mission;
  const tdm::GuidanceOptions o;
  tdm::Guidance g(o, 0.06);
  tdm::PadState pad;
  pad.velocity = Eigen::Vector3d(2, 0, 0);
  pad.yaw_rate = 0.25;
  const tdm::StateMachineOptions machine;
  touchdown::plan::KinematicState estimate;
  estimate.p = o.tracking_point;
  ASSERT_EQ(g.update(0, tdm::MissionState::Landing, true, pad, estimate, {}, machine).replan, tdm::ReplanOutcome::Ok);
  int replans = 0;
  long allocations = 0;
  for (int k = 1; k < 100; ++k) {  // 2 s at the ground station's 50 Hz
    const double t = 0.02 * k;
    // The drone on the plan, 1 cm off it (the replans start from the
    // plan's reference).
    const double tau = t - g.plan_start();
    estimate = {g.trajectory().evaluate(tau) + Eigen::Vector3d(0.01, 0, 0), g.trajectory().evaluate(tau, 1),
                g.trajectory().evaluate(tau, 2)};
    g_allocations = 0;
    g_armed = true;
    const tdm::GuidanceOutput out = g.update(t, tdm::MissionState::Landing, false, pad, estimate, {}, machine);
    g_armed = false;
    allocations += g_allocations;
    ASSERT_NE(out.replan, tdm::ReplanOutcome::Failed) << g.message();
    replans += out.replan == tdm::ReplanOutcome::Ok ? 1 : 0;
  }
  EXPECT_GE(replans, 15);
  EXPECT_EQ(allocations, 0);
}
