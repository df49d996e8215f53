// Equality elimination by variable reduction (Gill, Murray & Wright,
// "Practical Optimization", 1981, sec. 5.1.3) with Gauss–Jordan complete
// pivoting, then the Goldfarb–Idnani dual active-set method (Math.
// Programming 27, 1983, the algorithm of sec. 3 with the numerically
// stable update of sec. 4) on the inequalities in the free variables: the
// active constraints' normals N satisfy Jᵀ N = [R; 0] with J = L⁻ᵀ Q for
// P = L Lᵀ, so that the primal step direction is z = J₂ J₂ᵀ n⁺ and the
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
constexpr const char* kNotFinite = "qp: every entry of P, q, A and b must be finite";

// c, s with [c s; −s c] [a; b] = [ρ; 0]. The entries are those of unit
// normals mapped by J (bounded by P's conditioning): no overflow guard.
void givens(double a, double b, double& c, double& s) {
  const double rho = std::sqrt(a * a + b * b);
  if (rho == 0) {
    c = 1;
    s = 0;
  } else {
    c = a / rho;
    s = b / rho;
  }
}

// Columns (i, j) of M's top `rows` rows ← (c M_i + s M_j, −s M_i + c M_j).
void rotate_columns(Eigen::MatrixXd& M, Eigen::Index rows, Eigen::Index i, Eigen::Index j, double c, double s) {
  double* a = M.col(i).data();
  double* b = M.col(j).data();
  for (Eigen::Index k = 0; k < rows; ++k) {
    const double ak = a[k], bk = b[k];
    a[k] = c * ak + s * bk;
    b[k] = -s * ak + c * bk;
  }
}

// Every entry finite (x·0 is 0 for a finite x and NaN otherwise; four
// independent sums keep the loop vectorisable without fast-math).
bool all_finite(const Eigen::Ref<const Eigen::MatrixXd>& M) {
  double acc[4] = {0, 0, 0, 0};
  for (Eigen::Index j = 0; j < M.cols(); ++j) {
    const double* c = M.col(j).data();
    Eigen::Index i = 0;
    for (; i + 4 <= M.rows(); i += 4) {
      for (int l = 0; l < 4; ++l) acc[l] += c[i + l] * 0.0;
    }
    for (; i < M.rows(); ++i) acc[0] += c[i] * 0.0;
  }
  return acc[0] + acc[1] + acc[2] + acc[3] == 0.0;
}

}  // namespace

bool QpOptions::validate(std::string* why) const {
  if (max_iterations < 0) return invalid(why, "max_iterations: must be >= 0, got " + std::to_string(max_iterations));
  if (!(tolerance > 0) || !std::isfinite(tolerance)) return invalid(why, "tolerance: must be > 0 and finite");
  return true;
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
  tableau_.resize(n + 1 + m_eq, m_eq);
  basis_.assign(static_cast<std::size_t>(std::min(n, m_eq)), -1);
  free_.assign(static_cast<std::size_t>(n), -1);
  Wt_.resize(n, std::min(n, m_eq));
  PZ_.resize(n, n);
  PZB_.resize(std::min(n, m_eq), n);
  Pc_.resize(n, n);
  L_.resize(n, n);
  J_.resize(n, n);
  R_.resize(n, n);
  normals_.resize(n, m_in);
  offsets_.resize(m_in);
  scale_.resize(m_in);
  eq_scale_.resize(m_eq);
  x_ = Eigen::VectorXd::Zero(n);
  x0_.resize(n);
  g_.resize(n);
  qc_.resize(n);
  v_.resize(n);
  d_.resize(n);
  z_.resize(n);
  r_.resize(n);
  u_.resize(n);
  slack_.resize(m_in);
  eq_residual_.resize(m_eq);
  lambda_.resize(m_eq);
  mu_.resize(m_in);
  active_.assign(static_cast<std::size_t>(n), -1);
  active_in_.clear();
  active_in_.reserve(static_cast<std::size_t>(n));
  previous_.clear();
  previous_.reserve(static_cast<std::size_t>(n));
  prefer_.assign(static_cast<std::size_t>(m_in), 0);
}

