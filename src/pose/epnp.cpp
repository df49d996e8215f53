// EPnP, following Lepetit, Moreno-Noguer & Fua, "EPnP: An Accurate O(n)
// Solution to the PnP Problem", IJCV 81(2), 2009. Section numbers below
// refer to that paper. Everything is fixed-size: no heap allocation.
#include "touchdown/pose/epnp.hpp"

#include <Eigen/Cholesky>
#include <Eigen/LU>
#include <Eigen/SVD>
#include <array>
#include <cmath>
#include <limits>
#include <utility>

#include "dense_solvers.hpp"

namespace touchdown::pose {
namespace {

// Build cost: each of Eigen's decompositions is instantiated, unrolled and
// vectorised per matrix type; with six fixed-size ones (three eigensolvers,
// three SVDs, an LU) this file took about a minute to compile. The symmetric
// eigenproblems and the relinearisation's least squares now go through
// dense_solvers.cpp, compiled once and in parallel with this file.
using detail::SymmetricMatrix;
using detail::SymmetricVector;

struct SymmetricEigen {
  SymmetricVector eigenvalues;   // ascending
  SymmetricMatrix eigenvectors;  // columns
  bool ok = false;
  explicit SymmetricEigen(const SymmetricMatrix& a) { ok = detail::symmetric_eigen(a, eigenvalues, eigenvectors); }
};

// Control points in the body frame (sec. 3.1): the centroid and, per
// principal axis of the points, the centroid plus sqrt(λ/n) along it. `K`
// is 4 (general) or 3 (planar: the two in-plane axes).
template <int K>
struct ControlPoints {
  Eigen::Matrix<double, 3, K> c;             // columns c_0 .. c_{K-1}
  Eigen::Matrix<double, K - 1, 3> to_alpha;  // (α_1..α_{K-1}) = to_alpha (p − c_0)
};

struct PointStats {
  Eigen::Vector3d centroid;
  Eigen::Vector3d eigenvalues;   // ascending
  Eigen::Matrix3d eigenvectors;  // columns, matching eigenvalues
};

PointStats point_stats(std::span<const Eigen::Vector3d> p) {
  PointStats s;
  s.centroid.setZero();
  for (const auto& q : p) s.centroid += q;
  s.centroid /= static_cast<double>(p.size());
  Eigen::Matrix3d S = Eigen::Matrix3d::Zero();
  for (const auto& q : p) S.noalias() += (q - s.centroid) * (q - s.centroid).transpose();
  SymmetricVector eigenvalues;
  SymmetricMatrix eigenvectors;
  if (!detail::symmetric_eigen(S / static_cast<double>(p.size()), eigenvalues, eigenvectors)) {
    s.eigenvalues.setZero();  // reads as collinear: no solution
    s.eigenvectors.setIdentity();
    return s;
  }
  s.eigenvalues = eigenvalues.cwiseMax(0.0);
  s.eigenvectors = eigenvectors;
  return s;
}

template <int K>
bool make_control_points(const PointStats& s, ControlPoints<K>& cp) {
  cp.c.col(0) = s.centroid;
  Eigen::Matrix<double, 3, K - 1> axes;
  for (int k = 1; k < K; ++k) {
    const int e = 3 - k;  // largest eigenvalue first
    const double scale = std::sqrt(s.eigenvalues(e));
    if (!(scale > 1e-12)) return false;
    axes.col(k - 1) = scale * s.eigenvectors.col(e);
    cp.c.col(k) = s.centroid + axes.col(k - 1);
  }
  // The axes are orthogonal, so the (pseudo-)inverse is axesᵀ / |axis|².
  for (int k = 0; k < K - 1; ++k) cp.to_alpha.row(k) = axes.col(k).transpose() / axes.col(k).squaredNorm();
  return true;
}

template <int K>
Eigen::Matrix<double, K, 1> alphas(const ControlPoints<K>& cp, const Eigen::Vector3d& p) {
  Eigen::Matrix<double, K, 1> a;
  a.template tail<K - 1>() = cp.to_alpha * (p - cp.c.col(0));
  a(0) = 1.0 - a.template tail<K - 1>().sum();
  return a;
}

// Rigid transform with p_camera ≈ R p_body + t (absolute orientation by SVD,
// Arun, Huang & Blostein 1987 / Umeyama 1991 without scale).
Eigen::Isometry3d absolute_orientation(std::span<const Eigen::Vector3d> p_body, const Eigen::Vector3d* p_camera,
                                       std::size_t n) {
  Eigen::Vector3d mb = Eigen::Vector3d::Zero(), mc = Eigen::Vector3d::Zero();
  for (std::size_t i = 0; i < n; ++i) {
    mb += p_body[i];
    mc += p_camera[i];
  }
  mb /= static_cast<double>(n);
  mc /= static_cast<double>(n);
  Eigen::Matrix3d H = Eigen::Matrix3d::Zero();
  for (std::size_t i = 0; i < n; ++i) H.noalias() += (p_camera[i] - mc) * (p_body[i] - mb).transpose();
  const Eigen::JacobiSVD<Eigen::Matrix3d> svd(H, Eigen::ComputeFullU | Eigen::ComputeFullV);
  Eigen::Matrix3d D = Eigen::Matrix3d::Identity();
  if ((svd.matrixU() * svd.matrixV().transpose()).determinant() < 0) D(2, 2) = -1;
  Eigen::Isometry3d T = Eigen::Isometry3d::Identity();
  T.linear() = svd.matrixU() * D * svd.matrixV().transpose();
  T.translation() = mc - T.linear() * mb;
  return T;
}

double reprojection_rms(const PinholeCamera& cam, const Eigen::Isometry3d& T, std::span<const Eigen::Vector3d> p,
                        std::span<const Eigen::Vector2d> uv) {
  double s = 0;
  for (std::size_t i = 0; i < p.size(); ++i) {
    const Eigen::Vector3d q = T * p[i];
    if (!(q.z() > 0)) return std::numeric_limits<double>::infinity();
    s += (cam.project(q) - uv[i]).squaredNorm();
  }
  return std::sqrt(s / static_cast<double>(p.size()));
}

// Index of β_ab (a ≤ b < 4) in the 10-vector (β00, β01, β02, β03, β11, ...).
constexpr int pair_index(int a, int b) {
  if (a > b) std::swap(a, b);
  constexpr int kStart[4] = {0, 4, 7, 9};
  return kStart[a] + (b - a);
}

// The identities β_x0 β_y0 = β_x1 β_y1 between the ten products β_ab used
// by the relinearisation (sec. 3.3): β_aa β_bb = β_ab² (6), β_aa β_bd =
// β_ab β_ad (12), β_01 β_23 = β_02 β_13 = β_03 β_12 (2).
struct ProductIdentity {
  int x0, y0, x1, y1;
};
constexpr std::array<ProductIdentity, 20> make_product_identities() {
  std::array<ProductIdentity, 20> t{};
  int row = 0;
  for (int a = 0; a < 4; ++a) {
    for (int b = a + 1; b < 4; ++b) t[row++] = {pair_index(a, a), pair_index(b, b), pair_index(a, b), pair_index(a, b)};
  }
  for (int a = 0; a < 4; ++a) {
    for (int b = 0; b < 4; ++b) {
      for (int d = b + 1; d < 4; ++d) {
        if (b == a || d == a) continue;
        t[row++] = {pair_index(a, a), pair_index(b, d), pair_index(a, b), pair_index(a, d)};
      }
    }
  }
  t[row++] = {pair_index(0, 1), pair_index(2, 3), pair_index(0, 2), pair_index(1, 3)};
  t[row++] = {pair_index(0, 1), pair_index(2, 3), pair_index(0, 3), pair_index(1, 2)};
  return t;
}
constexpr std::array<ProductIdentity, 20> kProductIdentities = make_product_identities();

// The solver for K control points (3K unknowns: their camera coordinates).
template <int K>
class Epnp {
 public:
  static constexpr int kDim = 3 * K;
  static constexpr int kPairs = K * (K - 1) / 2;
  using VecD = Eigen::Matrix<double, kDim, 1>;

