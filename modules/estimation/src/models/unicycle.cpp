#include "viewline/estimation/models/unicycle.h"

#include <algorithm>
#include <cmath>

#include "model_checks.h"

namespace viewline::estimation {

double wrapAngle(double a) {
  core::requireFinite(a, "wrapAngle: angle");
  // std::remainder gives [−π, π]; map −π to π so the range is (−π, π].
  double w = std::remainder(a, 2.0 * M_PI);
  if (w <= -M_PI) w += 2.0 * M_PI;
  return w;
}

void UnicycleModel::validate() const {
  detail::requireNonNegative(q_v, "UnicycleModel.q_v");
  detail::requireNonNegative(q_w, "UnicycleModel.q_w");
  detail::requireNonNegative(input_sigma_v, "UnicycleModel.input_sigma_v");
  detail::requireNonNegative(input_sigma_w, "UnicycleModel.input_sigma_w");
  core::requirePositive(input_period, "UnicycleModel.input_period");
}

namespace {
void checkState(const Eigen::VectorXd& x) {
  core::requireSize(x, 5, 1, "UnicycleModel: state x");
  core::requireFinite(x, "UnicycleModel: state x");
}
}  // namespace

Eigen::VectorXd UnicycleModel::propagate(const Eigen::VectorXd& x, double dt) const {
  detail::requireDt(dt, "UnicycleModel");
  checkState(x);
  const double phi = x[2] + 0.5 * x[4] * dt;  // heading at mid-step
  Eigen::Matrix<double, 5, 1> y;
  y << x[0] + x[3] * dt * std::cos(phi), x[1] + x[3] * dt * std::sin(phi), x[2] + x[4] * dt, x[3], x[4];
  return y;
}

Eigen::MatrixXd UnicycleModel::jacobian(const Eigen::VectorXd& x, double dt) const {
  detail::requireDt(dt, "UnicycleModel");
  checkState(x);
  const double phi = x[2] + 0.5 * x[4] * dt;
  const double c = std::cos(phi), s = std::sin(phi), v = x[3];
  Eigen::MatrixXd F = Eigen::MatrixXd::Identity(5, 5);
  F(0, 2) = -v * dt * s;
  F(0, 3) = dt * c;
  F(0, 4) = -0.5 * v * dt * dt * s;
  F(1, 2) = v * dt * c;
  F(1, 3) = dt * s;
  F(1, 4) = 0.5 * v * dt * dt * c;
  F(2, 4) = dt;
  return F;
}

namespace {
Eigen::MatrixXd randomWalkNoise(double q_v, double q_w, double dt) {
  Eigen::MatrixXd Q = Eigen::MatrixXd::Zero(5, 5);
  Q(3, 3) = q_v * dt;
  Q(4, 4) = q_w * dt;
  return Q;
}
}  // namespace

Eigen::MatrixXd UnicycleModel::processNoise(double dt) const {
  validate();
  detail::requireDt(dt, "UnicycleModel");
  if (hasInputNoise())
    throw core::InvalidInput("UnicycleModel.processNoise: held input noise (input_sigma_v/w) depends on the state: "
                             "pass the state to linearise at");
  return randomWalkNoise(q_v, q_w, dt);
}

Eigen::MatrixXd UnicycleModel::processNoise(const Eigen::VectorXd& x, double dt) const {
  validate();
  detail::requireDt(dt, "UnicycleModel");
  checkState(x);
  Eigen::MatrixXd Q = randomWalkNoise(q_v, q_w, dt);
  if (!hasInputNoise()) return Q;
  // G = ∂(x⁺, y⁺, θ⁺)/∂(v, ω): the v and ω columns of F (header), Σ_ε averaged over dt / T periods.
  const Eigen::MatrixXd F = jacobian(x, dt);
  const Eigen::Matrix<double, 3, 2> G = F.block<3, 2>(0, 3);
  const double share = std::min(1.0, input_period / dt);
  const Eigen::Vector2d var(input_sigma_v * input_sigma_v * share, input_sigma_w * input_sigma_w * share);
  Q.topLeftCorner<3, 3>() += G * var.asDiagonal() * G.transpose();
  return Q;
}

NonlinearTransition UnicycleModel::transition(double dt) const {
  NonlinearTransition tr;
  tr.Q = processNoise(dt);
  const UnicycleModel model = *this;
  tr.f = [model, dt](const Eigen::VectorXd& x) { return model.propagate(x, dt); };
  tr.F = [model, dt](const Eigen::VectorXd& x) { return model.jacobian(x, dt); };
  tr.dt = dt;
  tr.normalize = [](const Eigen::VectorXd& x) {
    Eigen::Matrix<double, 5, 1> y = x;
    y[2] = wrapAngle(y[2]);
    return Eigen::VectorXd(y);
  };
  return tr;
}

NonlinearTransition UnicycleModel::transition(double dt, const Eigen::VectorXd& x) const {
  UnicycleModel random_walks = *this;
  random_walks.input_sigma_v = random_walks.input_sigma_w = 0.0;
  NonlinearTransition tr = random_walks.transition(dt);
  tr.Q = processNoise(x, dt);
  return tr;
}

NonlinearMeasurement UnicycleModel::positionMeasurement(const Eigen::Vector2d& y, double sigma) {
  core::requireFinite(y, "UnicycleModel: measurement y");
  core::requirePositive(sigma, "UnicycleModel: measurement sigma");
  NonlinearMeasurement m;
  m.h = [](const Eigen::VectorXd& x) { return Eigen::VectorXd(x.head<2>()); };
  m.H = [](const Eigen::VectorXd&) {
    Eigen::MatrixXd H = Eigen::MatrixXd::Zero(2, 5);
    H(0, 0) = H(1, 1) = 1.0;
    return H;
  };
  m.y = y;
  m.R = sigma * sigma * Eigen::MatrixXd::Identity(2, 2);
  return m;
}

Eigen::VectorXd UnicycleModel::difference(const Eigen::VectorXd& a, const Eigen::VectorXd& b) {
  core::requireSize(a, 5, 1, "UnicycleModel::difference: a");
  core::requireSize(b, 5, 1, "UnicycleModel::difference: b");
  Eigen::VectorXd d = a - b;
  d[2] = wrapAngle(d[2]);
  return d;
}

}  // namespace viewline::estimation