// Gauss–Jordan on the normalised equalities with complete pivoting. The
// tableau is stored transposed (one column per equation) so that row
// operations run down contiguous columns. Afterwards column k < rank has a
// 1 at its basic variable basis_[k] and 0 at the other basic variables.
bool QpSolver::eliminate_equalities(const Eigen::Ref<const Eigen::MatrixXd>& A_eq,
                                    const Eigen::Ref<const Eigen::VectorXd>& b_eq) {
  const int n = n_, m = m_eq_;
  tableau_.setZero();
  for (int i = 0; i < m; ++i) {
    const double norm = A_eq.row(i).norm();
    eq_scale_(i) = norm > 0 ? 1 / norm : 0;
    tableau_.col(i).head(n) = A_eq.row(i).transpose() * eq_scale_(i);
    tableau_(n, i) = b_eq(i) * eq_scale_(i);
    tableau_(n + 1 + i, i) = 1;
  }
  std::fill(free_.begin(), free_.end(), 0);  // used as "is basic" marks until the end
  // Each equation in turn pivots on its largest coefficient among the
  // variables not yet basic (rows are scaled so the pivot row's entries
  // are at most 1 afterwards, which bounds the multipliers as partial
  // pivoting does); an equation whose coefficients have all vanished is a
  // combination of the earlier ones and moves to the end.
  int k = 0, end = m;
  while (k < end && k < n) {
    const double* col = tableau_.col(k).data();
    int pivot_row = -1;
    double best = 1e-10;  // rows are unit vectors: below this an equation depends on the others
    for (int j = 0; j < n; ++j) {
      if (free_[static_cast<std::size_t>(j)] == 0 && std::abs(col[j]) > best) {
        best = std::abs(col[j]);
        pivot_row = j;
      }
    }
    if (pivot_row < 0) {
      --end;
      if (k != end) tableau_.col(k).swap(tableau_.col(end));
      continue;
    }
    basis_[static_cast<std::size_t>(k)] = pivot_row;
    free_[static_cast<std::size_t>(pivot_row)] = 1;
    tableau_.col(k) /= tableau_(pivot_row, k);
    for (int c = 0; c < m; ++c) {
      if (c == k) continue;
      const double f = tableau_(pivot_row, c);
      if (f != 0) tableau_.col(c) -= f * tableau_.col(k);
    }
    ++k;
  }
  rank_ = k;
  // The remaining combinations have (numerically) zero coefficients: their
  // right-hand sides must vanish too.
  for (int c = rank_; c < m; ++c) {
    if (std::abs(tableau_(n, c)) > 10 * options_.tolerance) return false;
  }
  int f = 0;
  for (int j = 0; j < n; ++j) {
    if (free_[static_cast<std::size_t>(j)] == 0) free_[static_cast<std::size_t>(f++)] = j;
  }
  nc_ = n - rank_;
  x0_.setZero();
  for (int b = 0; b < rank_; ++b) {
    x0_(basis_[static_cast<std::size_t>(b)]) = tableau_(n, b);
    for (int j = 0; j < nc_; ++j) Wt_(j, b) = -tableau_(free_[static_cast<std::size_t>(j)], b);
  }
  return true;
}