  Epnp(const PinholeCamera& cam, std::span<const Eigen::Vector3d> p, std::span<const Eigen::Vector2d> uv,
       const ControlPoints<K>& cp)
      : cam_(cam), p_(p), uv_(uv), cp_(cp) {}

  EpnpResult solve() {
    // Sec. 3.2: M x = 0 with two rows per point; accumulate MᵀM directly.
    Eigen::Matrix<double, kDim, kDim> MtM = Eigen::Matrix<double, kDim, kDim>::Zero();
    Eigen::Matrix<double, kDim, 1> ru, rv;
    for (std::size_t i = 0; i < p_.size(); ++i) {
      const auto a = alphas(cp_, p_[i]);
      for (int j = 0; j < K; ++j) {
        ru.template segment<3>(3 * j) << a(j) * cam_.fx, 0.0, a(j) * (cam_.cx - uv_[i].x());
        rv.template segment<3>(3 * j) << 0.0, a(j) * cam_.fy, a(j) * (cam_.cy - uv_[i].y());
      }
      MtM.noalias() += ru * ru.transpose();
      MtM.noalias() += rv * rv.transpose();
    }
    const SymmetricEigen es{SymmetricMatrix(MtM)};
    if (!es.ok) return {};                                       // NoSolution
    for (int k = 0; k < 4; ++k) v_[k] = es.eigenvectors.col(k);  // smallest eigenvalues first
    // Squared control-point distances in the body frame (ρ of sec. 3.3).
    int q = 0;
    for (int i = 0; i < K; ++i) {
      for (int j = i + 1; j < K; ++j, ++q) {
        pair_[q] = {i, j};
        rho_[q] = (cp_.c.col(i) - cp_.c.col(j)).squaredNorm();
      }
    }
    EpnpResult best;
    best.rms_px = std::numeric_limits<double>::infinity();
    // Sec. 3.3: N = 1, 2, 3 null-space directions (N = 3 needs 6 distance
    // constraints, i.e. K = 4); each refined by Gauss–Newton (sec. 3.5).
    const int max_n = K == 4 ? 3 : 2;
    for (int n = 1; n <= max_n; ++n) {
      Eigen::Vector4d beta = Eigen::Vector4d::Zero();
      if (!initial_betas(n, beta)) continue;
      refine_betas(K == 4 ? 4 : 3, beta);
      consider(beta, best);
    }
    if constexpr (K == 4) {
      // N = 4 (four points: the null space is 4-dimensional), solved by
      // relinearisation (sec. 3.3), and the cheap β_0a-only guess of the
      // authors' reference code; each refined over all four betas. With
      // five or more points the null space is 1-dimensional up to noise and
      // N ≤ 3 suffices, so the costlier relinearisation is skipped.
      Eigen::Vector4d beta;
      if (p_.size() == 4 && relinearised_betas(beta)) {
        refine_betas(4, beta);
        consider(beta, best);
      }
      if (first_row_betas(beta)) {
        refine_betas(4, beta);
        consider(beta, best);
      }
    }
    best.status = std::isfinite(best.rms_px) ? EpnpStatus::Ok : EpnpStatus::NoSolution;
    best.planar = K == 3;
    return best;
  }

