#pragma once
/// \file
/// Dense strictly convex quadratic programs on Eigen:
///
///   min ½ xᵀ P x + qᵀ x   s.t.   A_eq x = b_eq,   A_in x ≤ b_in,
///
/// with P symmetric and positive definite on the null space of A_eq (so a
/// positive semidefinite P, as a jerk cost on Bézier control points, is
/// fine when the equalities pin its null directions).
///
/// Equalities are eliminated first (variable reduction, Gill, Murray &
/// Wright, "Practical Optimization", sec. 5.1.3): Gauss–Jordan elimination
/// with complete pivoting on the row-normalised A_eq picks r = rank(A_eq)
/// basic variables and writes them as x_B = x0_B + W x_N in the free ones;
/// dependent equalities are dropped when consistent and reported infeasible
/// when not. The inequalities in the n − r free variables are then solved
/// by the dual active-set method of Goldfarb & Idnani ("A numerically
/// stable dual method for solving strictly convex quadratic programs",
/// Math. Programming 27, 1983): start at the unconstrained minimum, then
/// repeatedly add the most violated inequality, dropping active ones whose
/// multiplier would turn negative, with the factorisation Jᵀ N = [R; 0]
/// (J = L⁻ᵀ Q, P = L Lᵀ) kept up to date by Givens rotations. Every iterate
/// is dual feasible, so the first primal feasible one is optimal, and a
/// violated constraint that no step can satisfy proves the problem
/// infeasible. Zero entries of the inequality rows are skipped when they
/// are mapped to the free variables, so sparse rows (a corridor face acts
/// on one control point) cost little.
///
/// Warm start: solve() with warm_start = true tries the inequalities active
/// at the previous solution first (the next QP of a replan or of a time
/// allocation usually has almost the same active set), which saves the
/// drops a cold start makes.
///
/// Allocation: resize() allocates; solve() does not when the problem has
/// the sizes given to resize(). Not thread-safe (one solver per thread).
#include <Eigen/Core>
#include <array>
#include <string>
#include <string_view>
#include <vector>

#include "touchdown/core/enum_names.hpp"

namespace touchdown::plan {

struct QpOptions {
  /// Inequality add/drop steps before `IterationLimit`; 0 = 3 (n + m_eq + m_in) + 10.
  int max_iterations = 0;
  /// A constraint counts as violated, and an equality as met, within this
  /// distance (rows are normalised, so it is in the units of x).
  double tolerance = 1e-9;
  /// False (with "field: what is wrong" in *why) for an invalid value.
  [[nodiscard]] bool validate(std::string* why) const;
};

enum class QpStatus {
  Optimal,
  Infeasible,      ///< the constraints have no common point (or the equalities contradict each other)
  IterationLimit,  ///< stopped at max_iterations; x is dual feasible, not primal feasible
  NotConvex,       ///< P is not positive definite on the null space of A_eq
};

}  // namespace touchdown::plan

template <>
struct touchdown::EnumNames<touchdown::plan::QpStatus> {
  static constexpr std::array<std::string_view, 4> names{"optimal", "infeasible", "iteration_limit", "not_convex"};
};

namespace touchdown::plan {

inline std::string_view to_string(QpStatus status) { return enum_name(status); }

/// How far a solution is from the KKT conditions (∞-norms): stationarity
/// ‖P x + q + A_eqᵀ λ + A_inᵀ μ‖, primal max(‖A_eq x − b_eq‖, max(A_in x −
/// b_in)₊), dual max(−μ)₊, complementarity max |μ_i (b_in − A_in x)_i|.
struct KktResiduals {
  double stationarity = 0;
  double primal = 0;
  double dual = 0;
  double complementarity = 0;
};

class QpSolver {
 public:
  explicit QpSolver(const QpOptions& options = {});
  /// Sizes the work space for n variables, m_eq equalities and m_in
  /// inequalities (allocates). solve() calls it when the sizes differ.
  void resize(int n, int m_eq, int m_in);

  /// Solves the QP. Throws InvalidArgument for mismatched sizes or
  /// non-finite input; every outcome of a well-formed problem is a status.
  QpStatus solve(const Eigen::Ref<const Eigen::MatrixXd>& P, const Eigen::Ref<const Eigen::VectorXd>& q,
                 const Eigen::Ref<const Eigen::MatrixXd>& A_eq, const Eigen::Ref<const Eigen::VectorXd>& b_eq,
                 const Eigen::Ref<const Eigen::MatrixXd>& A_in, const Eigen::Ref<const Eigen::VectorXd>& b_in,
                 bool warm_start = false);