// The QP in the free variables v (x = x0 + Z v, Z = [W; I] up to order):
// P_c = Zᵀ P Z, q_c = Zᵀ (P x0 + q), and the inequalities' rows Zᵀ a_i with
// right-hand sides b_i − a_i x0 (raw, normalised by dual_active_set).
void QpSolver::reduce(const Eigen::Ref<const Eigen::MatrixXd>& P, const Eigen::Ref<const Eigen::VectorXd>& q,
                      const Eigen::Ref<const Eigen::MatrixXd>& A_in, const Eigen::Ref<const Eigen::VectorXd>& b_in) {
  const int nc = nc_, rk = rank_;
  for (int j = 0; j < nc; ++j) {
    auto col = PZ_.col(j);
    col = P.col(free_[static_cast<std::size_t>(j)]);
    for (int b = 0; b < rk; ++b) {
      const double w = Wt_(j, b);
      if (w != 0) col += w * P.col(basis_[static_cast<std::size_t>(b)]);
    }
  }
  for (int b = 0; b < rk; ++b) PZB_.row(b).head(nc) = PZ_.row(basis_[static_cast<std::size_t>(b)]).head(nc);
  auto Pc = Pc_.topLeftCorner(nc, nc);
  for (int i = 0; i < nc; ++i) Pc.row(i) = PZ_.row(free_[static_cast<std::size_t>(i)]).head(nc);
  Pc.noalias() += Wt_.topLeftCorner(nc, rk) * PZB_.topLeftCorner(rk, nc);

  g_.noalias() = P * x0_;
  g_ += q;
  for (int i = 0; i < nc; ++i) qc_(i) = g_(free_[static_cast<std::size_t>(i)]);
  for (int b = 0; b < rk; ++b) qc_.head(nc) += g_(basis_[static_cast<std::size_t>(b)]) * Wt_.col(b).head(nc);

  // Without inequalities normals_ has no column: a row of it would offset
  // its null data pointer (undefined, though nothing is read).
  if (m_in_ > 0) {
    for (int j = 0; j < nc; ++j) normals_.row(j) = A_in.col(free_[static_cast<std::size_t>(j)]).transpose();
  }
  offsets_ = b_in;
  for (int b = 0; b < rk; ++b) {
    const int var = basis_[static_cast<std::size_t>(b)];
    const auto a = A_in.col(var);
    if (x0_(var) != 0) offsets_ -= x0_(var) * a;
    for (int i = 0; i < m_in_; ++i) {
      if (a(i) != 0) normals_.col(i).head(nc) += a(i) * Wt_.col(b).head(nc);
    }
  }
}

// d = Jᵀ n, z = J₂ d₂ (primal direction), r = R⁻¹ d₁ (multiplier change).
void QpSolver::step_direction(int id) {
  const int nc = nc_;
  const auto normal = normals_.col(id).head(nc);
  d_.head(nc).noalias() = J_.topLeftCorner(nc, nc).transpose() * normal;
  z_.head(nc).noalias() = J_.block(0, q_, nc, nc - q_) * d_.segment(q_, nc - q_);
  for (int i = q_ - 1; i >= 0; --i) {  // back substitution R r = d₁
    double sum = d_(i);
    for (int j = i + 1; j < q_; ++j) sum -= R_(i, j) * r_(j);
    r_(i) = sum / R_(i, i);
  }
}