 private:
  // Differences of null vector k between control points i and j.
  Eigen::Vector3d dv(int k, int pair) const {
    const auto [i, j] = pair_[pair];
    return v_[k].template segment<3>(3 * i) - v_[k].template segment<3>(3 * j);
  }

  // Linearised distance constraints: Σ_{a≤b} β_ab (2 − δ_ab) dv_a·dv_b = ρ
  // in the unknowns β_ab = β_a β_b, solved by least squares, then the
  // betas read off the square terms (sec. 3.3).
  bool initial_betas(int n, Eigen::Vector4d& beta) const {
    const int m = n * (n + 1) / 2;
    Eigen::Matrix<double, kPairs, 6> L = Eigen::Matrix<double, kPairs, 6>::Zero();
    Eigen::Matrix<double, kPairs, 1> rho;
    for (int q = 0; q < kPairs; ++q) {
      int c = 0;
      for (int a = 0; a < n; ++a) {
        for (int b = a; b < n; ++b, ++c) L(q, c) = (a == b ? 1.0 : 2.0) * dv(a, q).dot(dv(b, q));
      }
      rho(q) = rho_[q];
    }
    if (m > kPairs) return false;
    const Eigen::Matrix<double, 6, 6> LtL = L.transpose() * L;
    const Eigen::Matrix<double, 6, 1> Ltr = L.transpose() * rho;
    Eigen::Matrix<double, 6, 1> x = Eigen::Matrix<double, 6, 1>::Zero();
    {
      // Solve the leading m×m block.
      Eigen::Matrix<double, 6, 6> A = Eigen::Matrix<double, 6, 6>::Identity();
      A.topLeftCorner(m, m) = LtL.topLeftCorner(m, m);
      Eigen::Matrix<double, 6, 1> rhs = Eigen::Matrix<double, 6, 1>::Zero();
      rhs.head(m) = Ltr.head(m);
      const Eigen::FullPivLU<Eigen::Matrix<double, 6, 6>> lu(A);
      if (!lu.isInvertible()) return false;
      x = lu.solve(rhs);
    }
    // Index of β_aa in x.
    auto diag_index = [n](int a) {
      int c = 0;
      for (int i = 0; i < a; ++i) c += n - i;
      return c;
    };
    const double b00 = x(diag_index(0));
    if (b00 <= 0) {
      // All squared-norm terms must be positive; try the other sign of the solution.
      x = -x;
    }
    if (!(x(diag_index(0)) > 0)) return false;
    beta.setZero();
    beta(0) = std::sqrt(x(diag_index(0)));
    for (int a = 1; a < n; ++a) {
      // β_0a = β_0 β_a gives β_a with its sign; its magnitude agrees with β_aa.
      beta(a) = x(a) / beta(0);
    }
    return true;
  }

