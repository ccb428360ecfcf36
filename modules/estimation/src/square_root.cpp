#include "viewline/estimation/square_root.h"

#include <Eigen/Cholesky>
#include <algorithm>
#include <cmath>
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

void lowerTriangularizeInPlace(Eigen::Ref<RowMatrixXd> A) {
  const Eigen::Index r = A.rows();
  const Eigen::Index c = A.cols();
  const Eigen::Index k = std::min(r, c);
  for (Eigen::Index i = 0; i < k; ++i) {
    const Eigen::Index len = c - i;
    auto x = A.row(i).segment(i, len);
    const double tail = (len > 1) ? x.tail(len - 1).squaredNorm() : 0.0;
    if (tail > 0.0) {
      // Householder H = I − β v vᵀ with x H = α e₁ (row i): α = −sign(x₀) σ, v = x − α e₁,
      // β = 2 / vᵀv = 1 / (σ (σ + |x₀|)) (no cancellation).
      const double x0 = x[0];
      const double sigma = std::sqrt(x0 * x0 + tail);
      const double alpha = (x0 > 0.0) ? -sigma : sigma;
      const double beta = 1.0 / (sigma * (sigma + std::abs(x0)));
      x[0] = x0 - alpha;  // x now holds v
      for (Eigen::Index j = i + 1; j < r; ++j) {
        auto row = A.row(j).segment(i, len);
        const double w = beta * row.dot(x);
        row -= w * x;
      }
      x[0] = alpha;
      x.tail(len - 1).setZero();
    }
    // Non-negative diagonal: flip column i (rows above i are already zero there).
    if (A(i, i) < 0.0) A.col(i).tail(r - i) *= -1.0;
  }
}

Eigen::MatrixXd lowerTriangularize(const Eigen::MatrixXd& A) {
  const Eigen::Index r = A.rows();
  const Eigen::Index c = A.cols();
  Eigen::MatrixXd T = Eigen::MatrixXd::Zero(r, r);
  if (r == 0) return T;
  RowMatrixXd work = A;
  lowerTriangularizeInPlace(work);
  const Eigen::Index k = std::min(r, c);
  T.leftCols(k) = work.leftCols(k);
  return T;
}

}  // namespace viewline::estimation
