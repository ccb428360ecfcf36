#include "viewline/estimation/models/constant_acceleration.h"

#include <Eigen/Core>
#include <unsupported/Eigen/KroneckerProduct>

#include "model_checks.h"

namespace viewline::estimation {

void ConstantAccelerationModel::validate() const {
  detail::requireDim(dim, "ConstantAccelerationModel.dim");
  detail::requireNonNegative(q, "ConstantAccelerationModel.q");
}

LinearTransition ConstantAccelerationModel::transition(double dt) const {
  validate();
  detail::requireDt(dt, "ConstantAccelerationModel");
  const double t2 = dt * dt, t3 = t2 * dt, t4 = t3 * dt, t5 = t4 * dt;
  Eigen::Matrix3d phi, qa;
  phi << 1.0, dt, t2 / 2.0, 0.0, 1.0, dt, 0.0, 0.0, 1.0;
  qa << t5 / 20.0, t4 / 8.0, t3 / 6.0, t4 / 8.0, t3 / 3.0, t2 / 2.0, t3 / 6.0, t2 / 2.0, dt;
  const Eigen::MatrixXd I = Eigen::MatrixXd::Identity(dim, dim);
  LinearTransition tr;
  // Block layout (p, ṗ, p̈): per-axis 3x3 ⊗ I_d.
  tr.Phi = Eigen::kroneckerProduct(Eigen::MatrixXd(phi), I);
  tr.Q = q * Eigen::kroneckerProduct(Eigen::MatrixXd(qa), I);
  tr.dt = dt;
  return tr;
}

}  // namespace viewline::estimation