  // Relinearisation for N = 4: the 6 linear equations in the 10 products
  // β_ab leave β̄ = β̄_p + Σ λ_i n_i (4 null vectors n_i); the identities
  // β_ab β_cd = β_ac β_bd between products are then linear in (λ_i, λ_iλ_j)
  // (14 unknowns, 20 equations), solved by least squares.
  bool relinearised_betas(Eigen::Vector4d& beta) const {
    Eigen::Matrix<double, 6, 10> L;
    Eigen::Matrix<double, 6, 1> rho;
    for (int q = 0; q < 6; ++q) {
      for (int a = 0; a < 4; ++a) {
        for (int b = a; b < 4; ++b) L(q, pair_index(a, b)) = (a == b ? 1.0 : 2.0) * dv(a, q).dot(dv(b, q));
      }
      rho(q) = rho_[q];
    }
    // β̄_p: minimum-norm solution; N: null space of L (rank 6).
    detail::RectVector bp_solution;
    detail::SquareMatrix null_space;
    if (!detail::min_norm_and_null_space(L, rho, 1e-12, bp_solution, null_space)) return false;
    const Eigen::Matrix<double, 10, 1> bp = bp_solution;
    const Eigen::Matrix<double, 10, 4> N = null_space;
    // z = (λ_0..λ_3, λ_00, λ_01, λ_02, λ_03, λ_11, λ_12, λ_13, λ_22, λ_23, λ_33).
    Eigen::Matrix<double, 20, 14> A = Eigen::Matrix<double, 20, 14>::Zero();
    Eigen::Matrix<double, 20, 1> c = Eigen::Matrix<double, 20, 1>::Zero();
    // Adds +sign · β̄_X β̄_Y to equation `row`.
    auto add_product = [&](int row, int X, int Y, double sign) {
      c(row) += sign * bp(X) * bp(Y);
      for (int i = 0; i < 4; ++i) {
        A(row, i) += sign * (bp(X) * N(Y, i) + bp(Y) * N(X, i));
        for (int j = i; j < 4; ++j) {
          const double q = i == j ? N(X, i) * N(Y, i) : N(X, i) * N(Y, j) + N(X, j) * N(Y, i);
          A(row, 4 + pair_index(i, j)) += sign * q;
        }
      }
    };
    // One loop over the table (rather than a call per identity) keeps the
    // compiler from unrolling twenty copies of add_product.
    for (int row = 0; row < 20; ++row) {
      const ProductIdentity& e = kProductIdentities[row];
      add_product(row, e.x0, e.y0, 1);
      add_product(row, e.x1, e.y1, -1);
    }
    detail::RectVector z_solution;
    detail::least_squares(A, -c, z_solution);
    const Eigen::Matrix<double, 14, 1> z = z_solution;
    if (!z.allFinite()) return false;
    const Eigen::Matrix<double, 10, 1> b = bp + N * z.template head<4>();
    // β_a = ±sqrt(β_aa), signs relative to the largest.
    int m = 0;
    for (int a = 1; a < 4; ++a) {
      if (b(pair_index(a, a)) > b(pair_index(m, m))) m = a;
    }
    if (!(b(pair_index(m, m)) > 0)) return false;
    const double bm = std::sqrt(b(pair_index(m, m)));
    for (int a = 0; a < 4; ++a) beta(a) = a == m ? bm : b(pair_index(m, a)) / bm;
    return true;
  }

