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

}  // namespace viewline::estimation
