#include "touchdown/plan/planner.hpp"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <utility>
#include <vector>

#include "touchdown/core/error.hpp"
#include "touchdown/plan/qp.hpp"

namespace tp = touchdown::plan;

namespace {

// Largest world-frame |velocity| and |acceleration| component over 1 ms samples.
std::pair<double, double> planner_world_peaks(const tp::PlanResult& r, const tp::PadMotion& pad) {
  double v = 0, a = 0;
  const double total = r.trajectory.total_duration();
  for (double t = 0; t <= total; t += 1e-3) {
    const tp::KinematicState rel{r.trajectory.evaluate(t), r.trajectory.evaluate(t, 1), r.trajectory.evaluate(t, 2)};
    const tp::KinematicState w = pad.to_world(t, rel);
    v = std::max(v, w.v.cwiseAbs().maxCoeff());
    a = std::max(a, w.a.cwiseAbs().maxCoeff());
  }
  return {v, a};
}

tp::PlannerOptions planner_loose(int order, int segments, std::vector<double> durations) {
  tp::PlannerOptions o;
  o.order = order;
  o.segments = segments;
  o.v_max = 100;
  o.a_max = 100;
  o.durations = std::move(durations);
  o.export_qp = true;
  return o;
}

tp::PlannerOptions planner_with_corridor() {
  tp::PlannerOptions o;
  o.v_max = 4;
  o.a_max = 4;
  tp::CorridorOptions c;
  c.h_touchdown = 0.5;
  c.radius = 0.25;
  c.dilate = 0.2;
  c.deflate = 0.3;
  c.margin = 1.0;
  tp::CameraFov cam;
  // On the pad, looking up and backward (toward −x) at the approaching drone.
  cam.T_pad_camera.linear() = Eigen::AngleAxisd(-0.6, Eigen::Vector3d::UnitY()).toRotationMatrix();
  cam.T_pad_camera.translation() = Eigen::Vector3d(0.2, 0, 0.05);
  cam.horizontal_fov_rad = 1.5;
  cam.vertical_fov_rad = 1.2;
  cam.near_m = 0.1;
  cam.far_m = 10;
  c.camera = cam;
  o.corridor = c;
  o.obstacles.push_back({Eigen::Vector3d(-1.6, -0.3, 0), Eigen::Vector3d(-1.3, 0.3, 1.2)});
  return o;
}

}  // namespace

// Rest to rest over D in T: the minimum-jerk curve is the quintic
// 10τ³ − 15τ⁴ + 6τ⁵ whatever the order (≥ 5) and the number of segments,
// at cost 720 D²/T⁵ per axis.
TEST(Planner, RestToRestCostsTheQuinticsClosedForm) {
  const Eigen::Vector3d D(1.5, -0.8, 0.6);
  const double T = 2.5;
  for (int order = 5; order <= 9; ++order) {
    for (int segments = 1; segments <= 3; ++segments) {
      std::vector<double> durations;
      for (int k = 0; k < segments; ++k) durations.push_back(T * (k + 1.0) / (segments * (segments + 1) / 2.0));
      tp::KinematicState start, goal;
      start.p = Eigen::Vector3d(0.3, 0.2, 2);
      goal.p = start.p + D;
      const tp::PlanResult r = tp::plan(start, goal, {}, planner_loose(order, segments, durations));
      ASSERT_TRUE(r.ok()) << r.message;
      EXPECT_NEAR(r.cost, 720 * D.squaredNorm() / std::pow(T, 5), 1e-7) << order << " " << segments;
      // The QP's own objective is the same number.
      Eigen::VectorXd x(r.qp.P.rows());
      int i = 0;
      for (const auto& c : r.trajectory.all_control_points()) x.segment<3>(3 * i++) = c;
      EXPECT_NEAR(0.5 * x.dot(r.qp.P * x) + r.qp.q.dot(x) + r.qp.constant, r.cost, 1e-8);
      const double tau = 0.37;
      const double s = 10 * std::pow(tau, 3) - 15 * std::pow(tau, 4) + 6 * std::pow(tau, 5);
      EXPECT_LT((r.trajectory.evaluate(tau * T) - (start.p + s * D)).norm(), 1e-8);
    }
  }
}