  // Least squares on the β_0a = β_0 β_a terms alone (a = 0..3).
  bool first_row_betas(Eigen::Vector4d& beta) const {
    Eigen::Matrix<double, kPairs, 4> L;
    Eigen::Matrix<double, kPairs, 1> rho;
    for (int q = 0; q < kPairs; ++q) {
      for (int a = 0; a < 4; ++a) L(q, a) = (a == 0 ? 1.0 : 2.0) * dv(0, q).dot(dv(a, q));
      rho(q) = rho_[q];
    }
    Eigen::Vector4d x = (L.transpose() * L).ldlt().solve(L.transpose() * rho);
    if (!x.allFinite()) return false;
    if (x(0) < 0) x = -x;
    if (!(x(0) > 0)) return false;
    beta(0) = std::sqrt(x(0));
    for (int a = 1; a < 4; ++a) beta(a) = x(a) / beta(0);
    return true;
  }

  // Gauss–Newton on Σ_q (|Σ_k β_k dv_k|² − ρ_q)² over the first n betas (sec. 3.5).
  void refine_betas(int n, Eigen::Vector4d& beta) const {
    for (int it = 0; it < 5; ++it) {
      Eigen::Matrix4d JtJ = Eigen::Matrix4d::Zero();
      Eigen::Vector4d Jtr = Eigen::Vector4d::Zero();
      for (int q = 0; q < kPairs; ++q) {
        Eigen::Vector3d d = Eigen::Vector3d::Zero();
        for (int k = 0; k < n; ++k) d += beta(k) * dv(k, q);
        const double r = d.squaredNorm() - rho_[q];
        Eigen::Vector4d J = Eigen::Vector4d::Zero();
        for (int k = 0; k < n; ++k) J(k) = 2.0 * d.dot(dv(k, q));
        JtJ.noalias() += J * J.transpose();
        Jtr += J * r;
      }
      for (int k = n; k < 4; ++k) JtJ(k, k) = 1.0;  // unused betas stay fixed
      const Eigen::Vector4d step = JtJ.ldlt().solve(-Jtr);
      if (!step.allFinite()) return;
      beta += step;
      if (step.norm() < 1e-14 * (1.0 + beta.norm())) return;
    }
  }

