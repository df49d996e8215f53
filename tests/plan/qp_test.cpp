#include "touchdown/plan/qp.hpp"

#include <gtest/gtest.h>

#include <Eigen/LU>
#include <nlopt.hpp>
#include <random>

#include "touchdown/core/error.hpp"

namespace tp = touchdown::plan;

namespace {

struct QpInstance {
  Eigen::MatrixXd P, A_eq, A_in;
  Eigen::VectorXd q, b_eq, b_in;
  Eigen::VectorXd feasible;  // a strictly feasible point (SLSQP starts there)
};

// A random strictly convex QP with a strictly feasible point x_f: b_in =
// A_in x_f + a positive margin, so it is feasible and some constraints are
// active at the optimum (q pulls far away).
QpInstance qp_random_instance(int n, int m_eq, int m_in, std::mt19937& rng) {
  std::normal_distribution<double> g(0, 1);
  std::uniform_real_distribution<double> margin(0.01, 1);
  QpInstance p;
  Eigen::MatrixXd M(n, n);
  for (int i = 0; i < n; ++i) {
    for (int j = 0; j < n; ++j) M(i, j) = g(rng);
  }
  p.P = M * M.transpose() / n + Eigen::MatrixXd::Identity(n, n);
  p.q.resize(n);
  for (int i = 0; i < n; ++i) p.q(i) = 10 * g(rng);
  Eigen::VectorXd xf(n);
  for (int i = 0; i < n; ++i) xf(i) = g(rng);
  p.A_eq.resize(m_eq, n);
  p.A_in.resize(m_in, n);
  for (int i = 0; i < m_eq; ++i) {
    for (int j = 0; j < n; ++j) p.A_eq(i, j) = g(rng);
  }
  for (int i = 0; i < m_in; ++i) {
    for (int j = 0; j < n; ++j) p.A_in(i, j) = g(rng);
  }
  p.feasible = xf;
  p.b_eq = p.A_eq * xf;
  p.b_in = p.A_in * xf;
  for (int i = 0; i < m_in; ++i) p.b_in(i) += margin(rng);
  return p;
}

struct QpSlsqpData {
  const QpInstance* p;
  int row;
};

double qp_slsqp_objective(unsigned n, const double* x, double* grad, void* data) {
  const auto* p = static_cast<const QpInstance*>(data);
  const Eigen::Map<const Eigen::VectorXd> xv(x, n);
  const Eigen::VectorXd g = p->P * xv + p->q;
  if (grad) Eigen::Map<Eigen::VectorXd>(grad, n) = g;
  return 0.5 * xv.dot(p->P * xv) + p->q.dot(xv);
}

double qp_slsqp_eq(unsigned n, const double* x, double* grad, void* data) {
  const auto* d = static_cast<const QpSlsqpData*>(data);
  const Eigen::Map<const Eigen::VectorXd> xv(x, n);
  if (grad) Eigen::Map<Eigen::VectorXd>(grad, n) = d->p->A_eq.row(d->row).transpose();
  return d->p->A_eq.row(d->row).dot(xv) - d->p->b_eq(d->row);
}

double qp_slsqp_in(unsigned n, const double* x, double* grad, void* data) {
  const auto* d = static_cast<const QpSlsqpData*>(data);
  const Eigen::Map<const Eigen::VectorXd> xv(x, n);
  if (grad) Eigen::Map<Eigen::VectorXd>(grad, n) = d->p->A_in.row(d->row).transpose();
  return d->p->A_in.row(d->row).dot(xv) - d->p->b_in(d->row);
}

double qp_objective(const QpInstance& p, const Eigen::VectorXd& x) { return 0.5 * x.dot(p.P * x) + p.q.dot(x); }

double qp_violation(const QpInstance& p, const Eigen::VectorXd& x) {
  double v = 0;
  if (p.A_eq.rows() > 0) v = (p.A_eq * x - p.b_eq).cwiseAbs().maxCoeff();
  if (p.A_in.rows() > 0) v = std::max(v, (p.A_in * x - p.b_in).maxCoeff());
  return v;
}

// SLSQP stops about 1e-6 from the optimum. Polish (as OSQP does): solve
// the KKT system of the equalities and the inequalities tight at x (a
// plain linear solve, independent of the solver under test) and keep the
// result when it is feasible with non-negative multipliers.
Eigen::VectorXd qp_polish(const QpInstance& p, const Eigen::VectorXd& x) {
  const auto n = p.P.rows();
  std::vector<int> tight;
  for (int i = 0; i < p.A_in.rows(); ++i) {
    if (p.b_in(i) - p.A_in.row(i).dot(x) < 1e-5) tight.push_back(i);
  }
  const auto m = p.A_eq.rows() + static_cast<Eigen::Index>(tight.size());
  Eigen::MatrixXd A(m, n);
  Eigen::VectorXd b(m);
  A.topRows(p.A_eq.rows()) = p.A_eq;
  b.head(p.A_eq.rows()) = p.b_eq;
  for (std::size_t k = 0; k < tight.size(); ++k) {
    A.row(p.A_eq.rows() + static_cast<Eigen::Index>(k)) = p.A_in.row(tight[k]);
    b(p.A_eq.rows() + static_cast<Eigen::Index>(k)) = p.b_in(tight[k]);
  }
  Eigen::MatrixXd K = Eigen::MatrixXd::Zero(n + m, n + m);
  K.topLeftCorner(n, n) = p.P;
  K.topRightCorner(n, m) = A.transpose();
  K.bottomLeftCorner(m, n) = A;
  Eigen::VectorXd rhs(n + m);
  rhs << -p.q, b;
  const Eigen::VectorXd sol = K.fullPivLu().solve(rhs);
  const Eigen::VectorXd polished = sol.head(n);
  const bool signs_ok = m == p.A_eq.rows() || sol.tail(static_cast<Eigen::Index>(tight.size())).minCoeff() >= -1e-9;
  return signs_ok && (K * sol - rhs).norm() < 1e-9 && qp_violation(p, polished) < 1e-9 ? polished : x;
}

// NLopt's SLSQP (Kraft 1988) on the same QP: an independent solver. Its
// line search sometimes gives up at the start ("roundoff limited") or
// stalls, so it runs from several starts (the known feasible point, the
// origin, points around the first), restarting from where it stopped while the objective drops, and
// the better feasible answer is the reference.
Eigen::VectorXd qp_slsqp_solve(const QpInstance& p) {
  const auto n = static_cast<unsigned>(p.P.rows());
  std::vector<QpSlsqpData> eq, in;
  for (int i = 0; i < p.A_eq.rows(); ++i) eq.push_back({&p, i});
  for (int i = 0; i < p.A_in.rows(); ++i) in.push_back({&p, i});
  Eigen::VectorXd answer = p.feasible;
  std::vector<Eigen::VectorXd> starts = {p.feasible, Eigen::VectorXd::Zero(n)};
  std::mt19937 rng(n);
  std::normal_distribution<double> g(0, 1);
  for (int k = 0; k < 4; ++k)
    starts.push_back(p.feasible + 0.5 * Eigen::VectorXd::NullaryExpr(n, [&] { return g(rng); }));
  for (const Eigen::VectorXd& start : starts) {
    std::vector<double> x(start.data(), start.data() + n);
    double best = INFINITY;
    for (int restart = 0; restart < 20; ++restart) {
      nlopt::opt opt(nlopt::LD_SLSQP, n);
      opt.set_min_objective(qp_slsqp_objective, const_cast<QpInstance*>(&p));
      for (auto& d : eq) opt.add_equality_constraint(qp_slsqp_eq, &d, 1e-12);
      for (auto& d : in) opt.add_inequality_constraint(qp_slsqp_in, &d, 1e-12);
      opt.set_xtol_rel(0);
      opt.set_ftol_rel(0);
      opt.set_maxeval(20000);
      double f = 0;
      try {
        opt.optimize(x, f);
      } catch (const nlopt::roundoff_limited&) {
        f = qp_objective(p, Eigen::Map<Eigen::VectorXd>(x.data(), n));  // x is SLSQP's best point
      }
      if (f > best - 1e-13 * (1 + std::abs(best))) break;
      best = f;
    }
    const Eigen::VectorXd candidate = qp_polish(p, Eigen::Map<Eigen::VectorXd>(x.data(), n));
    if (qp_violation(p, candidate) < 1e-9 && qp_objective(p, candidate) < qp_objective(p, answer)) answer = candidate;
  }
  return answer;
}

}  // namespace

