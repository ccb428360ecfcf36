#pragma once
// Square-root helpers: factors of PSD matrices and the QR triangularisation
// used by the array algorithms.

#include <Eigen/Core>

namespace viewline::estimation {

/// A square-root factor F (n x n) with F Fᵀ = M for a symmetric positive semi-definite M
/// (Cholesky when definite, pivoted LDLT otherwise). Throws core::InvalidInput when M is not PSD.
Eigen::MatrixXd psdSqrt(const Eigen::MatrixXd& M, const char* what);

/// Lower-triangular T (rows(A) x rows(A)) with T Tᵀ = A Aᵀ, from a Householder QR of Aᵀ.
/// The diagonal of T is made non-negative.
Eigen::MatrixXd lowerTriangularize(const Eigen::MatrixXd& A);

/// Row-major dynamic matrix: the layout lowerTriangularizeInPlace works on.
using RowMatrixXd = Eigen::Matrix<double, Eigen::Dynamic, Eigen::Dynamic, Eigen::RowMajor>;

/// In-place form of lowerTriangularize for the filter's hot path: Householder reflections applied
/// from the right, row by row (A ← A Θ, Θ orthogonal), on a row-major array so that every
/// reflection works on contiguous row segments. On return, with r = rows(A), c = cols(A):
/// A(:, 0:min(r,c)) is lower triangular (trapezoidal when r > c) with a non-negative diagonal, the
/// other columns are zero, and A Aᵀ is unchanged. No allocation.
void lowerTriangularizeInPlace(Eigen::Ref<RowMatrixXd> A);

}  // namespace viewline::estimation
