#include "pose/p3p.hpp"

#include <Eigen/Eigenvalues>
#include <cmath>

namespace touchdown::pose::detail {

namespace {

constexpr double kSideTolerance = 0.05;

// Polynomials as coefficient arrays, lowest degree first.
template <std::size_t N>
using Poly = std::array<double, N>;

template <std::size_t A, std::size_t B>
Poly<A + B - 1> multiply(const Poly<A>& p, const Poly<B>& q) {
  Poly<A + B - 1> r{};
  for (std::size_t i = 0; i < A; ++i) {
    for (std::size_t k = 0; k < B; ++k) r[i + k] += p[i] * q[k];
  }
  return r;
}

double evaluate(const Poly<5>& p, double x, double* derivative) {
  double v = 0, d = 0;
  for (int i = 4; i >= 0; --i) {
    d = d * x + v;
    v = v * x + p[static_cast<std::size_t>(i)];
  }
  *derivative = d;
  return v;
}

}  // namespace

P3pSolutions solve_p3p(const Eigen::Vector3d& j1, const Eigen::Vector3d& j2, const Eigen::Vector3d& j3, double a,
                       double b, double c) {
  P3pSolutions out;
  if (!(a > 0 && b > 0 && c > 0)) return out;
  const double ca = j2.dot(j3), cb = j1.dot(j3), cg = j1.dot(j2);  // cos α, cos β, cos γ
  // With s2 = u·s1 and s3 = v·s1, the law of cosines on the three sides:
  //   s1² (1 + v² − 2v cos β) = b²,  s1² (1 + u² − 2u cos γ) = c²,
  //   s1² (u² + v² − 2uv cos α) = a².
  // Eliminating s1 and u² gives u = N(v) / D(v) with K = (a² − c²)/b²,
  //   N = (K − 1) v² − 2K cos β v + (1 + K),  D = 2 (cos γ − v cos α),
  // and substituting into the second equation (times D²) the quartic
  //   D² + N² − 2 N D cos γ − (c²/b²)(1 + v² − 2v cos β) D² = 0.
  const double b2 = b * b, k = (a * a - c * c) / b2, c2b2 = c * c / b2;
  const Poly<3> n{1 + k, -2 * k * cb, k - 1};
  const Poly<2> d{2 * cg, -2 * ca};
  const Poly<3> side{1, -2 * cb, 1};
  const Poly<3> dd = multiply(d, d);
  const Poly<5> nn = multiply(n, n);
  const Poly<4> nd = multiply(n, d);
  const Poly<5> sdd = multiply(side, dd);
  Poly<5> q{};
  for (std::size_t i = 0; i < 5; ++i) {
    q[i] = nn[i] - c2b2 * sdd[i];
    if (i < 3) q[i] += dd[i];
    if (i < 4) q[i] -= 2 * cg * nd[i];
  }
  double scale = 0;
  for (const double x : q) scale = std::max(scale, std::abs(x));
  if (!(scale > 0) || !std::isfinite(scale) || std::abs(q[4]) < 1e-10 * scale) return out;
  // Real roots: the eigenvalues of the companion matrix.
  Eigen::Matrix4d companion = Eigen::Matrix4d::Zero();
  for (int i = 0; i < 4; ++i) companion(i, 3) = -q[static_cast<std::size_t>(i)] / q[4];
  for (int i = 1; i < 4; ++i) companion(i, i - 1) = 1;
  const Eigen::EigenSolver<Eigen::Matrix4d> es(companion, false);
  if (es.info() != Eigen::Success) return out;
  for (int r = 0; r < 4; ++r) {
    const std::complex<double> root = es.eigenvalues()(r);
    // A double root that noise split into a complex pair: its real part.
    if (std::abs(root.imag()) > 1e-2 * (1 + std::abs(root.real()))) continue;
    if (root.imag() < 0) continue;  // one of a (near-)conjugate pair
    double v = root.real();
    for (int it = 0; it < 2; ++it) {  // Newton polish
      double dv = 0;
      const double f = evaluate(q, v, &dv);
      if (std::abs(dv) > 1e-300) v -= f / dv;
    }
    const double dv = 2 * (cg - v * ca);
    if (std::abs(dv) < 1e-12) continue;
    const double u = (n[0] + v * (n[1] + v * n[2])) / dv;
    const double s1 = b / std::sqrt(1 + v * v - 2 * v * cb);
    const Eigen::Vector3d s(s1, u * s1, v * s1);
    if (!(s.minCoeff() > 0) || !s.allFinite()) continue;
    // The sides it implies: exact for a real root; within 5 % for the real
    // part of a near-complex one; far off on degenerate input (collinear
    // rays).
    const Eigen::Vector3d q1 = s(0) * j1, q2 = s(1) * j2, q3 = s(2) * j3;
    if (std::abs((q2 - q3).norm() - a) > kSideTolerance * a || std::abs((q1 - q2).norm() - c) > kSideTolerance * c)
      continue;
    out.s[static_cast<std::size_t>(out.count++)] = s;
  }
  return out;
}

}  // namespace touchdown::pose::detail