TEST(QpSolver, ProjectionOntoABoxHasItsKnownAnswer) {
  // min ½‖x − (2, −3, 0.5)‖² s.t. x ≤ 1, y ≥ −1, z ≤ 4: (1, −1, 0.5), μ = (1, 2, 0).
  tp::QpSolver solver;
  const Eigen::MatrixXd P = Eigen::MatrixXd::Identity(3, 3);
  const Eigen::Vector3d q(-2, 3, -0.5);
  Eigen::MatrixXd A(3, 3);
  A << 1, 0, 0, 0, -1, 0, 0, 0, 1;
  const Eigen::Vector3d b(1, 1, 4);
  ASSERT_EQ(solver.solve(P, q, Eigen::MatrixXd(0, 3), Eigen::VectorXd(0), A, b), tp::QpStatus::Optimal);
  EXPECT_NEAR((solver.x() - Eigen::Vector3d(1, -1, 0.5)).norm(), 0, 1e-12);
  EXPECT_NEAR((solver.multipliers_in() - Eigen::Vector3d(1, 2, 0)).norm(), 0, 1e-12);
  EXPECT_EQ(solver.active_set().size(), 2u);
  EXPECT_LT(solver.kkt().stationarity, 1e-12);
}

TEST(QpSolver, EqualityConstrainedMatchesTheKktSystem) {
  std::mt19937 rng(3);
  const QpInstance p = qp_random_instance(8, 3, 0, rng);
  Eigen::MatrixXd K = Eigen::MatrixXd::Zero(11, 11);
  K.topLeftCorner(8, 8) = p.P;
  K.topRightCorner(8, 3) = p.A_eq.transpose();
  K.bottomLeftCorner(3, 8) = p.A_eq;
  Eigen::VectorXd rhs(11);
  rhs << -p.q, p.b_eq;
  const Eigen::VectorXd sol = K.fullPivLu().solve(rhs);
  tp::QpSolver solver;
  ASSERT_EQ(solver.solve(p.P, p.q, p.A_eq, p.b_eq, p.A_in, p.b_in), tp::QpStatus::Optimal);
  EXPECT_LT((solver.x() - sol.head(8)).norm(), 1e-9);
  EXPECT_LT((solver.multipliers_eq() - sol.tail(3)).norm(), 1e-8);
}

