#include "touchdown/plan/bezier.hpp"

#include <algorithm>
#include <array>
#include <cmath>
#include <string>

#include "touchdown/core/error.hpp"

namespace touchdown::plan {

namespace {

constexpr int kMaxOrder = 20;  // evaluation works in a fixed buffer of this many + 1 points

void require(bool condition, const std::string& message) {
  if (!condition) throw InvalidArgument(message);
}

// n!/(n−j)!: the factor of the j-th derivative of an order-n curve.
double falling_factorial(int n, int j) {
  double f = 1;
  for (int i = 0; i < j; ++i) f *= n - i;
  return f;
}

}  // namespace

double binomial(int n, int k) {
  if (k < 0 || k > n || n < 0) return 0;
  k = std::min(k, n - k);
  double c = 1;
  for (int i = 1; i <= k; ++i) c = c * (n - k + i) / i;
  return std::round(c);
}

Eigen::MatrixXd bernstein_gram(int m) {
  require(m >= 0, "bernstein_gram: order must be >= 0, got " + std::to_string(m));
  Eigen::MatrixXd G(m + 1, m + 1);
  for (int i = 0; i <= m; ++i) {
    for (int j = 0; j <= m; ++j) {
      // ∫₀¹ τ^(i+j) (1−τ)^(2m−i−j) dτ = 1 / ((2m+1) C(2m, i+j)) (the Beta function).
      G(i, j) = binomial(m, i) * binomial(m, j) / (binomial(2 * m, i + j) * (2 * m + 1));
    }
  }
  return G;
}

Eigen::MatrixXd derivative_matrix(int n, int j) {
  require(n >= 0 && j >= 0 && j <= n,
          "derivative_matrix: need 0 <= derivative <= order, got " + std::to_string(j) + " of " + std::to_string(n));
  // j-th forward difference: Δ^j c_i = Σ_k (−1)^(j−k) C(j, k) c_{i+k}.
  Eigen::MatrixXd D = Eigen::MatrixXd::Zero(n - j + 1, n + 1);
  const double scale = falling_factorial(n, j);
  for (int i = 0; i <= n - j; ++i) {
    for (int k = 0; k <= j; ++k) D(i, i + k) = scale * (((j - k) % 2) ? -1.0 : 1.0) * binomial(j, k);
  }
  return D;
}

Eigen::MatrixXd elevation_matrix(int n, int r) {
  require(n >= 0 && r >= 0, "elevation_matrix: order and elevation must be >= 0");
  // Repeated single-step elevation: e_i = (i/(m+1)) c_{i−1} + (1 − i/(m+1)) c_i.
  Eigen::MatrixXd E = Eigen::MatrixXd::Identity(n + 1, n + 1);
  for (int m = n; m < n + r; ++m) {
    Eigen::MatrixXd step = Eigen::MatrixXd::Zero(m + 2, m + 1);
    for (int i = 0; i <= m + 1; ++i) {
      const double a = static_cast<double>(i) / (m + 1);
      if (i >= 1) step(i, i - 1) = a;
      if (i <= m) step(i, i) = 1 - a;
    }
    E = step * E;
  }
  return E;
}

Eigen::MatrixXd jerk_cost_matrix(int n, double duration) {
  require(n >= 3, "jerk_cost_matrix: order must be >= 3, got " + std::to_string(n));
  require(std::isfinite(duration) && duration > 0, "jerk_cost_matrix: duration must be > 0");
  // d³p/dt³ = (1/T³) Σ d_i B_i^(n−3)(τ), dt = T dτ: ∫ = dᵀ G d / T⁵.
  const Eigen::MatrixXd D = derivative_matrix(n, 3);
  return D.transpose() * bernstein_gram(n - 3) * D / std::pow(duration, 5);
}

PiecewiseBezier::PiecewiseBezier(int order, std::vector<double> durations, std::vector<Eigen::Vector3d> control_points)
    : order_(order), durations_(std::move(durations)), control_points_(std::move(control_points)) {
  require(order_ >= 1 && order_ <= kMaxOrder,
          "bezier: order must be in [1, " + std::to_string(kMaxOrder) + "], got " + std::to_string(order_));
  require(!durations_.empty(), "bezier: at least one segment");
  for (std::size_t k = 0; k < durations_.size(); ++k) {
    require(std::isfinite(durations_[k]) && durations_[k] > 0,
            "bezier: durations[" + std::to_string(k) + "] must be > 0 and finite");
  }
  require(control_points_.size() == durations_.size() * static_cast<std::size_t>(order_ + 1),
          "bezier: " + std::to_string(durations_.size()) + " segments of order " + std::to_string(order_) + " need " +
              std::to_string(durations_.size() * static_cast<std::size_t>(order_ + 1)) + " control points, got " +
              std::to_string(control_points_.size()));
}

void PiecewiseBezier::assign(int order, std::span<const double> durations,
                             std::span<const Eigen::Vector3d> control_points) {
  // Checked as the constructor does, the messages built only on failure.
  const bool durations_ok =
      std::all_of(durations.begin(), durations.end(), [](double d) { return std::isfinite(d) && d > 0; });
  if (order < 1 || order > kMaxOrder || durations.empty() || !durations_ok ||
      control_points.size() != durations.size() * static_cast<std::size_t>(order + 1)) {
    *this = PiecewiseBezier(order, std::vector<double>(durations.begin(), durations.end()),
                            std::vector<Eigen::Vector3d>(control_points.begin(), control_points.end()));
    return;
  }
  order_ = order;
  durations_.assign(durations.begin(), durations.end());
  control_points_.assign(control_points.begin(), control_points.end());
}

double PiecewiseBezier::total_duration() const {
  double t = 0;
  for (const double d : durations_) t += d;
  return t;
}

double PiecewiseBezier::start_time(int segment) const {
  double t = 0;
  for (int k = 0; k < segment; ++k) t += duration(k);
  return t;
}

std::span<const Eigen::Vector3d> PiecewiseBezier::control_points(int segment) const {
  return std::span<const Eigen::Vector3d>(control_points_)
      .subspan(static_cast<std::size_t>(segment) * static_cast<std::size_t>(order_ + 1),
               static_cast<std::size_t>(order_ + 1));
}

Eigen::Vector3d PiecewiseBezier::evaluate_segment(int segment, double tau, int derivative) const {
  if (derivative > order_) return Eigen::Vector3d::Zero();
  const auto c = control_points(segment);
  std::array<Eigen::Vector3d, kMaxOrder + 1> w;
  for (int i = 0; i <= order_; ++i) w[static_cast<std::size_t>(i)] = c[static_cast<std::size_t>(i)];
  // Hodograph: forward differences, in place.
  int m = order_;
  for (int j = 0; j < derivative; ++j, --m) {
    for (int i = 0; i < m; ++i)
      w[static_cast<std::size_t>(i)] = w[static_cast<std::size_t>(i + 1)] - w[static_cast<std::size_t>(i)];
  }
  // de Casteljau on the m + 1 remaining points.
  tau = std::clamp(tau, 0.0, 1.0);
  for (int r = m; r > 0; --r) {
    for (int i = 0; i < r; ++i) {
      w[static_cast<std::size_t>(i)] =
          (1 - tau) * w[static_cast<std::size_t>(i)] + tau * w[static_cast<std::size_t>(i + 1)];
    }
  }
  return w[0] * (falling_factorial(order_, derivative) / std::pow(duration(segment), derivative));
}

Eigen::Vector3d PiecewiseBezier::evaluate(double t, int derivative) const {
  int k = 0;
  double t0 = 0;
  const int last = segments() - 1;
  while (k < last && t >= t0 + duration(k)) {
    t0 += duration(k);
    ++k;
  }
  return evaluate_segment(k, (t - t0) / duration(k), derivative);
}

double PiecewiseBezier::jerk_cost() const {
  if (order_ < 3) return 0;
  double cost = 0;
  for (int k = 0; k < segments(); ++k) {
    const Eigen::MatrixXd Q = jerk_cost_matrix(order_, duration(k));
    const auto c = control_points(k);
    Eigen::MatrixXd X(order_ + 1, 3);
    for (int i = 0; i <= order_; ++i) X.row(i) = c[static_cast<std::size_t>(i)].transpose();
    cost += (X.transpose() * Q * X).trace();
  }
  return cost;
}

std::vector<Eigen::Vector3d> PiecewiseBezier::derivative_control_points(int segment, int derivative) const {
  if (derivative > order_) return {Eigen::Vector3d::Zero()};
  const auto c = control_points(segment);
  const Eigen::MatrixXd D = derivative_matrix(order_, derivative) / std::pow(duration(segment), derivative);
  std::vector<Eigen::Vector3d> out(static_cast<std::size_t>(order_ - derivative + 1), Eigen::Vector3d::Zero());
  for (int i = 0; i < D.rows(); ++i) {
    for (int j = 0; j < D.cols(); ++j) out[static_cast<std::size_t>(i)] += D(i, j) * c[static_cast<std::size_t>(j)];
  }
  return out;
}

PiecewiseBezier::Bounds PiecewiseBezier::hull_bounds(int derivative) const {
  Bounds b{Eigen::Vector3d::Constant(INFINITY), Eigen::Vector3d::Constant(-INFINITY)};
  for (int k = 0; k < segments(); ++k) {
    for (const Eigen::Vector3d& p : derivative_control_points(k, derivative)) {
      b.min = b.min.cwiseMin(p);
      b.max = b.max.cwiseMax(p);
    }
  }
  return b;
}

}  // namespace touchdown::plan
