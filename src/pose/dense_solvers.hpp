#pragma once
// The dense decompositions of the pose code, compiled once (internal).
//
// Build cost: Eigen instantiates each decomposition per matrix type, and a
// fixed-size SelfAdjointEigenSolver or JacobiSVD costs several seconds of
// compile time each (a JacobiSVD on rectangular matrices twice what a
// column-pivoted QR costs). Here each is instantiated once, on stack-allocated
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
/// 6x10 and 20x14), solved by column-pivoted Householder QR.
constexpr int kMaxRows = 20;
constexpr int kMaxCols = 14;
using RectMatrix = Eigen::Matrix<double, Eigen::Dynamic, Eigen::Dynamic, 0, kMaxRows, kMaxCols>;
using RectVector = Eigen::Matrix<double, Eigen::Dynamic, 1, 0, kMaxRows, 1>;
using SquareMatrix = Eigen::Matrix<double, Eigen::Dynamic, Eigen::Dynamic, 0, kMaxCols, kMaxCols>;

/// For `a` with fewer rows than columns and full row rank: the minimum-norm
/// solution x of a x = b and an orthonormal basis of the null space of `a`
/// (its columns), from the QR decomposition aᵀ P = Q R (x = Q₁ R₁⁻ᵀ Pᵀ b,
/// null space Q₂). False when |R_rr| ≤ rank_tolerance |R_11| (rank deficient).
bool min_norm_and_null_space(const RectMatrix& a, const RectVector& b, double rank_tolerance, RectVector& x,
                             SquareMatrix& null_space);

/// Least-squares solution of a x = b (rows ≥ cols; column-pivoted QR).
void least_squares(const RectMatrix& a, const RectVector& b, RectVector& x);

}  // namespace touchdown::pose::detail