// Random instances against SLSQP: the same minimiser to 1e-6, and KKT
// residuals of our solution near machine precision.
TEST(QpSolver, RandomInstancesEqualSlsqp) {
  std::mt19937 rng(5);
  int active_total = 0;
  for (int trial = 0; trial < 30; ++trial) {
    const int n = 5 + trial % 20, m_eq = trial % 4, m_in = 2 * n + trial % 7;
    const QpInstance p = qp_random_instance(n, m_eq, m_in, rng);
    tp::QpSolver solver;
    ASSERT_EQ(solver.solve(p.P, p.q, p.A_eq, p.b_eq, p.A_in, p.b_in), tp::QpStatus::Optimal) << trial;
    const Eigen::VectorXd reference = qp_slsqp_solve(p);
    EXPECT_LT((solver.x() - reference).cwiseAbs().maxCoeff(), 1e-6) << "trial " << trial << " n " << n;
    EXPECT_LT(solver.kkt().stationarity, 1e-8 * (1 + p.q.norm()));
    EXPECT_LT(solver.kkt().primal, 1e-9);
    EXPECT_LT(solver.kkt().dual, 1e-12);
    EXPECT_LT(solver.kkt().complementarity, 1e-8);
    active_total += static_cast<int>(solver.active_set().size());
  }
  EXPECT_GT(active_total, 30);  // the instances do exercise the inequalities
}