// A pad driving at 1.5 m/s with v_max 2: the plan keeps the drone's world
// velocity within 2 m/s; the same limit applied to the pad-frame velocity
// (the published code's shortcut) lets the world velocity exceed it.
TEST(Planner, WorldFrameVelocityLimitHoldsWhereAPadFrameLimitWouldNot) {
  tp::KinematicState start;
  start.p = Eigen::Vector3d(-4, 0.5, 2);
  tp::PadMotion pad;
  pad.velocity = Eigen::Vector3d(1.5, 0, 0);
  tp::PlannerOptions o = planner_loose(7, 2, {6, 6});
  o.v_max = 2;
  const tp::PlanResult r = tp::plan(start, std::nullopt, pad, o);
  ASSERT_TRUE(r.ok()) << r.message;
  const auto [v, a] = planner_world_peaks(r, pad);
  EXPECT_LE(v, 2 + 1e-9);
  EXPECT_GT(v, 1.9);  // the limit is active
  // Naive: the limit on the pad-frame velocity (a planner that ignores the pad's motion).
  const tp::PlanResult naive = tp::plan(start, std::nullopt, tp::PadMotion{}, o);
  ASSERT_TRUE(naive.ok());
  EXPECT_GT(planner_world_peaks(naive, pad).first, 2.05);
  EXPECT_GT(r.cost, naive.cost);  // the world limit costs jerk
}

// The same on a pad turning at 0.4 rad/s (a vehicle on a circle), with the
// acceleration limited too: every 1 ms sample within both limits.
TEST(Planner, RotatingPadLimitsHoldInTheWorldFrame) {
  tp::KinematicState start;
  start.p = Eigen::Vector3d(-3, 1, 2.5);
  start.v = Eigen::Vector3d(0.2, 0, -0.1);
  tp::PadMotion pad;
  pad.velocity = Eigen::Vector3d(0, 2, 0);
  pad.yaw = 1.2;
  pad.yaw_rate = 0.4;
  tp::PlannerOptions o = planner_loose(7, 2, {});
  o.v_max = 3;
  o.a_max = 2.5;
  const tp::PlanResult r = tp::plan(start, std::nullopt, pad, o);
  ASSERT_TRUE(r.ok()) << r.message;
  const auto [v, a] = planner_world_peaks(r, pad);
  EXPECT_LE(v, 3 + 1e-9);
  EXPECT_LE(a, 2.5 + 1e-9);
  EXPECT_GT(r.evaluations, 5);
}

TEST(Planner, PadMotionWorldStatesAreTheDerivativesOfWorldPositions) {
  tp::PadMotion pad;
  pad.velocity = Eigen::Vector3d(1.2, -0.7, 0.1);
  pad.yaw = 0.5;
  pad.yaw_rate = -0.3;
  // A pad-frame curve: p(t) = (t², sin t, 1 + t) and its derivatives.
  auto rel = [](double t) {
    return tp::KinematicState{Eigen::Vector3d(t * t, std::sin(t), 1 + t), Eigen::Vector3d(2 * t, std::cos(t), 1),
                              Eigen::Vector3d(2, -std::sin(t), 0)};
  };
  const double h = 1e-4;
  for (const double t : {0.0, 0.7, 2.3}) {
    const tp::KinematicState w = pad.to_world(t, rel(t));
    const Eigen::Vector3d v_num = (pad.to_world(t + h, rel(t + h)).p - pad.to_world(t - h, rel(t - h)).p) / (2 * h);
    const Eigen::Vector3d a_num = (pad.to_world(t + h, rel(t + h)).v - pad.to_world(t - h, rel(t - h)).v) / (2 * h);
    EXPECT_LT((w.v - v_num).norm(), 1e-6);
    EXPECT_LT((w.a - a_num).norm(), 1e-6);
    EXPECT_LT((pad.world_velocity(t) - (pad.position(t + h) - pad.position(t - h)) / (2 * h)).norm(), 1e-6);
  }
}

