// QpSolver::solve must not touch the heap once sized (qp.hpp, issue 10): a
// counting global operator new, armed only around the solves.
#include <gtest/gtest.h>

#include <random>

#include "counting_new.hpp"
#include "touchdown/plan/qp.hpp"

TEST(QpAllocation, SolveDoesNotAllocateOnceSized) {
  std::mt19937 rng(2);
  std::normal_distribution<double> g(0, 1);
  const int n = 21, me = 3, mi = 120;
  Eigen::MatrixXd M = Eigen::MatrixXd::NullaryExpr(n, n, [&] { return g(rng); });
  const Eigen::MatrixXd P = M * M.transpose() / n + Eigen::MatrixXd::Identity(n, n);
  const Eigen::MatrixXd A_eq = Eigen::MatrixXd::NullaryExpr(me, n, [&] { return g(rng); });
  const Eigen::MatrixXd A_in = Eigen::MatrixXd::NullaryExpr(mi, n, [&] { return g(rng); });
  const Eigen::VectorXd x_feasible = Eigen::VectorXd::NullaryExpr(n, [&] { return g(rng); });
  const Eigen::VectorXd b_eq = A_eq * x_feasible;
  const Eigen::VectorXd b_in = A_in * x_feasible + Eigen::VectorXd::Constant(mi, 0.2);
  Eigen::VectorXd q = 10 * Eigen::VectorXd::NullaryExpr(n, [&] { return g(rng); });
  touchdown::plan::QpSolver solver;
  solver.resize(n, me, mi);
  ASSERT_EQ(solver.solve(P, q, A_eq, b_eq, A_in, b_in), touchdown::plan::QpStatus::Optimal);
  ASSERT_GT(solver.active_set().size(), 2u);  // inequalities are added and dropped
  long allocations = 0;
  for (int trial = 0; trial < 20; ++trial) {
    q(trial % n) += 0.5;
    g_allocations = 0;
    g_armed = true;
    const auto status = solver.solve(P, q, A_eq, b_eq, A_in, b_in, trial % 2 == 1);
    g_armed = false;
    allocations += g_allocations;
    EXPECT_EQ(status, touchdown::plan::QpStatus::Optimal);
  }
  EXPECT_EQ(allocations, 0);
}

// The Replanner (planner.hpp) replans the bundled landing at the remaining
// durations without touching the heap once sized, and gives the plan
// plan_in_corridor() gives at the same durations.
#include "touchdown/plan/planner.hpp"
#include "touchdown/plan/problem_io.hpp"

TEST(PlanAllocation, ReplanInAKeptCorridorDoesNotAllocate) {
  namespace tp = touchdown::plan;
  const tp::PlanProblem problem = tp::load_plan_problem(std::string(TOUCHDOWN_SOURCE_DIR) + "/data/plans/landing.yaml");
  const tp::PlanResult first = tp::plan(problem.start, problem.goal, problem.pad, problem.options);
  ASSERT_TRUE(first.ok()) << first.message;
  const tp::KinematicState goal = problem.goal ? *problem.goal : tp::default_goal(problem.options);
  tp::Replanner replanner(problem.options, first.segment_polytopes);
  std::vector<double> T;
  for (int k = 0; k < first.trajectory.segments(); ++k) T.push_back(first.trajectory.duration(k));
  ASSERT_EQ(replanner.plan(problem.start, goal, problem.pad, T), tp::PlanStatus::Ok);  // sizes the work space
  long allocations = 0;
  for (int i = 1; i <= 10; ++i) {
    // From the plan's state 0.1 s on, at what is left of its durations.
    const double t = 0.1 * i;
    const tp::KinematicState from{first.trajectory.evaluate(t), first.trajectory.evaluate(t, 1),
                                  first.trajectory.evaluate(t, 2)};
    T[0] = first.trajectory.duration(0) - t;
    g_allocations = 0;
    g_armed = true;
    const tp::PlanStatus status = replanner.plan(from, goal, problem.pad, T);
    g_armed = false;
    allocations += g_allocations;
    ASSERT_EQ(status, tp::PlanStatus::Ok) << "t = " << t;
    // The same plan as plan_in_corridor at these durations.
    tp::PlannerOptions fixed = problem.options;
    fixed.durations = T;
    const tp::PlanResult reference = tp::plan_in_corridor(from, goal, problem.pad, fixed, first.segment_polytopes);
    ASSERT_TRUE(reference.ok());
    const auto a = replanner.trajectory().all_control_points(), b = reference.trajectory.all_control_points();
    ASSERT_EQ(a.size(), b.size());
    for (std::size_t k = 0; k < a.size(); ++k) EXPECT_LT((a[k] - b[k]).norm(), 1e-9) << k;
    EXPECT_NEAR(replanner.cost(), reference.cost, 1e-9 * (1 + reference.cost));
  }
  EXPECT_EQ(allocations, 0);
  // Outside the corridor: a status, not an exception.
  tp::KinematicState outside = problem.start;
  outside.p.z() = -5;
  EXPECT_EQ(replanner.plan(outside, goal, problem.pad, T), tp::PlanStatus::NoCorridor);
}