// P only semidefinite (rank n − k) but definite on A_eq's null space: the
// elimination makes the problem strictly convex. Oracle: the KKT system of
// the equalities and the inequalities active at our answer, solved by a
// plain LU, with non-negative multipliers; and SLSQP's minimiser.
TEST(QpSolver, SemidefiniteHessianDefiniteOnTheEqualitiesNullSpace) {
  std::mt19937 rng(11);
  std::normal_distribution<double> g(0, 1);
  for (int trial = 0; trial < 10; ++trial) {
    const int n = 8 + trial, m_eq = 3, k = 2 + trial % 2;
    QpInstance p = qp_random_instance(n, m_eq, 2 * n, rng);
    const Eigen::MatrixXd B = Eigen::MatrixXd::NullaryExpr(n, n - k, [&] { return g(rng); });
    p.P = B * B.transpose() / n;  // rank n − k ≤ n: singular
    tp::QpSolver solver;
    ASSERT_EQ(solver.solve(p.P, p.q, p.A_eq, p.b_eq, p.A_in, p.b_in), tp::QpStatus::Optimal) << trial;
    const Eigen::VectorXd reference = qp_slsqp_solve(p);
    EXPECT_LT((solver.x() - reference).cwiseAbs().maxCoeff(), 1e-6) << trial;
    EXPECT_LT(solver.kkt().stationarity, 1e-8 * (1 + p.q.norm())) << trial;
    EXPECT_LT(solver.kkt().primal, 1e-9) << trial;
    EXPECT_LT(solver.kkt().dual, 1e-12) << trial;
  }
  // Singular on the null space too (a free direction of zero curvature): not convex enough.
  const Eigen::MatrixXd P = Eigen::Vector3d(1, 1, 0).asDiagonal();
  Eigen::MatrixXd E(1, 3);
  E << 1, 0, 0;
  tp::QpSolver solver;
  EXPECT_EQ(solver.solve(P, Eigen::Vector3d(0, 0, 1), E, Eigen::VectorXd::Constant(1, 2), Eigen::MatrixXd(0, 3),
                         Eigen::VectorXd(0)),
            tp::QpStatus::NotConvex);
  // ... and pinned by a second equality it is fine: x = (2, −q_y, 5).
  Eigen::MatrixXd E2(2, 3);
  E2 << 1, 0, 0, 0, 0, 1;
  ASSERT_EQ(
      solver.solve(P, Eigen::Vector3d(0, 0.5, 1), E2, Eigen::Vector2d(2, 5), Eigen::MatrixXd(0, 3), Eigen::VectorXd(0)),
      tp::QpStatus::Optimal);
  EXPECT_LT((solver.x() - Eigen::Vector3d(2, -0.5, 5)).norm(), 1e-12);
  EXPECT_LT((solver.multipliers_eq() - Eigen::Vector2d(-2, -1)).norm(), 1e-12);  // P x + q + Aᵀλ = 0
}

