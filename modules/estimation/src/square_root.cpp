#include "viewline/estimation/square_root.h"

#include <Eigen/Cholesky>
#include <Eigen/QR>
#include <string>

#include "viewline/core/checks.h"

namespace viewline::estimation {

Eigen::MatrixXd psdSqrt(const Eigen::MatrixXd& M, const char* what) {
  const Eigen::Index n = M.rows();
  if (n == 0) return Eigen::MatrixXd(0, 0);
  Eigen::LLT<Eigen::MatrixXd> llt(M);
  if (llt.info() == Eigen::Success) return llt.matrixL();
  core::requireSymmetricPositiveSemiDefinite(M, what);
  // Semi-definite: M = Pᵀ L D Lᵀ P  ->  F = Pᵀ L D^½.
  Eigen::LDLT<Eigen::MatrixXd> ldlt(M);
  const Eigen::VectorXd d = ldlt.vectorD().cwiseMax(0.0).cwiseSqrt();
  Eigen::MatrixXd L = ldlt.matrixL();
  Eigen::MatrixXd F = ldlt.transpositionsP().transpose() * (L * d.asDiagonal());
  return F;
}

Eigen::MatrixXd lowerTriangularize(const Eigen::MatrixXd& A) {
  const Eigen::Index r = A.rows();
  const Eigen::Index c = A.cols();
  Eigen::MatrixXd T = Eigen::MatrixXd::Zero(r, r);
  if (r == 0) return T;
  // Aᵀ = Q R  ->  A = Rᵀ Qᵀ, A Aᵀ = Rᵀ R; T = Rᵀ (first r rows of R).
  Eigen::HouseholderQR<Eigen::MatrixXd> qr(A.transpose());
  const Eigen::Index k = std::min(r, c);
  const Eigen::MatrixXd R = qr.matrixQR().topRows(k).template triangularView<Eigen::Upper>();
  T.leftCols(k) = R.transpose();
  for (Eigen::Index j = 0; j < k; ++j) {
    if (T(j, j) < 0.0) T.col(j) = -T.col(j);
  }
  return T;
}

}  // namespace viewline::estimation
