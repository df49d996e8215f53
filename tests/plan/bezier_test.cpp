#include "touchdown/plan/bezier.hpp"

#include <gtest/gtest.h>

#include <cmath>
#include <random>

#include "touchdown/core/error.hpp"

namespace tp = touchdown::plan;

namespace {

tp::PiecewiseBezier bezier_random_curve(int order, int segments, std::mt19937& rng) {
  std::uniform_real_distribution<double> point(-2, 2), duration(0.4, 3);
  std::vector<double> durations;
  std::vector<Eigen::Vector3d> cps;
  for (int k = 0; k < segments; ++k) {
    durations.push_back(duration(rng));
    for (int i = 0; i <= order; ++i) {
      const double z = point(rng), y = point(rng);  // one draw per statement: z first, as recorded
      cps.emplace_back(point(rng), y, z);
    }
  }
  return tp::PiecewiseBezier(order, durations, cps);
}

// Composite Gauss–Legendre (5 points) of ‖p'''(t)‖² over each segment.
double bezier_numeric_jerk_cost(const tp::PiecewiseBezier& c) {
  const double x[5] = {0, -0.5384693101056831, 0.5384693101056831, -0.9061798459386640, 0.9061798459386640};
  const double w[5] = {0.5688888888888889, 0.4786286704993665, 0.4786286704993665, 0.2369268850561891,
                       0.2369268850561891};
  double total = 0;
  for (int k = 0; k < c.segments(); ++k) {
    const int pieces = 20;
    for (int j = 0; j < pieces; ++j) {
      const double a = static_cast<double>(j) / pieces, b = static_cast<double>(j + 1) / pieces;
      for (int g = 0; g < 5; ++g) {
        const double tau = 0.5 * (a + b) + 0.5 * (b - a) * x[g];
        total += w[g] * 0.5 * (b - a) * c.duration(k) * c.evaluate_segment(k, tau, 3).squaredNorm();
      }
    }
  }
  return total;
}

}  // namespace

TEST(Bezier, BinomialAndGramAreExact) {
  EXPECT_EQ(tp::binomial(7, 3), 35);
  EXPECT_EQ(tp::binomial(20, 10), 184756);
  EXPECT_EQ(tp::binomial(5, 6), 0);
  // The Bernstein basis is a partition of unity: every row of G sums to ∫ B_i = 1/(m+1).
  for (int m = 0; m <= 12; ++m) {
    const Eigen::MatrixXd G = tp::bernstein_gram(m);
    EXPECT_NEAR((G - G.transpose()).norm(), 0, 1e-15);
    for (int i = 0; i <= m; ++i) EXPECT_NEAR(G.row(i).sum(), 1.0 / (m + 1), 1e-14);
  }
}

// The derivative at 1e-6 steps of the time before it, for orders 5…10.
TEST(Bezier, DerivativesMatchFiniteDifferences) {
  std::mt19937 rng(11);
  for (int n = 5; n <= 10; ++n) {
    const tp::PiecewiseBezier c = bezier_random_curve(n, 3, rng);
    std::uniform_real_distribution<double> when(0.01, c.total_duration() - 0.01);
    for (int trial = 0; trial < 20; ++trial) {
      const double t = when(rng), h = 1e-5;
      for (int j = 1; j <= 3; ++j) {
        const Eigen::Vector3d numeric = (c.evaluate(t + h, j - 1) - c.evaluate(t - h, j - 1)) / (2 * h);
        const Eigen::Vector3d analytic = c.evaluate(t, j);
        EXPECT_LT((numeric - analytic).norm(), 1e-5 * (1 + analytic.norm())) << "order " << n << " derivative " << j;
      }
    }
  }
}

TEST(Bezier, JerkCostMatrixEqualsNumericalIntegration) {
  std::mt19937 rng(12);
  for (int n = 5; n <= 10; ++n) {
    for (int trial = 0; trial < 5; ++trial) {
      const tp::PiecewiseBezier c = bezier_random_curve(n, 2, rng);
      const double exact = c.jerk_cost(), numeric = bezier_numeric_jerk_cost(c);
      EXPECT_NEAR(exact, numeric, 1e-9 * numeric) << "order " << n;
    }
  }
}