// More equalities than variables, dependent and consistent (each row twice,
// scaled, plus sums): the rank is found, the answer and KKT residuals hold.
TEST(QpSolver, DependentEqualitiesBeyondTheVariableCount) {
  std::mt19937 rng(12);
  const QpInstance base = qp_random_instance(6, 3, 10, rng);
  QpInstance p = base;
  p.A_eq.resize(8, 6);
  p.b_eq.resize(8);
  p.A_eq.topRows(3) = base.A_eq;
  p.b_eq.head(3) = base.b_eq;
  p.A_eq.middleRows(3, 3) = -2.5 * base.A_eq;
  p.b_eq.segment(3, 3) = -2.5 * base.b_eq;
  p.A_eq.row(6) = base.A_eq.row(0) + base.A_eq.row(2);
  p.b_eq(6) = base.b_eq(0) + base.b_eq(2);
  p.A_eq.row(7) = 1e3 * base.A_eq.row(1);
  p.b_eq(7) = 1e3 * base.b_eq(1);
  tp::QpSolver reduced, full;
  ASSERT_EQ(reduced.solve(base.P, base.q, base.A_eq, base.b_eq, base.A_in, base.b_in), tp::QpStatus::Optimal);
  ASSERT_EQ(full.solve(p.P, p.q, p.A_eq, p.b_eq, p.A_in, p.b_in), tp::QpStatus::Optimal);
  EXPECT_EQ(full.equality_rank(), 3);
  EXPECT_LT((full.x() - reduced.x()).norm(), 1e-10);
  EXPECT_LT(full.kkt().stationarity, 1e-9 * (1 + p.q.norm()));
  EXPECT_LT(full.kkt().primal, 1e-9);
  // 7 independent equalities on 6 variables: x is fixed by six, the 7th contradicts.
  Eigen::MatrixXd A = Eigen::MatrixXd::Identity(7, 6);
  A(6, 0) = 1;
  A(6, 1) = 1;
  Eigen::VectorXd b = Eigen::VectorXd::Zero(7);
  b(6) = 1;
  EXPECT_EQ(full.solve(p.P, p.q, A, b, Eigen::MatrixXd(0, 6), Eigen::VectorXd(0)), tp::QpStatus::Infeasible);
  b(6) = 0;  // consistent: x = 0 whatever the objective, the inequalities then decide
  EXPECT_EQ(full.solve(p.P, p.q, A, b, Eigen::MatrixXd(0, 6), Eigen::VectorXd(0)), tp::QpStatus::Optimal);
  EXPECT_LT(full.x().norm(), 1e-12);
  Eigen::MatrixXd G = Eigen::MatrixXd::Zero(1, 6);
  G(0, 3) = -1;  // −x₃ ≤ −1 contradicts x₃ = 0
  EXPECT_EQ(full.solve(p.P, p.q, A, b, G, Eigen::VectorXd::Constant(1, -1)), tp::QpStatus::Infeasible);
  EXPECT_EQ(full.blocking_constraint(), 0);
}

TEST(QpSolver, WarmStartGivesTheSameAnswerInFewerSteps) {
  std::mt19937 rng(6);
  QpInstance p = qp_random_instance(20, 2, 50, rng);
  tp::QpSolver solver;
  ASSERT_EQ(solver.solve(p.P, p.q, p.A_eq, p.b_eq, p.A_in, p.b_in), tp::QpStatus::Optimal);
  const int cold_iterations = solver.iterations();
  // A slightly different problem (as the next replan): warm and cold agree.
  p.q *= 1.02;
  tp::QpSolver cold;
  ASSERT_EQ(cold.solve(p.P, p.q, p.A_eq, p.b_eq, p.A_in, p.b_in), tp::QpStatus::Optimal);
  ASSERT_EQ(solver.solve(p.P, p.q, p.A_eq, p.b_eq, p.A_in, p.b_in, true), tp::QpStatus::Optimal);
  EXPECT_LT((solver.x() - cold.x()).norm(), 1e-9);
  EXPECT_LE(solver.iterations(), cold.iterations());
  EXPECT_GT(cold_iterations, 2 + 2);  // there were inequalities to add at all
}

TEST(QpSolver, ContradictoryConstraintsAreInfeasible) {
  tp::QpSolver solver;
  const Eigen::MatrixXd P = Eigen::MatrixXd::Identity(2, 2);
  const Eigen::Vector2d q(0.3, -0.1);
  // x ≤ 0 and x ≥ 1 among satisfiable ones.
  Eigen::MatrixXd A(4, 2);
  A << 0, 1, 1, 0, 0, -1, -1, 0;
  const Eigen::Vector4d b(5, 0, 5, -1);
  EXPECT_EQ(solver.solve(P, q, Eigen::MatrixXd(0, 2), Eigen::VectorXd(0), A, b), tp::QpStatus::Infeasible);
  EXPECT_FALSE(solver.ok());
  EXPECT_EQ(solver.message(), "infeasible");
  EXPECT_TRUE(solver.blocking_constraint() == 1 || solver.blocking_constraint() == 3);
  // Equalities that contradict each other.
  Eigen::MatrixXd E(2, 2);
  E << 1, 1, 2, 2;
  EXPECT_EQ(solver.solve(P, q, E, Eigen::Vector2d(1, 3), Eigen::MatrixXd(0, 2), Eigen::VectorXd(0)),
            tp::QpStatus::Infeasible);
  // ... and consistent dependent ones are fine.
  EXPECT_EQ(solver.solve(P, q, E, Eigen::Vector2d(1, 2), Eigen::MatrixXd(0, 2), Eigen::VectorXd(0)),
            tp::QpStatus::Optimal);
  EXPECT_NEAR(solver.x().sum(), 1, 1e-12);
  // A triangle that excludes the equality line x + y = 3: x ≥ 0, y ≥ 0, x + y ≤ 1.
  Eigen::MatrixXd T(3, 2);
  T << -1, 0, 0, -1, 1, 1;
  EXPECT_EQ(solver.solve(P, q, Eigen::RowVector2d(1, 1), Eigen::VectorXd::Constant(1, 3), T, Eigen::Vector3d(0, 0, 1)),
            tp::QpStatus::Infeasible);
}

