#include "viewline/estimation/models/singer.h"

#include <unsupported/Eigen/KroneckerProduct>
#include <unsupported/Eigen/MatrixFunctions>

#include "model_checks.h"

namespace viewline::estimation {

void SingerModel::validate() const {
  detail::requireDim(dim, "SingerModel.dim");
  core::requirePositive(tau, "SingerModel.tau");
  detail::requireNonNegative(sigma_m, "SingerModel.sigma_m");
}

LinearTransition SingerModel::transition(double dt) const {
  validate();
  detail::requireDt(dt, "SingerModel");
  const double alpha = 1.0 / tau;
  // Per axis: A = [[0,1,0],[0,0,1],[0,0,−α]], W = G Qc Gᵀ = 2 α σm² e3 e3ᵀ.
  Eigen::Matrix3d A = Eigen::Matrix3d::Zero();
  A(0, 1) = 1.0;
  A(1, 2) = 1.0;
  A(2, 2) = -alpha;
  const Eigen::Matrix3d phi = (A * dt).exp();
  // Q solves Q̇ = A Q + Q Aᵀ + W, Q(0) = 0: vec Q = ∫₀ᵀ e^{(A⊕A)s} ds vec W (column-major vec,
  // A⊕A = I⊗A + A⊗I), the upper-right block of exp([[A⊕A, vec W], [0, 0]] T). Only e^{+A s}
  // (stable) appears, so no overflow for small τ and no cancellation for large τ.
  const Eigen::Matrix3d I3 = Eigen::Matrix3d::Identity();
  Eigen::Matrix<double, 10, 10> M = Eigen::Matrix<double, 10, 10>::Zero();
  M.topLeftCorner<9, 9>() = Eigen::kroneckerProduct(I3, A) + Eigen::kroneckerProduct(A, I3);
  M(8, 9) = 2.0 * alpha * sigma_m * sigma_m;  // vec W: only W(2,2), index 2 + 3*2 = 8
  const Eigen::Matrix<double, 10, 10> E = (M * dt).exp();
  Eigen::Matrix3d qa = Eigen::Map<const Eigen::Matrix3d>(E.col(9).head<9>().data());
  qa = 0.5 * (qa + qa.transpose()).eval();

  const Eigen::MatrixXd I = Eigen::MatrixXd::Identity(dim, dim);
  LinearTransition tr;
  tr.Phi = Eigen::kroneckerProduct(Eigen::MatrixXd(phi), I);
  tr.Q = Eigen::kroneckerProduct(Eigen::MatrixXd(qa), I);
  tr.dt = dt;
  return tr;
}

}  // namespace viewline::estimation
