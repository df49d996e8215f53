#pragma once
// The dense decompositions of the pose code, compiled once (internal).
//
// Build cost: Eigen instantiates each decomposition per matrix type, and a
// fixed-size SelfAdjointEigenSolver or JacobiSVD costs several seconds of
// compile time each. Here each is instantiated once, on stack-allocated
// matrices of bounded dynamic size (no heap allocation), in its own
// translation unit, so the files that use them compile fast and in parallel.
#include <Eigen/Core>

namespace touchdown::pose::detail {

/// Symmetric problems up to 14x14 (EPnP's MᵀM is 9x9 or 12x12).
constexpr int kMaxSymmetricSize = 14;
using SymmetricMatrix = Eigen::Matrix<double, Eigen::Dynamic, Eigen::Dynamic, 0, kMaxSymmetricSize, kMaxSymmetricSize>;
using SymmetricVector = Eigen::Matrix<double, Eigen::Dynamic, 1, 0, kMaxSymmetricSize, 1>;

/// Eigenvalues (ascending) and eigenvectors (columns, matching) of the
/// symmetric matrix `a` (only its lower triangle is read); false when the
/// iteration did not converge.
bool symmetric_eigen(const SymmetricMatrix& a, SymmetricVector& eigenvalues, SymmetricMatrix& eigenvectors);

/// Rectangular problems up to 20 rows x 14 columns (EPnP's relinearisation:
/// 6x10 and 20x14).
constexpr int kMaxSvdRows = 20;
constexpr int kMaxSvdCols = 14;
using SvdMatrix = Eigen::Matrix<double, Eigen::Dynamic, Eigen::Dynamic, 0, kMaxSvdRows, kMaxSvdCols>;
using SvdLeftMatrix = Eigen::Matrix<double, Eigen::Dynamic, Eigen::Dynamic, 0, kMaxSvdRows, kMaxSvdRows>;
using SvdRightMatrix = Eigen::Matrix<double, Eigen::Dynamic, Eigen::Dynamic, 0, kMaxSvdCols, kMaxSvdCols>;
using SvdVector = Eigen::Matrix<double, Eigen::Dynamic, 1, 0, kMaxSvdRows, 1>;

/// Full singular value decomposition a = U diag(s) Vᵀ (Jacobi, singular
/// values descending; U is rows x rows, V is cols x cols).
void svd(const SvdMatrix& a, SvdLeftMatrix& u, SvdVector& s, SvdRightMatrix& v);

/// Minimum-norm least-squares solution of a x = b (Jacobi SVD with Eigen's
/// default rank threshold).
void least_squares(const SvdMatrix& a, const SvdVector& b, SvdVector& x);

}  // namespace touchdown::pose::detail
