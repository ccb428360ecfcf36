#include "viewline/estimation/models/constant_velocity.h"

#include "model_checks.h"

namespace viewline::estimation {

void ConstantVelocityModel::validate() const {
  detail::requireDim(dim, "ConstantVelocityModel.dim");
  detail::requireNonNegative(q, "ConstantVelocityModel.q");
}

LinearTransition ConstantVelocityModel::transition(double dt) const {
  validate();
  detail::requireDt(dt, "ConstantVelocityModel");
  const Eigen::Index d = dim;
  const Eigen::MatrixXd I = Eigen::MatrixXd::Identity(d, d);
  LinearTransition tr;
  tr.Phi = Eigen::MatrixXd::Identity(2 * d, 2 * d);
  tr.Phi.topRightCorner(d, d) = dt * I;
  // Q = q [dt³/3, dt²/2; dt²/2, dt] ⊗ I
  tr.Q.resize(2 * d, 2 * d);
  tr.Q << q * dt * dt * dt / 3.0 * I, q * dt * dt / 2.0 * I, q * dt * dt / 2.0 * I, q * dt * I;
  tr.dt = dt;
  return tr;
}

}  // namespace viewline::estimation
