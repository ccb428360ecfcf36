#include "viewline/tracking/ballistic.h"

#include <cmath>

#include "viewline/core/checks.h"

namespace viewline::tracking {

Matrix6 BallisticModel::processNoise(double dt) const {
  const Eigen::Matrix3d I = Eigen::Matrix3d::Identity();
  Matrix6 Q;
  Q << accel_psd * dt * dt * dt / 3.0 * I, accel_psd * dt * dt / 2.0 * I,  //
      accel_psd * dt * dt / 2.0 * I, accel_psd * dt * I;
  return Q;
}

estimation::LinearTransition BallisticModel::transition(double dt) const {
  if (!std::isfinite(dt)) core::requireFinite(dt, "ballistic transition dt");
  if (dt < 0.0) throw core::InvalidInput("ballistic transition dt is negative (expected >= 0)");
  if (!(accel_psd >= 0.0)) throw core::InvalidInput("ballistic model accel_psd must be >= 0");
  if (!gravity_w.allFinite()) core::requireFinite(gravity_w, "ballistic model gravity_w");
  const Eigen::Matrix3d I = Eigen::Matrix3d::Identity();
  estimation::LinearTransition tr;
  tr.Phi = Eigen::MatrixXd::Identity(6, 6);
  tr.Phi.topRightCorner(3, 3) = dt * I;
  tr.Gamma.resize(6, 3);
  tr.Gamma.topRows(3) = 0.5 * dt * dt * I;
  tr.Gamma.bottomRows(3) = dt * I;
  tr.u = gravity_w;
  tr.Q = processNoise(dt);
  tr.dt = dt;
  return tr;
}

Vector6 BallisticModel::propagate(const Vector6& x, double dt) const {
  Vector6 out;
  out.head<3>() = x.head<3>() + dt * x.tail<3>() + 0.5 * dt * dt * gravity_w;
  out.tail<3>() = x.tail<3>() + dt * gravity_w;
  return out;
}

}  // namespace viewline::tracking
