#include "viewline/estimation/models/ballistic_drag.h"

#include <cmath>
#include <sstream>
#include <unsupported/Eigen/MatrixFunctions>

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

namespace {
// ṗ = v, v̇ = g_vec − k |v| v, with g_vec given (the propagations compute it once per call).
Vec6 derivativeWith(const Vec6& x, const Eigen::Vector3d& g_vec, double k) {
  const Eigen::Vector3d v = x.tail<3>();
  Vec6 d;
  d << v, g_vec - k * v.norm() * v;
  return d;
}
}  // namespace

Vec6 DragBallisticModel::derivative(const Vec6& x) const { return derivativeWith(x, gravity(), k); }

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
  const Eigen::Vector3d gv = gravity();  // once per call (derivative() normalises `up` every time)
  Vec6 x = x0;
  const double h = dt / substeps;
  for (int i = 0; i < substeps; ++i) {
    const Vec6 k1 = derivativeWith(x, gv, k);
    const Vec6 k2 = derivativeWith(x + 0.5 * h * k1, gv, k);
    const Vec6 k3 = derivativeWith(x + 0.5 * h * k2, gv, k);
    const Vec6 k4 = derivativeWith(x + h * k3, gv, k);
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
  Mat6 S;
  propagateWithJacobianFixed(x0, dt, S);
  return S;
}

namespace {

// J(x) S for J = [0 I; 0 D(v)] (derivativeJacobian), without the products by J's zeros and
// ones: the top rows are S's bottom rows, the bottom rows D S_bottom, each entry summed over
// the same terms in the same order as the full 6x6 product, which adds only zero products
// before them. Entries that are not zero are therefore the same doubles; a zero may differ
// in sign, and only ever reaches S through additions to S, whose zeros are +0 (S starts at the
// identity and is only added to), so S itself is the same to the bit (estimation_models_test
// DragBallisticModel.OnePassJacobianIsTheFullProducts).
Mat6 derivativeJacobianTimes(const Vec6& x, double k, const Mat6& S) {
  const Eigen::Vector3d v = x.tail<3>();
  const double speed = v.norm();
  Mat6 d;
  d.topRows<3>() = S.bottomRows<3>();
  if (speed > 0.0) {
    const Eigen::Matrix3d D = -k * (speed * Eigen::Matrix3d::Identity() + v * v.transpose() / speed);
    for (int j = 0; j < 6; ++j)
      for (int i = 0; i < 3; ++i) d(3 + i, j) = D(i, 0) * S(3, j) + D(i, 1) * S(4, j) + D(i, 2) * S(5, j);
  } else {
    d.bottomRows<3>().setZero();
  }
  return d;
}

}  // namespace

Vec6 DragBallisticModel::propagateWithJacobianFixed(const Vec6& x0, double dt, Mat6& S) const {
  checkStep(*this, x0, dt);
  const Eigen::Vector3d gv = gravity();
  Vec6 x = x0;
  // RK4 on (x, S) with Ṡ = J(x) S: each stage's S-part is the derivative of the x-stage. The
  // x-part is propagateFixed's arithmetic, operation for operation.
  S = Mat6::Identity();
  const double h = dt / substeps;
  for (int i = 0; i < substeps; ++i) {
    const Vec6 x1 = x;
    const Vec6 k1 = derivativeWith(x1, gv, k);
    const Mat6 d1 = derivativeJacobianTimes(x1, k, S);
    const Vec6 x2 = x + 0.5 * h * k1;
    const Mat6 S2 = S + 0.5 * h * d1;
    const Vec6 k2 = derivativeWith(x2, gv, k);
    const Mat6 d2 = derivativeJacobianTimes(x2, k, S2);
    const Vec6 x3 = x + 0.5 * h * k2;
    const Mat6 S3 = S + 0.5 * h * d2;
    const Vec6 k3 = derivativeWith(x3, gv, k);
    const Mat6 d3 = derivativeJacobianTimes(x3, k, S3);
    const Vec6 x4 = x + h * k3;
    const Mat6 S4 = S + h * d3;
    const Vec6 k4 = derivativeWith(x4, gv, k);
    const Mat6 d4 = derivativeJacobianTimes(x4, k, S4);
    x += h / 6.0 * (k1 + 2.0 * k2 + 2.0 * k3 + k4);
    S += h / 6.0 * (d1 + 2.0 * d2 + 2.0 * d3 + d4);
  }
  return x;
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

Mat6 DragBallisticModel::processNoiseFixed(const Vec6& x, double dt) const {
  checkStep(*this, x, dt);  // the checks of processNoise (and discretize: dt > 0, q >= 0) first
  // discretize() (discretization.cpp) with n = 6, G = [0; I], Qc = q I, on fixed-size storage:
  // Eigen picks the same product kernels (and blocking) for these sizes, so the bits are those of
  // the dynamic path (estimation_test DragBallistic.FixedSizeProcessNoiseIsTheDynamicOne).
  using Mat12 = Eigen::Matrix<double, 12, 12>;
  const Mat6 A = derivativeJacobian(x);
  if (!A.allFinite()) core::requireFinite(A, "continuous model A");
  Eigen::Matrix<double, 6, 3> G = Eigen::Matrix<double, 6, 3>::Zero();
  G.bottomRows<3>().setIdentity();
  const Eigen::Matrix3d Qc = q * Eigen::Matrix3d::Identity();
  Mat12 M = Mat12::Zero();
  M.topLeftCorner<6, 6>() = -A * dt;
  M.topRightCorner<6, 6>() = G * Qc * G.transpose() * dt;
  M.bottomRightCorner<6, 6>() = A.transpose() * dt;
  const Mat12 E = M.exp();
  const Mat6 Phi = E.bottomRightCorner<6, 6>().transpose();
  Mat6 Q = Phi * E.topRightCorner<6, 6>();
  Q = 0.5 * (Q + Q.transpose()).eval();  // core::symmetrize
  return Q;
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