// The quintic 10τ³ − 15τ⁴ + 6τ⁵ (rest to rest over D in T) has Bernstein
// control points (0, 0, 0, D, D, D) and jerk cost 720 D²/T⁵; elevated to
// any order it is the same curve with the same cost.
TEST(Bezier, RestToRestQuinticCostsItsClosedForm) {
  const double D = 1.7, T = 2.3;
  std::vector<Eigen::Vector3d> quintic;
  for (int i = 0; i < 6; ++i) quintic.emplace_back(i < 3 ? 0.0 : D, 0, 0);
  const tp::PiecewiseBezier c5(5, {T}, quintic);
  EXPECT_NEAR(c5.jerk_cost(), 720 * D * D / std::pow(T, 5), 1e-9);
  for (const double tau : {0.1, 0.5, 0.77}) {
    const double expected = D * (10 * std::pow(tau, 3) - 15 * std::pow(tau, 4) + 6 * std::pow(tau, 5));
    EXPECT_NEAR(c5.evaluate(tau * T).x(), expected, 1e-12);
  }
  for (int n = 6; n <= 10; ++n) {
    const Eigen::MatrixXd E = tp::elevation_matrix(5, n - 5);
    std::vector<Eigen::Vector3d> elevated(static_cast<std::size_t>(n + 1), Eigen::Vector3d::Zero());
    for (int i = 0; i <= n; ++i) {
      for (int j = 0; j <= 5; ++j)
        elevated[static_cast<std::size_t>(i)] += E(i, j) * quintic[static_cast<std::size_t>(j)];
    }
    const tp::PiecewiseBezier cn(n, {T}, elevated);
    EXPECT_NEAR(cn.jerk_cost(), c5.jerk_cost(), 1e-9) << n;
    EXPECT_NEAR((cn.evaluate(0.3 * T, 2) - c5.evaluate(0.3 * T, 2)).norm(), 0, 1e-10) << n;
  }
}

TEST(Bezier, HodographControlPointsDescribeTheDerivative) {
  std::mt19937 rng(13);
  const tp::PiecewiseBezier c = bezier_random_curve(7, 2, rng);
  for (int j = 1; j <= 3; ++j) {
    const std::vector<Eigen::Vector3d> h = c.derivative_control_points(1, j);
    ASSERT_EQ(static_cast<int>(h.size()), 7 - j + 1);
    // The hodograph as a curve of duration T (its own 1/T^j already applied) evaluates to the derivative.
    const tp::PiecewiseBezier hc(7 - j, {c.duration(1)}, h);
    for (const double tau : {0.0, 0.25, 0.6, 1.0}) {
      EXPECT_LT((hc.evaluate_segment(0, tau) - c.evaluate_segment(1, tau, j)).norm(), 1e-9);
    }
  }
}

TEST(Bezier, HullBoundsContainTheCurve) {
  std::mt19937 rng(14);
  const tp::PiecewiseBezier c = bezier_random_curve(7, 3, rng);
  for (int j = 0; j <= 2; ++j) {
    const auto b = c.hull_bounds(j);
    for (int s = 0; s <= 1000; ++s) {
      const Eigen::Vector3d v = c.evaluate(c.total_duration() * s / 1000.0, j);
      EXPECT_TRUE((v.array() >= b.min.array() - 1e-12).all() && (v.array() <= b.max.array() + 1e-12).all());
    }
    // Each end control point lies on its curve, so a bound is never looser than needed there.
    const auto cps = c.derivative_control_points(0, j);
    EXPECT_LT((cps.front() - c.evaluate_segment(0, 0, j)).norm(), 1e-9);
  }
}

TEST(Bezier, RejectsBadCurves) {
  EXPECT_THROW(tp::PiecewiseBezier(7, {1.0}, std::vector<Eigen::Vector3d>(7)), touchdown::InvalidArgument);
  EXPECT_THROW(tp::PiecewiseBezier(7, {0.0}, std::vector<Eigen::Vector3d>(8)), touchdown::InvalidArgument);
  EXPECT_THROW(tp::PiecewiseBezier(0, {1.0}, std::vector<Eigen::Vector3d>(1)), touchdown::InvalidArgument);
  EXPECT_THROW(tp::jerk_cost_matrix(2, 1.0), touchdown::InvalidArgument);
  EXPECT_THROW(tp::jerk_cost_matrix(7, -1.0), touchdown::InvalidArgument);
}
