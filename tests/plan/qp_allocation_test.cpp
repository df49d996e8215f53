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