TEST(QpSolver, RandomInfeasibleInstancesAreNeverReportedOptimal) {
  std::mt19937 rng(8);
  for (int trial = 0; trial < 20; ++trial) {
    QpInstance p = qp_random_instance(10, 2, 30, rng);
    // Add a ≤ −1 − a·x_anything conflict: a·x ≤ c and −a·x ≤ −c − 1.
    const Eigen::VectorXd a = p.A_in.row(trial % 30).transpose();
    p.A_in.conservativeResize(32, Eigen::NoChange);
    p.b_in.conservativeResize(32);
    p.A_in.row(30) = a.transpose();
    p.b_in(30) = 0.5;
    p.A_in.row(31) = -a.transpose();
    p.b_in(31) = -1.5;
    tp::QpSolver solver;
    EXPECT_EQ(solver.solve(p.P, p.q, p.A_eq, p.b_eq, p.A_in, p.b_in), tp::QpStatus::Infeasible) << trial;
  }
}

TEST(QpSolver, DuplicateConstraintsAreHandled) {
  tp::QpSolver solver;
  const Eigen::MatrixXd P = Eigen::MatrixXd::Identity(2, 2);
  Eigen::MatrixXd A(3, 2);
  A << 1, 0, 2, 0, 1, 1;  // x ≤ 1 twice (scaled) and x + y ≤ 1
  ASSERT_EQ(
      solver.solve(P, Eigen::Vector2d(-3, -3), Eigen::MatrixXd(0, 2), Eigen::VectorXd(0), A, Eigen::Vector3d(1, 2, 1)),
      tp::QpStatus::Optimal);
  EXPECT_NEAR((solver.x() - Eigen::Vector2d(0.5, 0.5)).norm(), 0, 1e-12);
}

TEST(QpSolver, ReportsIndefiniteHessianAndIterationLimit) {
  tp::QpSolver solver;
  Eigen::Matrix2d P;
  P << 1, 0, 0, -1;
  EXPECT_EQ(solver.solve(P, Eigen::Vector2d::Zero(), Eigen::MatrixXd(0, 2), Eigen::VectorXd(0), Eigen::MatrixXd(0, 2),
                         Eigen::VectorXd(0)),
            tp::QpStatus::NotConvex);
  std::mt19937 rng(9);
  const QpInstance p = qp_random_instance(10, 0, 30, rng);
  tp::QpSolver limited(tp::QpOptions{.max_iterations = 1});
  EXPECT_EQ(limited.solve(p.P, p.q, p.A_eq, p.b_eq, p.A_in, p.b_in), tp::QpStatus::IterationLimit);
  EXPECT_THROW(tp::QpSolver(tp::QpOptions{.max_iterations = -1}), touchdown::InvalidArgument);
  EXPECT_THROW(solver.solve(Eigen::MatrixXd::Identity(2, 2), Eigen::Vector3d::Zero(), Eigen::MatrixXd(0, 2),
                            Eigen::VectorXd(0), Eigen::MatrixXd(0, 2), Eigen::VectorXd(0)),
               touchdown::InvalidArgument);
  Eigen::Vector2d nan_q(std::nan(""), 0);
  EXPECT_THROW(solver.solve(Eigen::MatrixXd::Identity(2, 2), nan_q, Eigen::MatrixXd(0, 2), Eigen::VectorXd(0),
                            Eigen::MatrixXd(0, 2), Eigen::VectorXd(0)),
               touchdown::InvalidArgument);
}
