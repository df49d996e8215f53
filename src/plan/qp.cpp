// Goldfarb–Idnani dual active-set method (Math. Programming 27, 1983, the
// algorithm of sec. 3 with the numerically stable update of sec. 4):
// the active constraints' normals N satisfy Jᵀ N = [R; 0] with J = L⁻ᵀ Q
// for P = L Lᵀ, so that the primal step direction is z = J₂ J₂ᵀ n⁺ and the
// change of the active multipliers r = R⁻¹ J₁ᵀ n⁺. Adding a constraint
// rotates the trailing columns of J (Givens) so that Jᵀ n⁺ has one entry
// past the active block; dropping one removes a column of R and restores
// its triangle with rotations that also act on J's columns.
#include "touchdown/plan/qp.hpp"

#include <algorithm>
#include <cmath>
#include <limits>

#include "touchdown/core/error.hpp"

namespace touchdown::plan {

namespace {

constexpr double kInf = std::numeric_limits<double>::infinity();

// c, s with [c s; −s c] [a; b] = [ρ; 0].
void givens(double a, double b, double& c, double& s) {
  const double rho = std::hypot(a, b);
  if (rho == 0) {
    c = 1;
    s = 0;
  } else {
    c = a / rho;
    s = b / rho;
  }
}

// Columns (i, j) of M ← (c M_i + s M_j, −s M_i + c M_j).
void rotate_columns(Eigen::MatrixXd& M, Eigen::Index i, Eigen::Index j, double c, double s) {
  double* a = M.col(i).data();
  double* b = M.col(j).data();
  for (Eigen::Index k = 0; k < M.rows(); ++k) {
    const double ak = a[k], bk = b[k];
    a[k] = c * ak + s * bk;
    b[k] = -s * ak + c * bk;
  }
}

}  // namespace

bool QpOptions::validate(std::string* why) const {
  if (max_iterations < 0) return invalid(why, "max_iterations: must be >= 0, got " + std::to_string(max_iterations));
  if (!(tolerance > 0) || !std::isfinite(tolerance)) return invalid(why, "tolerance: must be > 0 and finite");
  return true;
}

const char* to_string(QpStatus status) {
  switch (status) {
    case QpStatus::Optimal:
      return "optimal";
    case QpStatus::Infeasible:
      return "infeasible";
    case QpStatus::IterationLimit:
      return "iteration_limit";
    case QpStatus::NotConvex:
      return "not_convex";
  }
  return "unknown";
}

QpSolver::QpSolver(const QpOptions& options) : options_(options) {
  std::string why;
  if (!options_.validate(&why)) throw InvalidArgument("qp options: " + why);
}

void QpSolver::resize(int n, int m_eq, int m_in) {
  if (n < 1 || m_eq < 0 || m_in < 0) throw InvalidArgument("qp: need n >= 1 variables and m_eq, m_in >= 0");
  n_ = n;
  m_eq_ = m_eq;
  m_in_ = m_in;
  const int m = m_eq + m_in;
  llt_.compute(Eigen::MatrixXd::Identity(n, n));  // sizes its storage (solve() then reuses it)
  J_.resize(n, n);
  R_.resize(n, n);
  normals_.resize(n, m);
  offsets_.resize(m);
  scale_.resize(m);
  x_.resize(n);
  d_.resize(n);
  z_.resize(n);
  r_.resize(n);
  u_.resize(n);
  work_.resize(n);
  slack_.resize(m_in);
  lambda_.resize(m_eq);
  mu_.resize(m_in);
  active_.assign(static_cast<std::size_t>(n), -1);
  active_in_.clear();
  active_in_.reserve(static_cast<std::size_t>(n));
  previous_.clear();
  previous_.reserve(static_cast<std::size_t>(n));
  prefer_.assign(static_cast<std::size_t>(m_in), 0);
}

double QpSolver::normal_dot(int id, const Eigen::VectorXd& v) const { return normals_.col(id).dot(v); }

// d = Jᵀ n, z = J₂ d₂ (primal direction), r = R⁻¹ d₁ (multiplier change).
void QpSolver::step_direction(const Eigen::VectorXd& normal) {
  d_.noalias() = J_.transpose() * normal;
  z_.setZero();
  for (int j = q_; j < n_; ++j) z_ += d_(j) * J_.col(j);
  for (int i = q_ - 1; i >= 0; --i) {  // back substitution R r = d₁
    double sum = d_(i);
    for (int j = i + 1; j < q_; ++j) sum -= R_(i, j) * r_(j);
    r_(i) = sum / R_(i, i);
  }
}

// Appends constraint `id` (d_ = Jᵀ n holds its normal): rotates d_'s
// trailing part onto entry q and J's columns with it.
bool QpSolver::add_constraint(int id) {
  for (int j = n_ - 1; j > q_; --j) {
    if (d_(j) == 0) continue;
    double c, s;
    givens(d_(j - 1), d_(j), c, s);
    d_(j - 1) = c * d_(j - 1) + s * d_(j);
    d_(j) = 0;
    rotate_columns(J_, j - 1, j, c, s);
  }
  const double scale = d_.head(q_ + 1).cwiseAbs().maxCoeff();
  if (std::abs(d_(q_)) <= 1e-13 * std::max(1.0, scale)) return false;
  for (int i = 0; i <= q_; ++i) R_(i, q_) = d_(i);
  active_[static_cast<std::size_t>(q_)] = id;
  ++q_;
  return true;
}

// Removes the active constraint at `position` and restores R's triangle.
void QpSolver::drop_constraint(int position) {
  for (int k = position; k + 1 < q_; ++k) {
    active_[static_cast<std::size_t>(k)] = active_[static_cast<std::size_t>(k + 1)];
    u_(k) = u_(k + 1);
    R_.col(k).head(k + 2) = R_.col(k + 1).head(k + 2);
  }
  --q_;
  for (int k = position; k < q_; ++k) {  // column k has a subdiagonal entry R(k+1, k)
    double c, s;
    givens(R_(k, k), R_(k + 1, k), c, s);
    for (int j = k; j < q_; ++j) {
      const double a = R_(k, j), b = R_(k + 1, j);
      R_(k, j) = c * a + s * b;
      R_(k + 1, j) = -s * a + c * b;
    }
    R_(k + 1, k) = 0;
    rotate_columns(J_, k, k + 1, c, s);
  }
}

QpStatus QpSolver::solve(const Eigen::Ref<const Eigen::MatrixXd>& P, const Eigen::Ref<const Eigen::VectorXd>& q,
                         const Eigen::Ref<const Eigen::MatrixXd>& A_eq, const Eigen::Ref<const Eigen::VectorXd>& b_eq,
                         const Eigen::Ref<const Eigen::MatrixXd>& A_in, const Eigen::Ref<const Eigen::VectorXd>& b_in,
                         bool warm_start) {
  const auto n = P.rows();
  if (n < 1 || P.cols() != n || q.size() != n) throw InvalidArgument("qp: P must be n x n and q of size n");
  if (A_eq.rows() != b_eq.size() || (A_eq.rows() > 0 && A_eq.cols() != n)) {
    throw InvalidArgument("qp: A_eq must be m_eq x n and b_eq of size m_eq");
  }
  if (A_in.rows() != b_in.size() || (A_in.rows() > 0 && A_in.cols() != n)) {
    throw InvalidArgument("qp: A_in must be m_in x n and b_in of size m_in");
  }
  if (!P.allFinite() || !q.allFinite() || !A_eq.allFinite() || !b_eq.allFinite() || !A_in.allFinite() ||
      !b_in.allFinite()) {
    throw InvalidArgument("qp: every entry of P, q, A and b must be finite");
  }
  if (n != n_ || A_eq.rows() != m_eq_ || A_in.rows() != m_in_) {
    resize(static_cast<int>(n), static_cast<int>(A_eq.rows()), static_cast<int>(A_in.rows()));
    warm_start = false;
  }
  const double tol = options_.tolerance;
  const int max_iterations = options_.max_iterations > 0 ? options_.max_iterations : 3 * (n_ + m_eq_ + m_in_) + 10;
  iterations_ = 0;
  blocking_ = -1;
  q_ = 0;
  lambda_.setZero();
  mu_.setZero();
  active_in_.clear();
  std::fill(prefer_.begin(), prefer_.end(), 0);
  if (warm_start) {
    for (const int i : previous_) prefer_[static_cast<std::size_t>(i)] = 1;
  }

  // Unit GI normals: equality a x = b → (a/‖a‖) x − b/‖a‖ = 0; inequality
  // a x ≤ b → (−a/‖a‖) x − (−b/‖a‖) ≥ 0.
  for (int i = 0; i < m_eq_ + m_in_; ++i) {
    const bool eq = i < m_eq_;
    const auto row = eq ? A_eq.row(i) : A_in.row(i - m_eq_);
    const double rhs = eq ? b_eq(i) : b_in(i - m_eq_);
    const double norm = row.norm();
    if (norm == 0) {  // 0 = b or 0 ≤ b: met or impossible whatever x is
      normals_.col(i).setZero();
      offsets_(i) = eq ? (std::abs(rhs) <= tol ? 0.0 : kInf) : (rhs >= -tol ? -kInf : kInf);
      scale_(i) = 0;
      continue;
    }
    scale_(i) = 1 / norm;
    normals_.col(i) = (eq ? 1.0 : -1.0) * row.transpose() / norm;
    offsets_(i) = (eq ? 1.0 : -1.0) * rhs / norm;
  }

  llt_.compute(P);
  if (llt_.info() != Eigen::Success) {
    status_ = QpStatus::NotConvex;
    return status_;
  }
  J_.setIdentity();
  llt_.matrixU().solveInPlace(J_);  // Lᵀ J = I
  x_ = -q;
  llt_.solveInPlace(x_);

  auto finish = [&](QpStatus status) {
    status_ = status;
    for (int k = 0; k < q_; ++k) {
      const int id = active_[static_cast<std::size_t>(k)];
      if (id < m_eq_) {
        lambda_(id) = -u_(k) * scale_(id);
      } else {
        mu_(id - m_eq_) = u_(k) * scale_(id);
        active_in_.push_back(id - m_eq_);
      }
    }
    if (status == QpStatus::Optimal) {
      previous_.assign(active_in_.begin(), active_in_.end());
    }
    work_.noalias() = P * x_;
    objective_ = 0.5 * x_.dot(work_) + q.dot(x_);
    compute_kkt(P, q, A_eq, b_eq, A_in, b_in);
    return status_;
  };

  // Equalities: a full step onto each (the step may go either way; their
  // multipliers have no sign), never dropped.
  for (int i = 0; i < m_eq_; ++i) {
    if (scale_(i) == 0) {
      if (offsets_(i) != 0) {
        return finish(QpStatus::Infeasible);
      }
      continue;
    }
    if (++iterations_ > max_iterations) return finish(QpStatus::IterationLimit);
    work_ = normals_.col(i);
    step_direction(work_);
    const double slack = normal_dot(i, x_) - offsets_(i);
    const double zn = d_.tail(n_ - q_).squaredNorm();
    if (zn <= 1e-14 * std::max(1.0, d_.squaredNorm())) {  // dependent on the earlier equalities
      if (std::abs(slack) > tol * 10) return finish(QpStatus::Infeasible);
      continue;
    }
    const double t = -slack / zn;
    x_ += t * z_;
    for (int k = 0; k < q_; ++k) u_(k) -= t * r_(k);
    u_(q_) = t;
    if (!add_constraint(i)) return finish(QpStatus::Infeasible);
  }

  // Inequalities: add the most violated one until none is.
  while (true) {
    int p = -1;
    double worst = -tol, worst_preferred = -tol;
    int p_preferred = -1;
    for (int i = 0; i < m_in_; ++i) {
      const int id = m_eq_ + i;
      if (scale_(id) == 0) {
        if (offsets_(id) == kInf) {
          blocking_ = i;
          return finish(QpStatus::Infeasible);
        }
        slack_(i) = kInf;
        continue;
      }
      const double s = normal_dot(id, x_) - offsets_(id);
      slack_(i) = s;
      if (s < worst) {
        worst = s;
        p = i;
      }
      if (prefer_[static_cast<std::size_t>(i)] && s < worst_preferred) {
        worst_preferred = s;
        p_preferred = i;
      }
    }
    if (p_preferred >= 0) p = p_preferred;
    if (p < 0) return finish(QpStatus::Optimal);
    prefer_[static_cast<std::size_t>(p)] = 0;
    const int id = m_eq_ + p;
    work_ = normals_.col(id);
    double u_plus = 0;
    // Step 2: move until p is met (full step) or an active multiplier hits 0 (partial step, drop it).
    while (true) {
      if (++iterations_ > max_iterations) return finish(QpStatus::IterationLimit);
      step_direction(work_);
      double t1 = kInf;
      int drop = -1;
      for (int k = 0; k < q_; ++k) {
        if (active_[static_cast<std::size_t>(k)] < m_eq_ || r_(k) <= 1e-12) continue;
        const double ratio = u_(k) / r_(k);
        if (ratio < t1) {
          t1 = ratio;
          drop = k;
        }
      }
      const double zn = d_.tail(n_ - q_).squaredNorm();
      const double slack = normal_dot(id, x_) - offsets_(id);
      const double t2 = zn > 1e-14 * std::max(1.0, d_.squaredNorm()) ? -slack / zn : kInf;
      if (t1 == kInf && t2 == kInf) {
        blocking_ = p;
        return finish(QpStatus::Infeasible);
      }
      if (t2 == kInf) {  // step in the dual only
        for (int k = 0; k < q_; ++k) u_(k) -= t1 * r_(k);
        u_plus += t1;
        drop_constraint(drop);
        continue;
      }
      const double t = std::min(t1, t2);
      x_ += t * z_;
      for (int k = 0; k < q_; ++k) u_(k) -= t * r_(k);
      u_plus += t;
      if (t2 <= t1) {
        u_(q_) = u_plus;
        if (!add_constraint(id)) {
          blocking_ = p;
          return finish(QpStatus::Infeasible);
        }
        break;
      }
      drop_constraint(drop);
    }
  }
}

void QpSolver::compute_kkt(const Eigen::Ref<const Eigen::MatrixXd>& P, const Eigen::Ref<const Eigen::VectorXd>& q,
                           const Eigen::Ref<const Eigen::MatrixXd>& A_eq, const Eigen::Ref<const Eigen::VectorXd>& b_eq,
                           const Eigen::Ref<const Eigen::MatrixXd>& A_in,
                           const Eigen::Ref<const Eigen::VectorXd>& b_in) {
  work_.noalias() = P * x_;
  work_ += q;
  if (m_eq_ > 0) work_.noalias() += A_eq.transpose() * lambda_;
  if (m_in_ > 0) work_.noalias() += A_in.transpose() * mu_;
  kkt_.stationarity = work_.cwiseAbs().maxCoeff();
  kkt_.primal = 0;
  for (int i = 0; i < m_eq_; ++i) kkt_.primal = std::max(kkt_.primal, std::abs(A_eq.row(i).dot(x_) - b_eq(i)));
  kkt_.dual = 0;
  kkt_.complementarity = 0;
  for (int i = 0; i < m_in_; ++i) {
    const double s = b_in(i) - A_in.row(i).dot(x_);
    kkt_.primal = std::max(kkt_.primal, -s);
    kkt_.dual = std::max(kkt_.dual, -mu_(i));
    kkt_.complementarity = std::max(kkt_.complementarity, std::abs(mu_(i) * s));
  }
}

}  // namespace touchdown::plan