  [[nodiscard]] QpStatus status() const { return status_; }
  [[nodiscard]] bool ok() const { return status_ == QpStatus::Optimal; }
  /// The status's fixed text (a solve in a replanning loop never allocates).
  [[nodiscard]] std::string_view message() const { return to_string(status_); }
  [[nodiscard]] const Eigen::VectorXd& x() const { return x_; }
  [[nodiscard]] double objective() const { return objective_; }
  /// Inequality add/drop steps of the dual method (equalities are eliminated, not iterated).
  [[nodiscard]] int iterations() const { return iterations_; }
  /// Rank of A_eq found by the elimination (the QP had n − rank free variables).
  [[nodiscard]] int equality_rank() const { return rank_; }
  /// Multipliers in the Lagrangian ½xᵀPx + qᵀx + λᵀ(A_eq x − b_eq) + μᵀ(A_in x − b_in).
  [[nodiscard]] const Eigen::VectorXd& multipliers_eq() const { return lambda_; }
  [[nodiscard]] const Eigen::VectorXd& multipliers_in() const { return mu_; }
  /// Indices of the active inequalities at the solution.
  [[nodiscard]] const std::vector<int>& active_set() const { return active_in_; }
  /// The index of the inequality that proved infeasibility (−1 if an
  /// equality did, or the problem is not infeasible).
  [[nodiscard]] int blocking_constraint() const { return blocking_; }
  /// KKT residuals of the last solution (computed by solve()).
  [[nodiscard]] const KktResiduals& kkt() const { return kkt_; }

 private:
  bool eliminate_equalities(const Eigen::Ref<const Eigen::MatrixXd>& A_eq,
                            const Eigen::Ref<const Eigen::VectorXd>& b_eq);  // false: inconsistent
  void reduce(const Eigen::Ref<const Eigen::MatrixXd>& P, const Eigen::Ref<const Eigen::VectorXd>& q,
              const Eigen::Ref<const Eigen::MatrixXd>& A_in, const Eigen::Ref<const Eigen::VectorXd>& b_in);
  QpStatus dual_active_set(const Eigen::Ref<const Eigen::MatrixXd>& P, const Eigen::Ref<const Eigen::VectorXd>& q,
                           bool warm_start);
  bool add_constraint(int id);  // factorisation update with d_ already set; false if dependent
  void drop_constraint(int position);
  void step_direction(int id);
  void compute_kkt(const Eigen::Ref<const Eigen::MatrixXd>& A_eq, const Eigen::Ref<const Eigen::VectorXd>& b_eq,
                   const Eigen::Ref<const Eigen::MatrixXd>& A_in, const Eigen::Ref<const Eigen::VectorXd>& b_in);

  QpOptions options_;
  int n_ = -1, m_eq_ = -1, m_in_ = -1;
  int rank_ = 0;  // rank of A_eq
  int nc_ = 0;    // variables of the reduced problem (n − rank)
  // Gauss–Jordan tableau, (n + 1 + m_eq) × m_eq: column k holds a combination
  // of the normalised equalities (coefficients; right-hand side; the
  // combination's weights on the original rows).
  Eigen::MatrixXd tableau_;
  std::vector<int> basis_, free_;  // basic and free variables (x_B = x0_B + Wtᵀ x_N)
  Eigen::MatrixXd Wt_;             // nc × rank used
  Eigen::MatrixXd PZ_, PZB_, Pc_;  // P Z (n × nc), its basic rows (rank × nc), Zᵀ P Z (nc × nc)
  Eigen::MatrixXd L_, J_, R_;      // Cholesky factor of the reduced P, J = L⁻ᵀ Q, R (top-left nc × nc used)
  Eigen::MatrixXd normals_;        // nc × m_in used: unit GI normals −ã/‖ã‖ of the reduced inequalities
  Eigen::VectorXd offsets_;        // GI offsets: inequality i is normals_ᵀ v − offsets ≥ 0
  Eigen::VectorXd scale_;          // 1/‖ã‖ per inequality (0 for a row that is zero in the free variables)
  Eigen::VectorXd eq_scale_;       // 1/‖a‖ per equality (0 for a zero row)
  Eigen::VectorXd x_, x0_, g_, qc_, v_, d_, z_, r_, u_, slack_, eq_residual_, lambda_, mu_;
  std::vector<int> active_;     // active inequalities, by position
  std::vector<int> active_in_;  // inequality indices active at the solution
  std::vector<int> previous_;   // the previous solution's active inequalities (warm start)
  std::vector<char> prefer_;    // per inequality: in previous_
  int q_ = 0;                   // number of active constraints
  QpStatus status_ = QpStatus::Infeasible;
  double objective_ = 0;
  int iterations_ = 0;
  int blocking_ = -1;
  KktResiduals kkt_;
};

}  // namespace touchdown::plan
