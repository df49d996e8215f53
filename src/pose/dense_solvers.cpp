#include "dense_solvers.hpp"

#include <Eigen/Eigenvalues>
#include <Eigen/SVD>

namespace touchdown::pose::detail {

bool symmetric_eigen(const SymmetricMatrix& a, SymmetricVector& eigenvalues, SymmetricMatrix& eigenvectors) {
  const Eigen::SelfAdjointEigenSolver<SymmetricMatrix> es(a);
  if (es.info() != Eigen::Success) return false;
  eigenvalues = es.eigenvalues();
  eigenvectors = es.eigenvectors();
  return true;
}

void svd(const SvdMatrix& a, SvdLeftMatrix& u, SvdVector& s, SvdRightMatrix& v) {
  const Eigen::JacobiSVD<SvdMatrix> decomposition(a, Eigen::ComputeFullU | Eigen::ComputeFullV);
  u = decomposition.matrixU();
  s = decomposition.singularValues();
  v = decomposition.matrixV();
}

void least_squares(const SvdMatrix& a, const SvdVector& b, SvdVector& x) {
  const Eigen::JacobiSVD<SvdMatrix> decomposition(a, Eigen::ComputeFullU | Eigen::ComputeFullV);
  x = decomposition.solve(b);
}

}  // namespace touchdown::pose::detail
