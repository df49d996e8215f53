#pragma once
/// \file
/// Piecewise Bézier curves in 3-D for landing trajectories: evaluation (de
/// Casteljau), derivatives through the hodograph, the exact jerk cost
/// matrix from products of Bernstein polynomials (no monomial table), and
/// convex-hull bounds.
///
/// A segment k of duration T_k has control points c_0 … c_n (order n) and
/// p(t) = Σ c_i B_i^n(t / T_k). Its j-th time derivative is a Bézier curve
/// of order n − j whose control points are n!/(n−j)! / T_k^j times the j-th
/// forward differences of the c_i (the hodograph), so every bound on
/// position, velocity or acceleration control points bounds the curve
/// (convex-hull property; Farouki, "The Bernstein polynomial basis: a
/// centennial retrospective", CAGD 2012).
///
/// Allocation: evaluation does not allocate; the matrix builders return
/// new matrices. Thread-safe: const methods and pure functions.
#include <Eigen/Core>
#include <span>
#include <vector>

namespace touchdown::plan {

/// Binomial coefficient C(n, k) as a double (0 outside 0 ≤ k ≤ n).
double binomial(int n, int k);

/// Gram matrix of the Bernstein basis of order m on [0, 1]:
/// G_ij = ∫₀¹ B_i^m B_j^m dτ = C(m,i) C(m,j) / (C(2m, i+j) (2m+1)).
Eigen::MatrixXd bernstein_gram(int m);

/// The (n−j+1) × (n+1) matrix D with d = D c: the control points of the
/// j-th derivative with respect to τ ∈ [0, 1] of an order-n Bézier curve
/// (n!/(n−j)! times the j-th forward differences). 0 ≤ j ≤ n.
Eigen::MatrixXd derivative_matrix(int n, int j);

/// The (n+r+1) × (n+1) degree-elevation matrix E: an order-n curve with
/// control points c is the order-(n+r) curve with control points E c.
Eigen::MatrixXd elevation_matrix(int n, int r);

/// Per axis, the (n+1) × (n+1) matrix Q with ∫₀ᵀ (d³p/dt³)² dt = cᵀ Q c for
/// an order-n segment of duration T: Q = D₃ᵀ G_{n−3} D₃ / T⁵. n ≥ 3, T > 0.
Eigen::MatrixXd jerk_cost_matrix(int n, double duration);

/// A piecewise Bézier curve in 3-D: `segments` segments of one order, each
/// with its own duration and n + 1 control points (not shared: continuity
/// is the planner's constraint, not the representation's).
class PiecewiseBezier {
 public:
  PiecewiseBezier() = default;
  /// control_points: segment after segment, order + 1 per segment. Throws
  /// InvalidArgument for order < 1, a duration ≤ 0 or not finite, or a
  /// count that does not match.
  PiecewiseBezier(int order, std::vector<double> durations, std::vector<Eigen::Vector3d> control_points);
  /// The same, into this curve's storage: no allocation when the counts
  /// are those it already holds (a replanning loop). Throws as the
  /// constructor; the curve is unchanged then.
  void assign(int order, std::span<const double> durations, std::span<const Eigen::Vector3d> control_points);

  [[nodiscard]] int order() const { return order_; }
  [[nodiscard]] int segments() const { return static_cast<int>(durations_.size()); }
  [[nodiscard]] double duration(int segment) const { return durations_[static_cast<std::size_t>(segment)]; }
  [[nodiscard]] double total_duration() const;
  /// Start time of a segment (the sum of the earlier durations).
  [[nodiscard]] double start_time(int segment) const;
  [[nodiscard]] std::span<const Eigen::Vector3d> control_points(int segment) const;
  [[nodiscard]] std::span<const Eigen::Vector3d> all_control_points() const { return control_points_; }

  /// The `derivative`-th time derivative (0 = position) at time t ∈ [0,
  /// total_duration()] (clamped); at a joint, the later segment's value.
  /// Zero for derivative > order. Allocation-free.
  [[nodiscard]] Eigen::Vector3d evaluate(double t, int derivative = 0) const;
  /// The same within one segment at τ ∈ [0, 1].
  [[nodiscard]] Eigen::Vector3d evaluate_segment(int segment, double tau, int derivative = 0) const;

  /// ∫ ‖d³p/dt³‖² dt over the whole curve, exact (jerk_cost_matrix).
  [[nodiscard]] double jerk_cost() const;

  /// Control points of the `derivative`-th time derivative of a segment
  /// (the hodograph, scaled by 1/T^j): order − j + 1 points.
  [[nodiscard]] std::vector<Eigen::Vector3d> derivative_control_points(int segment, int derivative) const;

  /// Per-axis bounds of the `derivative`-th derivative over the whole curve
  /// from the convex hull of its control points (conservative: contain the
  /// true range).
  struct Bounds {
    Eigen::Vector3d min, max;
  };
  [[nodiscard]] Bounds hull_bounds(int derivative) const;

 private:
  int order_ = 0;
  std::vector<double> durations_;
  std::vector<Eigen::Vector3d> control_points_;
};

}  // namespace touchdown::plan