// Appends inequality `id` (d_ = Jᵀ n holds its normal): rotates d_'s
// trailing part onto entry q and J's columns with it.
bool QpSolver::add_constraint(int id) {
  for (int j = nc_ - 1; j > q_; --j) {
    if (d_(j) == 0) continue;
    double c, s;
    givens(d_(j - 1), d_(j), c, s);
    d_(j - 1) = c * d_(j - 1) + s * d_(j);
    d_(j) = 0;
    rotate_columns(J_, nc_, j - 1, j, c, s);
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
    rotate_columns(J_, nc_, k, k + 1, c, s);
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
  // A_in is checked through its rows' norms (dual_active_set), which a
  // NaN or an infinity makes non-finite, after the reduction too.
  if (!all_finite(P) || !all_finite(q) || !all_finite(A_eq) || !all_finite(b_eq) || !all_finite(b_in)) {
    throw InvalidArgument(kNotFinite);
  }
  if (n != n_ || A_eq.rows() != m_eq_ || A_in.rows() != m_in_) {
    resize(static_cast<int>(n), static_cast<int>(A_eq.rows()), static_cast<int>(A_in.rows()));
    warm_start = false;
  }
  iterations_ = 0;
  blocking_ = -1;
  q_ = 0;
  lambda_.setZero();
  mu_.setZero();
  active_in_.clear();

  // Objective, equality multipliers and KKT residuals of x_, mu_ (the
  // multipliers need the elimination, so not after inconsistent equalities).
  auto finish = [&](QpStatus status, bool eliminated) {
    status_ = status;
    if (status == QpStatus::Optimal) {
      previous_.assign(active_in_.begin(), active_in_.end());
    }
    g_.noalias() = P * x_;
    objective_ = 0.5 * x_.dot(g_) + q.dot(x_);
    g_ += q;
    for (const int i : active_in_) g_ += mu_(i) * A_in.row(i).transpose();
    if (eliminated && m_eq_ > 0 && status != QpStatus::NotConvex) {
      // Aᵀ_eq λ = −(P x + q + Aᵀ_in μ): on the basic variables the
      // tableau's first rank columns are unit vectors, so the weights of
      // its combinations are that gradient's basic entries; map them back
      // to the original rows through the recorded weights.
      for (int k = 0; k < rank_; ++k) d_(k) = -g_(basis_[static_cast<std::size_t>(k)]);
      lambda_.noalias() = tableau_.bottomLeftCorner(m_eq_, rank_) * d_.head(rank_);
      lambda_ = lambda_.cwiseProduct(eq_scale_);
    }
    compute_kkt(A_eq, b_eq, A_in, b_in);
    return status_;
  };

  if (m_eq_ > 0) {
    if (!eliminate_equalities(A_eq, b_eq)) {
      x_.setZero();
      return finish(QpStatus::Infeasible, false);
    }
    reduce(P, q, A_in, b_in);
    if (nc_ == 0 && !all_finite(A_in)) throw InvalidArgument(kNotFinite);
  } else {
    rank_ = 0;
    nc_ = n_;
    normals_ = A_in.transpose();
    offsets_ = b_in;
  }
  const QpStatus status = m_eq_ > 0 ? dual_active_set(Pc_.topLeftCorner(nc_, nc_), qc_.head(nc_), warm_start)
                                    : dual_active_set(P, q, warm_start);
  // Back to x = x0 + Z v, and the multipliers of the original rows.
  if (m_eq_ > 0) {
    x_ = x0_;
    for (int j = 0; j < nc_; ++j) x_(free_[static_cast<std::size_t>(j)]) = v_(j);
    for (int b = 0; b < rank_; ++b) {
      x_(basis_[static_cast<std::size_t>(b)]) += Wt_.col(b).head(nc_).dot(v_.head(nc_));
    }
  } else {
    x_ = v_.head(n_);
  }
  for (int k = 0; k < q_; ++k) {
    const int id = active_[static_cast<std::size_t>(k)];
    mu_(id) = u_(k) * scale_(id);
    active_in_.push_back(id);
  }
  return finish(status, true);
}

// The dual method on min ½vᵀPv + qᵀv s.t. the raw rows in normals_ (columns,
// nc_ long) and offsets_, which it normalises first: row a v ≤ b becomes
// (−a/‖a‖) v − (−b/‖a‖) ≥ 0. Leaves v in v_ and the active set in active_/u_.
QpStatus QpSolver::dual_active_set(const Eigen::Ref<const Eigen::MatrixXd>& P,
                                   const Eigen::Ref<const Eigen::VectorXd>& q, bool warm_start) {
  const int nc = nc_;
  const double tol = options_.tolerance;
  const int max_iterations = options_.max_iterations > 0 ? options_.max_iterations : 3 * (n_ + m_eq_ + m_in_) + 10;
  std::fill(prefer_.begin(), prefer_.end(), 0);
  if (warm_start) {
    for (const int i : previous_) prefer_[static_cast<std::size_t>(i)] = 1;
  }
  for (int i = 0; i < m_in_; ++i) {
    auto col = normals_.col(i).head(nc);
    const double norm = col.norm();
    if (!std::isfinite(norm)) throw InvalidArgument(kNotFinite);
    if (norm == 0) {  // 0 ≤ b: met or impossible whatever v is
      offsets_(i) = offsets_(i) >= -tol ? -kInf : kInf;
      scale_(i) = 0;
      continue;
    }
    scale_(i) = 1 / norm;
    col *= -scale_(i);
    offsets_(i) *= -scale_(i);
  }

  // P = L Lᵀ (lower triangle of P), then J = L⁻ᵀ (upper triangular).
  auto L = L_.topLeftCorner(nc, nc);
  for (int j = 0; j < nc; ++j) {
    double djj = P(j, j) - L.row(j).head(j).squaredNorm();
    if (!(djj > 1e-14 * std::max(1.0, std::abs(P(j, j))))) return QpStatus::NotConvex;
    const double ljj = std::sqrt(djj);
    L(j, j) = ljj;
    for (int i = j + 1; i < nc; ++i) L(i, j) = (P(i, j) - L.row(i).head(j).dot(L.row(j).head(j))) / ljj;
  }
  auto J = J_.topLeftCorner(nc, nc);
  J.setZero();
  for (int j = 0; j < nc; ++j) {  // Lᵀ J = I, column by column (back substitution)
    J(j, j) = 1 / L(j, j);
    for (int i = j - 1; i >= 0; --i) {
      double sum = 0;
      for (int k = i + 1; k <= j; ++k) sum += L(k, i) * J(k, j);
      J(i, j) = -sum / L(i, i);
    }
  }
  // Unconstrained minimum v = −J Jᵀ q.
  d_.head(nc).noalias() = J.transpose() * q;
  v_.head(nc).noalias() = -J * d_.head(nc);

  // Add the most violated inequality until none is.
  while (true) {
    int p = -1;
    double worst = -tol, worst_preferred = -tol;
    int p_preferred = -1;
    if (m_in_ > 0) slack_.noalias() = normals_.topRows(nc).transpose() * v_.head(nc);
    for (int i = 0; i < m_in_; ++i) {
      if (scale_(i) == 0) {
        if (offsets_(i) == kInf) {
          blocking_ = i;
          return QpStatus::Infeasible;
        }
        continue;
      }
      const double s = slack_(i) - offsets_(i);
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
    if (p < 0) return QpStatus::Optimal;
    prefer_[static_cast<std::size_t>(p)] = 0;
    double u_plus = 0;
    // Move until p is met (full step) or an active multiplier hits 0 (partial step, drop it).
    while (true) {
      if (++iterations_ > max_iterations) return QpStatus::IterationLimit;
      step_direction(p);
      double t1 = kInf;
      int drop = -1;
      for (int k = 0; k < q_; ++k) {
        if (r_(k) <= 1e-12) continue;
        const double ratio = u_(k) / r_(k);
        if (ratio < t1) {
          t1 = ratio;
          drop = k;
        }
      }
      const double zn = d_.segment(q_, nc - q_).squaredNorm();
      const double slack = normals_.col(p).head(nc).dot(v_.head(nc)) - offsets_(p);
      const double t2 = zn > 1e-14 * std::max(1.0, d_.head(nc).squaredNorm()) ? -slack / zn : kInf;
      if (t1 == kInf && t2 == kInf) {
        blocking_ = p;
        return QpStatus::Infeasible;
      }
      if (t2 == kInf) {  // step in the dual only
        for (int k = 0; k < q_; ++k) u_(k) -= t1 * r_(k);
        u_plus += t1;
        drop_constraint(drop);
        continue;
      }
      const double t = std::min(t1, t2);
      v_.head(nc) += t * z_.head(nc);
      for (int k = 0; k < q_; ++k) u_(k) -= t * r_(k);
      u_plus += t;
      if (t2 <= t1) {
        u_(q_) = u_plus;
        if (!add_constraint(p)) {
          blocking_ = p;
          return QpStatus::Infeasible;
        }
        break;
      }
      drop_constraint(drop);
    }
  }
}

// Residuals of x_, lambda_, mu_ on the original rows; g_ holds P x + q + Aᵀ_in μ.
void QpSolver::compute_kkt(const Eigen::Ref<const Eigen::MatrixXd>& A_eq, const Eigen::Ref<const Eigen::VectorXd>& b_eq,
                           const Eigen::Ref<const Eigen::MatrixXd>& A_in,
                           const Eigen::Ref<const Eigen::VectorXd>& b_in) {
  kkt_ = KktResiduals{};
  if (m_eq_ > 0) {
    g_.noalias() += A_eq.transpose() * lambda_;
    eq_residual_.noalias() = A_eq * x_;
    eq_residual_ -= b_eq;
    kkt_.primal = eq_residual_.cwiseAbs().maxCoeff();
  }
  if (m_in_ > 0) {
    slack_ = b_in;
    slack_.noalias() -= A_in * x_;
    kkt_.primal = std::max(kkt_.primal, (-slack_).maxCoeff());
    kkt_.dual = std::max(0.0, (-mu_).maxCoeff());
    kkt_.complementarity = mu_.cwiseProduct(slack_).cwiseAbs().maxCoeff();
  }
  kkt_.stationarity = g_.cwiseAbs().maxCoeff();
  kkt_.primal = std::max(kkt_.primal, 0.0);
}

}  // namespace touchdown::plan
