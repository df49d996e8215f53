#include "dense_solvers.hpp"

#include <Eigen/Eigenvalues>
#include <Eigen/QR>
#include <cmath>

namespace touchdown::pose::detail {

bool symmetric_eigen(const SymmetricMatrix& a, SymmetricVector& eigenvalues, SymmetricMatrix& eigenvectors) {
  const Eigen::SelfAdjointEigenSolver<SymmetricMatrix> es(a);
  if (es.info() != Eigen::Success) return false;
  eigenvalues = es.eigenvalues();
  eigenvectors = es.eigenvectors();
  return true;
}

bool min_norm_and_null_space(const RectMatrix& a, const RectVector& b, double rank_tolerance, RectVector& x,
                             SquareMatrix& null_space) {
  const Eigen::Index r = a.rows(), n = a.cols();
  const Eigen::ColPivHouseholderQR<RectMatrix> qr(RectMatrix(a.transpose()));
  const RectMatrix& R = qr.matrixQR();  // R in the upper triangle
  if (!(std::abs(R(r - 1, r - 1)) > rank_tolerance * std::abs(R(0, 0)))) return false;
  const SquareMatrix Q = qr.householderQ();
  const RectVector pb = qr.colsPermutation().transpose() * b;
  const RectVector y = R.topLeftCorner(r, r).triangularView<Eigen::Upper>().transpose().solve(pb);
  x = Q.leftCols(r) * y;
  null_space = Q.rightCols(n - r);
  return true;
}

void least_squares(const RectMatrix& a, const RectVector& b, RectVector& x) {
  x = Eigen::ColPivHouseholderQR<RectMatrix>(a).solve(b);
}

}  // namespace touchdown::pose::detail
