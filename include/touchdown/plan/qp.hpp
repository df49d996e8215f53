#pragma once
/// \file
/// Dense strictly convex quadratic programs on Eigen:
///
///   min ½ xᵀ P x + qᵀ x   s.t.   A_eq x = b_eq,   A_in x ≤ b_in,
///
/// with P symmetric positive definite, solved by the dual active-set method
/// of Goldfarb & Idnani ("A numerically stable dual method for solving
/// strictly convex quadratic programs", Math. Programming 27, 1983): start
/// at the unconstrained minimum, add the equalities, then repeatedly add the
/// most violated inequality, dropping active ones whose multiplier would
/// turn negative, with the factorisation Jᵀ N = [R; 0] (J = L⁻ᵀ Q, P = L Lᵀ)
/// kept up to date by Givens rotations. Every iterate is dual feasible, so
/// the first primal feasible one is optimal, and a violated constraint that
/// no step can satisfy proves the problem infeasible.
///
/// Warm start: solve() with warm_start = true tries the inequalities active
/// at the previous solution first (the next QP of a replan or of a time
/// allocation usually has almost the same active set), which saves the
/// drops a cold start makes.
///
/// Allocation: resize() allocates; solve() does not when the problem has
/// the sizes given to resize(). Not thread-safe (one solver per thread).
#include <Eigen/Cholesky>
#include <Eigen/Core>
#include <string>
#include <vector>

namespace touchdown::plan {

struct QpOptions {
  /// Add/drop steps before `IterationLimit`; 0 = 3 (n + m_eq + m_in) + 10.
  int max_iterations = 0;
  /// A constraint counts as violated, and an equality as met, within this
  /// distance (rows are normalised, so it is in the units of x).
  double tolerance = 1e-9;
  /// False (with "field: what is wrong" in *why) for an invalid value.
  bool validate(std::string* why) const;
};

enum class QpStatus {
  Optimal,
  Infeasible,      ///< the constraints have no common point (or the equalities contradict each other)
  IterationLimit,  ///< stopped at max_iterations; x is dual feasible, not primal feasible
  NotConvex,       ///< P is not positive definite
};
const char* to_string(QpStatus status);

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
  [[nodiscard]] const Eigen::VectorXd& x() const { return x_; }
  [[nodiscard]] double objective() const { return objective_; }
  [[nodiscard]] int iterations() const { return iterations_; }
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
  bool add_constraint(int id);  // factorisation update with d_ already set; false if dependent
  void drop_constraint(int position);
  void step_direction(const Eigen::VectorXd& normal);
  double normal_dot(int id, const Eigen::VectorXd& v) const;
  void compute_kkt(const Eigen::Ref<const Eigen::MatrixXd>& P, const Eigen::Ref<const Eigen::VectorXd>& q,
                   const Eigen::Ref<const Eigen::MatrixXd>& A_eq, const Eigen::Ref<const Eigen::VectorXd>& b_eq,
                   const Eigen::Ref<const Eigen::MatrixXd>& A_in, const Eigen::Ref<const Eigen::VectorXd>& b_in);

  QpOptions options_;
  int n_ = -1, m_eq_ = -1, m_in_ = -1;
  Eigen::LLT<Eigen::MatrixXd> llt_;
  Eigen::MatrixXd J_, R_;
  Eigen::MatrixXd normals_;  // n × (m_eq + m_in): unit GI normals (equalities a/‖a‖, inequalities −a/‖a‖)
  Eigen::VectorXd offsets_;  // GI offsets: constraint i is normals_ᵀ x − offsets ≥ 0 (= 0 for equalities)
  Eigen::VectorXd scale_;    // 1/‖a‖ per constraint (0 for a zero row)
  Eigen::VectorXd x_, d_, z_, r_, u_, slack_, work_, lambda_, mu_;
  std::vector<int> active_;     // constraint ids (equalities 0..m_eq−1, inequalities m_eq + i), by position
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