// Corridor and limits at 1 ms samples: every sample inside its segment's
// polytope (the drone's radius already taken off), within the world limits.
TEST(Planner, CorridorAndLimitsHoldAtMillisecondSamples) {
  tp::KinematicState start;
  start.p = Eigen::Vector3d(-3, 0.4, 2.2);
  start.v = Eigen::Vector3d(0.5, 0, 0);
  tp::PadMotion pad;
  pad.velocity = Eigen::Vector3d(2, 0, 0);
  const tp::PlannerOptions o = planner_with_corridor();
  const tp::PlanResult r = tp::plan(start, std::nullopt, pad, o);
  ASSERT_TRUE(r.ok()) << r.message;
  ASSERT_EQ(r.segment_polytopes.size(), 2u);
  for (int k = 0; k < 2; ++k) {
    for (int s = 0; s <= 1000; ++s) {
      const Eigen::Vector3d p = r.trajectory.evaluate_segment(k, s / 1000.0);
      EXPECT_TRUE(r.segment_polytopes[static_cast<std::size_t>(k)].contains(p, 1e-7)) << k << " " << s;
      for (const tp::Box& b : o.obstacles) {
        EXPECT_FALSE(b.contains(p, -o.corridor->radius + 1e-9));
      }
    }
  }
  const auto [v, a] = planner_world_peaks(r, pad);
  EXPECT_LE(v, o.v_max + 1e-9);
  EXPECT_LE(a, o.a_max + 1e-9);
  EXPECT_LT((r.trajectory.evaluate(r.trajectory.total_duration()) - tp::default_goal(o).p).norm(), 1e-9);
}

// The time allocation is at least as good as the best point of the
// published method's offline 31 × 31 grid over the same bounds.
TEST(Planner, TimeAllocationBeatsTheGrid) {
  tp::KinematicState start;
  start.p = Eigen::Vector3d(-3, 0.4, 2.2);
  tp::PadMotion pad;
  pad.velocity = Eigen::Vector3d(2, 0, 0);
  tp::PlannerOptions o = planner_with_corridor();
  o.time.min = 0.3;
  o.time.max = 6;
  o.time.rho = 2;
  const tp::PlanResult r = tp::plan(start, std::nullopt, pad, o);
  ASSERT_TRUE(r.ok()) << r.message;
  double grid_best = INFINITY;
  for (int i = 0; i < 31; ++i) {
    for (int j = 0; j < 31; ++j) {
      tp::PlannerOptions g = o;
      g.durations = {o.time.min + (o.time.max - o.time.min) * i / 30.0,
                     o.time.min + (o.time.max - o.time.min) * j / 30.0};
      const tp::PlanResult q = tp::plan_in_corridor(start, tp::default_goal(o), pad, g, r.segment_polytopes);
      if (q.ok()) grid_best = std::min(grid_best, q.objective);
    }
  }
  ASSERT_LT(grid_best, INFINITY);
  EXPECT_LE(r.objective, grid_best * (1 + 1e-9));
  EXPECT_LT(r.evaluations, 961 / 4);
}

// Two independent eliminations of the same QP: the planner's closed-form
// one (per axis, in the Bézier structure) and QpSolver's Gauss–Jordan one
// on the exported 48-variable QP (semidefinite P, 27 equalities). With
// tight limits several velocity/acceleration rows are active; both must
// give the same control points and cost.
TEST(Planner, ExportedQpSolvedDirectlyGivesThePlannersAnswer) {
  tp::KinematicState start;
  start.p = Eigen::Vector3d(-3, 0.2, 2);
  start.v = Eigen::Vector3d(0.3, 0, 0);
  tp::PadMotion pad;
  pad.velocity = Eigen::Vector3d(2, 0, 0);
  tp::PlannerOptions o = planner_with_corridor();
  o.v_max = 2.5;
  o.a_max = 1.0;
  o.time.rho = 5;
  o.export_qp = true;
  const tp::PlanResult r = tp::plan(start, std::nullopt, pad, o);
  ASSERT_TRUE(r.ok()) << r.message;
  const tp::QpProblem& qp = r.qp;
  ASSERT_EQ(qp.P.rows(), 48);
  Eigen::VectorXd shift = Eigen::VectorXd::Zero(48);  // every control point moved by 1 m in x: no jerk
  for (int i = 0; i < 16; ++i) shift(3 * i) = 1;
  ASSERT_LT((qp.P * shift).norm(), 1e-9 * qp.P.norm());  // P is singular: no definite stand-in used
  tp::QpSolver solver;
  ASSERT_EQ(solver.solve(qp.P, qp.q, qp.A_eq, qp.b_eq, qp.A_in, qp.b_in), tp::QpStatus::Optimal);
  EXPECT_EQ(solver.equality_rank(), 27);
  EXPECT_GE(solver.active_set().size(), 3u);
  EXPECT_NEAR(solver.objective() + qp.constant, r.cost, 1e-7 * r.cost);
  double worst = 0;
  for (int k = 0; k < r.trajectory.segments(); ++k) {
    for (int i = 0; i <= r.trajectory.order(); ++i) {
      const int id = k * (r.trajectory.order() + 1) + i;
      const Eigen::Vector3d c = solver.x().segment<3>(3 * id);
      worst =
          std::max(worst, (c - r.trajectory.all_control_points()[static_cast<std::size_t>(id)]).cwiseAbs().maxCoeff());
    }
  }
  EXPECT_LT(worst, 1e-6);
  EXPECT_LT(solver.kkt().stationarity, 1e-6);
  EXPECT_LT(solver.kkt().primal, 1e-9);
}

