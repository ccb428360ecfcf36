#include "viewline/estimation/models/ballistic_drag.h"

#include <cmath>
#include <sstream>

#include "model_checks.h"
#include "viewline/estimation/discretization.h"

namespace viewline::estimation {

namespace {
using Vec6 = Eigen::Matrix<double, 6, 1>;
using Mat6 = Eigen::Matrix<double, 6, 6>;

Vec6 toVec6(const Eigen::VectorXd& x, const char* what) {
  core::requireSize(x, 6, 1, what);
  core::requireFinite(x, what);
  return x;
}
}  // namespace

double DragBallisticModel::dragConstant(double rho, double cd, double area, double mass) {
  detail::requireNonNegative(rho, "dragConstant: air density rho");
  detail::requireNonNegative(cd, "dragConstant: drag coefficient Cd");
  detail::requireNonNegative(area, "dragConstant: cross-section area A");
  core::requirePositive(mass, "dragConstant: mass m");
  return rho * cd * area / (2.0 * mass);
}

void DragBallisticModel::validate() const {
  // The common case first: the checks below build their messages (std::string, heap) even when
  // they pass, and the planner validates the model on every propagation step.
  const auto fine = [](double v) { return std::isfinite(v) && v >= 0.0; };
  if (up.allFinite() && up.norm() > 0.0 && fine(g) && fine(k) && fine(q) && substeps >= 1) return;
  core::requireFinite(up, "DragBallisticModel.up");
  if (!(up.norm() > 0.0)) throw core::InvalidInput("DragBallisticModel.up is the zero vector (expected a direction)");
  detail::requireNonNegative(g, "DragBallisticModel.g");
  detail::requireNonNegative(k, "DragBallisticModel.k");
  detail::requireNonNegative(q, "DragBallisticModel.q");
  if (substeps < 1) {
    std::ostringstream s;
    s << "DragBallisticModel.substeps = " << substeps << " (expected >= 1)";
    throw core::InvalidInput(s.str());
  }
}

Eigen::Vector3d DragBallisticModel::gravity() const { return -g * up.normalized(); }

Vec6 DragBallisticModel::derivative(const Vec6& x) const {
  const Eigen::Vector3d v = x.tail<3>();
  Vec6 d;
  // ṗ = v, v̇ = g_vec − k |v| v
  d << v, gravity() - k * v.norm() * v;
  return d;
}

Mat6 DragBallisticModel::derivativeJacobian(const Vec6& x) const {
  const Eigen::Vector3d v = x.tail<3>();
  const double speed = v.norm();
  Mat6 J = Mat6::Zero();
  J.topRightCorner<3, 3>().setIdentity();
  // ∂(|v| v)/∂v = |v| I + v vᵀ/|v| (→ 0 as v → 0)
  if (speed > 0.0) {
    J.bottomRightCorner<3, 3>() = -k * (speed * Eigen::Matrix3d::Identity() + v * v.transpose() / speed);
  }
  return J;
}

namespace {

// The checks of propagate/jacobian without building a message unless one fails (a std::string
// per call would be a heap allocation in the planner's hot path).
void checkStep(const DragBallisticModel& m, const Vec6& x, double dt) {
  m.validate();
  if (!(std::isfinite(dt) && dt > 0.0)) detail::requireDt(dt, "DragBallisticModel");
  if (!x.allFinite()) core::requireFinite(x, "DragBallisticModel: state x");
}

}  // namespace

Eigen::VectorXd DragBallisticModel::propagate(const Eigen::VectorXd& x0, double dt) const {
  validate();
  detail::requireDt(dt, "DragBallisticModel");
  return propagateFixed(toVec6(x0, "DragBallisticModel: state x"), dt);
}

Vec6 DragBallisticModel::propagateFixed(const Vec6& x0, double dt) const {
  checkStep(*this, x0, dt);
  Vec6 x = x0;
  const double h = dt / substeps;
  for (int i = 0; i < substeps; ++i) {
    const Vec6 k1 = derivative(x);
    const Vec6 k2 = derivative(x + 0.5 * h * k1);
    const Vec6 k3 = derivative(x + 0.5 * h * k2);
    const Vec6 k4 = derivative(x + h * k3);
    x += h / 6.0 * (k1 + 2.0 * k2 + 2.0 * k3 + k4);
  }
  return x;
}

Eigen::MatrixXd DragBallisticModel::jacobian(const Eigen::VectorXd& x0, double dt) const {
  validate();
  detail::requireDt(dt, "DragBallisticModel");
  return jacobianFixed(toVec6(x0, "DragBallisticModel: state x"), dt);
}

Mat6 DragBallisticModel::jacobianFixed(const Vec6& x0, double dt) const {
  checkStep(*this, x0, dt);
  Vec6 x = x0;
  // RK4 on (x, S) with Ṡ = J(x) S: each stage's S-part is the derivative of the x-stage.
  Mat6 S = Mat6::Identity();
  const double h = dt / substeps;
  for (int i = 0; i < substeps; ++i) {
    const Vec6 x1 = x;
    const Vec6 k1 = derivative(x1);
    const Mat6 d1 = derivativeJacobian(x1) * S;
    const Vec6 x2 = x + 0.5 * h * k1;
    const Mat6 S2 = S + 0.5 * h * d1;
    const Vec6 k2 = derivative(x2);
    const Mat6 d2 = derivativeJacobian(x2) * S2;
    const Vec6 x3 = x + 0.5 * h * k2;
    const Mat6 S3 = S + 0.5 * h * d2;
    const Vec6 k3 = derivative(x3);
    const Mat6 d3 = derivativeJacobian(x3) * S3;
    const Vec6 x4 = x + h * k3;
    const Mat6 S4 = S + h * d3;
    const Vec6 k4 = derivative(x4);
    const Mat6 d4 = derivativeJacobian(x4) * S4;
    x += h / 6.0 * (k1 + 2.0 * k2 + 2.0 * k3 + k4);
    S += h / 6.0 * (d1 + 2.0 * d2 + 2.0 * d3 + d4);
  }
  return S;
}

Eigen::MatrixXd DragBallisticModel::processNoise(const Eigen::VectorXd& x0, double dt) const {
  validate();
  detail::requireDt(dt, "DragBallisticModel");
  const Vec6 x = toVec6(x0, "DragBallisticModel: linearisation point");
  ContinuousLinearModel lin;
  lin.A = derivativeJacobian(x);
  lin.G = Eigen::MatrixXd::Zero(6, 3);
  lin.G.bottomRows(3).setIdentity();
  lin.Qc = q * Eigen::MatrixXd::Identity(3, 3);
  return discretize(lin, dt).Q;
}

NonlinearTransition DragBallisticModel::transition(double dt, const Eigen::VectorXd& x_lin) const {
  NonlinearTransition tr;
  tr.Q = processNoise(x_lin, dt);  // validates the model, dt and x_lin
  const DragBallisticModel model = *this;
  tr.f = [model, dt](const Eigen::VectorXd& x) { return model.propagate(x, dt); };
  tr.F = [model, dt](const Eigen::VectorXd& x) { return model.jacobian(x, dt); };
  tr.dt = dt;
  return tr;
}

}  // namespace viewline::estimation