  void consider(const Eigen::Vector4d& beta, EpnpResult& best) const {
    VecD x = VecD::Zero();
    for (int k = 0; k < 4; ++k) x += beta(k) * v_[k];
    // Camera-frame points from the control points; flip the global sign
    // if they lie behind the camera (the constraints are sign-blind).
    std::array<Eigen::Vector3d, kMaxPoints> pc;
    const std::size_t n = std::min(p_.size(), kMaxPoints);
    double zsum = 0;
    for (std::size_t i = 0; i < n; ++i) {
      const auto a = alphas(cp_, p_[i]);
      pc[i].setZero();
      for (int j = 0; j < K; ++j) pc[i] += a(j) * x.template segment<3>(3 * j);
      zsum += pc[i].z();
    }
    if (zsum < 0) {
      for (std::size_t i = 0; i < n; ++i) pc[i] = -pc[i];
    }
    const Eigen::Isometry3d T = absolute_orientation(p_.first(n), pc.data(), n);
    const double rms = reprojection_rms(cam_, T, p_, uv_);
    if (rms < best.rms_px) {
      best.rms_px = rms;
      best.T_camera_body = T;
    }
  }

 public:
  // Points beyond this many use the first kMaxPoints for the alignment
  // (the reprojection check still uses all of them).
  static constexpr std::size_t kMaxPoints = 64;

 private:
  const PinholeCamera& cam_;
  std::span<const Eigen::Vector3d> p_;
  std::span<const Eigen::Vector2d> uv_;
  const ControlPoints<K>& cp_;
  VecD v_[4];
  std::pair<int, int> pair_[kPairs];
  double rho_[kPairs];
};

}  // namespace

EpnpResult solve_epnp(const PinholeCamera& cam, std::span<const Eigen::Vector3d> p_body,
                      std::span<const Eigen::Vector2d> uv_px) {
  EpnpResult best;
  const std::size_t n = p_body.size();
  if (n != uv_px.size() || n < 4) {
    best.status = EpnpStatus::TooFewPoints;
    return best;
  }
  const PointStats s = point_stats(p_body);
  const double spread = s.eigenvalues(2);
  best.status = EpnpStatus::Degenerate;  // until a solver runs on a set of control points
  if (!(spread > 0) || s.eigenvalues(1) < 1e-10 * spread) return best;  // collinear
  // Quasi-planar sets (relief small against the extent) make the fourth
  // control point ill-conditioned: solve them both ways and keep the better.
  const double flatness = s.eigenvalues(0) / spread;
  if (flatness > 1e-8) {
    ControlPoints<4> cp;
    if (make_control_points(s, cp)) best = Epnp<4>(cam, p_body, uv_px, cp).solve();
  }
  if (flatness < 1e-2) {
    ControlPoints<3> cp;
    if (make_control_points(s, cp)) {
      const EpnpResult planar = Epnp<3>(cam, p_body, uv_px, cp).solve();
      if (planar.ok() ? !best.ok() || planar.rms_px < best.rms_px : !best.ok()) best = planar;
    }
  }
  return best;
}

PoseRefinement solve_pnp(const PinholeCamera& cam, std::span<const Eigen::Vector3d> p_body,
                         std::span<const Eigen::Vector2d> uv_px, const GaussNewtonOptions& options) {
  const EpnpResult e = solve_epnp(cam, p_body, uv_px);
  if (!e.ok()) {
    PoseRefinement r;
    r.status = RefineStatus::Degenerate;
    return r;
  }
  return refine_pose_gauss_newton(cam, p_body, uv_px, e.T_camera_body, options);
}

}  // namespace touchdown::pose