// time.max_evaluations is a cap on every QP solve of the time allocation
// (issue 31 item 6: below 18 it had no effect, the coarse grid and the
// guess alone took 17 and the local search at least one more): the
// progress callback sees each solve, and reaching the cap is reported.
TEST(Planner, EvaluationCapIsHonouredExactlyAndReported) {
  tp::KinematicState start;
  start.p = Eigen::Vector3d(-3, 0.4, 2.2);
  tp::PadMotion pad;
  pad.velocity = Eigen::Vector3d(2, 0, 0);
  for (const int cap : {1, 2, 5, 16, 17, 18, 300}) {
    tp::PlannerOptions o = planner_with_corridor();
    o.time.max_evaluations = cap;
    std::vector<std::pair<int, int>> calls;
    o.progress = [&calls](const touchdown::Progress& p) {
      calls.emplace_back(static_cast<int>(p.done), static_cast<int>(p.total));
    };
    const tp::PlanResult r = tp::plan(start, std::nullopt, pad, o);
    // Never a verdict of infeasibility from a search cut short.
    ASSERT_TRUE(r.ok() || r.status == tp::PlanStatus::AllocationCutShort) << "cap " << cap << ": " << r.message;
    if (cap >= 5) {
      EXPECT_TRUE(r.ok()) << "cap " << cap << ": " << r.message;
    }
    EXPECT_LE(r.evaluations, cap);
    ASSERT_EQ(static_cast<int>(calls.size()), r.evaluations) << "cap " << cap;
    for (std::size_t i = 0; i < calls.size(); ++i) {
      EXPECT_EQ(calls[i].first, static_cast<int>(i) + 1);
      EXPECT_EQ(calls[i].second, cap);
    }
    if (cap < 18) {
      // Every one of these stops the allocation early: exactly the cap, reported.
      EXPECT_EQ(r.evaluations, cap);
      EXPECT_TRUE(r.evaluation_cap_reached) << "cap " << cap;
    }
    if (cap == 300) {
      EXPECT_FALSE(r.evaluation_cap_reached);  // converges well before
      EXPECT_LT(r.evaluations, 300);
    }
  }
}

// A cap reached before any feasible durations were seen is not a verdict of
// infeasibility: the status says the allocation was cut short, with no
// trajectory and no diagnosis (which would cost solves beyond the cap); the
// same problem with room to search is planned.
TEST(Planner, CapReachedBeforeAnyFeasibleDurationsIsAllocationCutShort) {
  tp::KinematicState start;
  start.p = Eigen::Vector3d(-10, 0, 2);
  tp::PlannerOptions o = planner_loose(7, 2, {});
  o.a_max = 0.5;  // the first guess (about 1.2 s for 10 m) needs far more
  for (const int cap : {1, 5}) {
    o.time.max_evaluations = cap;
    const tp::PlanResult r = tp::plan(start, std::nullopt, {}, o);
    EXPECT_EQ(r.status, tp::PlanStatus::AllocationCutShort) << "cap " << cap << ": " << r.message;
    EXPECT_TRUE(r.evaluation_cap_reached);
    EXPECT_EQ(r.evaluations, cap);
    EXPECT_TRUE(r.conflicts.empty());
    EXPECT_NE(r.message.find("time.max_evaluations"), std::string::npos) << r.message;
    EXPECT_EQ(tp::to_string(r.status), "allocation_cut_short");
  }
  o.time.max_evaluations = 300;
  const tp::PlanResult r = tp::plan(start, std::nullopt, {}, o);
  EXPECT_TRUE(r.ok()) << r.message;
  EXPECT_FALSE(r.evaluation_cap_reached);
}

