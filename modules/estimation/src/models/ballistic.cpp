#include "viewline/estimation/models/ballistic.h"

#include "model_checks.h"

namespace viewline::estimation {

void BallisticModel::validate() const {
  core::requireFinite(up, "BallisticModel.up");
  if (!(up.norm() > 0.0)) throw core::InvalidInput("BallisticModel.up is the zero vector (expected a direction)");
  detail::requireNonNegative(g, "BallisticModel.g");
  detail::requireNonNegative(q, "BallisticModel.q");
}

Eigen::Vector3d BallisticModel::gravity() const {
  validate();
  return -g * up.normalized();
}

LinearTransition BallisticModel::transition(double dt) const {
  validate();
  detail::requireDt(dt, "BallisticModel");
  const double h = dt;
  const Eigen::Matrix3d I = Eigen::Matrix3d::Identity();
  const Eigen::Vector3d gv = gravity();
  LinearTransition tr;
  // Φ = [I hI; 0 I]
  tr.Phi = Eigen::MatrixXd::Identity(6, 6);
  tr.Phi.topRightCorner<3, 3>() = h * I;
  // Γ = (h²/2 g_vec, h g_vec), u = 1: with up = y, Γ = (0, −g h²/2, 0, 0, −g h, 0)ᵀ ([L] eq 20).
  tr.Gamma.resize(6, 1);
  tr.Gamma.col(0) << 0.5 * h * h * gv, h * gv;
  tr.u = Eigen::VectorXd::Ones(1);
  // Q = q [h³/3 I, h²/2 I; h²/2 I, h I]
  tr.Q.resize(6, 6);
  tr.Q << q * h * h * h / 3.0 * I, q * h * h / 2.0 * I, q * h * h / 2.0 * I, q * h * I;
  tr.dt = dt;
  return tr;
}

}  // namespace viewline::estimation