TEST(Planner, InfeasibleProblemsNameTheConflictingGroup) {
  tp::KinematicState start;
  start.p = Eigen::Vector3d(-4, 0, 2);
  // Far in little time with a small acceleration: only the acceleration limit conflicts.
  tp::PlannerOptions o = planner_loose(7, 2, {0.8, 0.8});
  o.a_max = 1;
  tp::PlanResult r = tp::plan(start, std::nullopt, {}, o);
  ASSERT_EQ(r.status, tp::PlanStatus::Infeasible);
  EXPECT_EQ(r.conflicts, std::vector<tp::ConstraintGroup>{tp::ConstraintGroup::Acceleration});
  // A tight speed limit: velocity.
  o = planner_loose(7, 2, {1, 1});
  o.v_max = 1;
  r = tp::plan(start, std::nullopt, {}, o);
  ASSERT_EQ(r.status, tp::PlanStatus::Infeasible);
  EXPECT_EQ(r.conflicts, std::vector<tp::ConstraintGroup>{tp::ConstraintGroup::Velocity});
  // A goal velocity above the limit: relaxing the boundary or the velocity group each fixes it.
  o = planner_loose(7, 2, {3, 3});
  o.v_max = 2;
  tp::KinematicState goal;
  goal.p = Eigen::Vector3d(0, 0, 0.5);
  goal.v = Eigen::Vector3d(3, 0, 0);
  r = tp::plan(start, goal, {}, o);
  ASSERT_EQ(r.status, tp::PlanStatus::Infeasible);
  EXPECT_NE(std::find(r.conflicts.begin(), r.conflicts.end(), tp::ConstraintGroup::Boundary), r.conflicts.end());
  EXPECT_NE(std::find(r.conflicts.begin(), r.conflicts.end(), tp::ConstraintGroup::Velocity), r.conflicts.end());
  EXPECT_EQ(std::find(r.conflicts.begin(), r.conflicts.end(), tp::ConstraintGroup::Acceleration), r.conflicts.end());
}

TEST(Planner, RejectsBadInput) {
  tp::KinematicState start;
  start.p = Eigen::Vector3d(-3, 0, 2);
  auto message = [&](tp::PlannerOptions o, tp::KinematicState s = {}) {
    if (s.p.isZero()) s = start;
    try {
      (void)tp::plan(s, std::nullopt, {}, o);
    } catch (const touchdown::InvalidArgument& e) {
      return std::string(e.what());
    }
    return std::string("no error");
  };
  tp::PlannerOptions o;
  o.order = 4;
  EXPECT_NE(message(o).find("order"), std::string::npos);
  o = {};
  o.v_max = -1;
  EXPECT_NE(message(o).find("limits.v_max"), std::string::npos);
  o = {};
  o.durations = {1, 0};
  EXPECT_NE(message(o).find("durations[1]"), std::string::npos);
  o.durations = {1, 2000};  // issue 11: reported infeasible (the QP "not convex")
  EXPECT_NE(message(o).find("durations[1]: must be in [0.001, 1000] s"), std::string::npos);
  o = {};
  o.time.max = 1e9;
  EXPECT_NE(message(o).find("time: need 0.001 <= min < max <= 1000 s"), std::string::npos);
  o = {};
  o.durations = {1};
  EXPECT_NE(message(o).find("durations"), std::string::npos);
  o = planner_with_corridor();
  tp::KinematicState in_obstacle;
  in_obstacle.p = Eigen::Vector3d(-1.45, 0, 0.8);
  EXPECT_NE(message(o, in_obstacle).find("start.p"), std::string::npos);
  tp::KinematicState nan_start = start;
  nan_start.v.x() = std::nan("");
  EXPECT_NE(message(tp::PlannerOptions{}, nan_start).find("start"), std::string::npos);
}
