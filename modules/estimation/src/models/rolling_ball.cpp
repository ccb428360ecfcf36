#include "viewline/estimation/models/rolling_ball.h"

#include <Eigen/LU>
#include <cmath>
#include <sstream>

#include "model_checks.h"

namespace viewline::estimation {

namespace {
void requireRotation(const Eigen::Matrix3d& R, const std::string& what) {
  core::requireFinite(R, what);
  if (!((R.transpose() * R - Eigen::Matrix3d::Identity()).cwiseAbs().maxCoeff() < 1e-6) || !(R.determinant() > 0.0)) {
    throw core::InvalidInput(what + " is not a rotation matrix (expected orthonormal with det +1)");
  }
}
}  // namespace

Eigen::Vector2d rollingBallAcceleration(const Eigen::Matrix3d& table_R_world, const Eigen::Vector3d& g_world) {
  requireRotation(table_R_world, "rollingBallAcceleration: table_R_world");
  core::requireFinite(g_world, "rollingBallAcceleration: g_world");
  // a_xy = (5/7) [table_R_world · g_world]_xy: a solid sphere (I = 2/5 m r²) rolling without
  // slipping has m a = m g_t − F, F r = I a / r  ->  a = g_t / (1 + 2/5) = (5/7) g_t.
  return (5.0 / 7.0) * (table_R_world * g_world).head<2>();
}

Eigen::Matrix3d tableRotationInWorld(const Eigen::Matrix3d& c_R_table, const Eigen::Matrix3d& c_R_world) {
  requireRotation(c_R_table, "tableRotationInWorld: c_R_table");
  requireRotation(c_R_world, "tableRotationInWorld: c_R_world");
  return c_R_table.transpose() * c_R_world;
}

void RollingBallModel::validate() const {
  detail::requireNonNegative(sigma_w, "RollingBallModel.sigma_w");
  core::requirePositive(beta, "RollingBallModel.beta");
  core::requirePositive(sigma_v, "RollingBallModel.sigma_v");
  detail::requireNonNegative(ball_radius, "RollingBallModel.ball_radius");
  core::requirePositive(table_side, "RollingBallModel.table_side");
  if (!(table_side > 2.0 * ball_radius)) {
    std::ostringstream s;
    s << "RollingBallModel.table_side = " << table_side << " (expected > 2 ball_radius = " << 2.0 * ball_radius << ")";
    throw core::InvalidInput(s.str());
  }
  if (prediction_steps < 1) {
    std::ostringstream s;
    s << "RollingBallModel.prediction_steps = " << prediction_steps << " (expected >= 1)";
    throw core::InvalidInput(s.str());
  }
}

ContinuousLinearModel RollingBallModel::continuous() const {
  validate();
  ContinuousLinearModel m;
  m.A = Eigen::MatrixXd::Zero(6, 6);
  m.B = Eigen::MatrixXd::Zero(6, 2);
  m.G = Eigen::MatrixXd::Zero(6, 4);
  const double gc = std::sqrt(2.0 * beta) * sigma_w;
  for (int i = 0; i < 2; ++i) {
    const int p = 2 * i, v = 2 * i + 1, w = 4 + i;
    m.A(p, v) = 1.0;      // ṗ = v
    m.A(v, w) = 1.0;      // v̇ = a + w1 + w2
    m.A(w, w) = -beta;    // ẇ2 = −β w2 + sqrt(2β) σw ε
    m.B(v, i) = 1.0;
    m.G(v, i) = 1.0;      // w1 (density σw²)
    m.G(w, 2 + i) = gc;   // ε (unit density)
  }
  m.Qc = Eigen::MatrixXd::Identity(4, 4);
  m.Qc(0, 0) = m.Qc(1, 1) = sigma_w * sigma_w;
  return m;
}

LinearTransition RollingBallModel::transition(double dt, const Eigen::Vector2d& a_xy) const {
  detail::requireDt(dt, "RollingBallModel");
  core::requireFinite(a_xy, "RollingBallModel: input a_xy");
  return discretize(continuous(), dt, a_xy);
}

LinearTransition RollingBallModel::transitionRamp(double dt, const Eigen::Vector2d& a0, const Eigen::Vector2d& a1) const {
  detail::requireDt(dt, "RollingBallModel");
  core::requireFinite(a0, "RollingBallModel: input a0");
  core::requireFinite(a1, "RollingBallModel: input a1");
  return discretizeFirstOrderHold(continuous(), dt, a0, a1);
}

LinearMeasurement RollingBallModel::measurement(const Eigen::Vector2d& y) const {
  validate();
  core::requireFinite(y, "RollingBallModel: measurement y");
  LinearMeasurement m;
  m.C = Eigen::MatrixXd::Zero(2, 6);
  m.C(0, 0) = 1.0;
  m.C(1, 2) = 1.0;
  m.y = y;
  m.R = sigma_v * sigma_v * Eigen::MatrixXd::Identity(2, 2);
  return m;
}

double RollingBallModel::positionLimit() const {
  validate();
  return 0.5 * table_side - ball_radius;
}

bool RollingBallModel::clamp(Eigen::Ref<Eigen::VectorXd> x) const {
  core::requireSize(x, 6, 1, "RollingBallModel::clamp: state");
  const double lim = positionLimit();
  bool clamped = false;
  for (int i = 0; i < 2; ++i) {
    double& p = x[2 * i];
    if (std::abs(p) > lim) {  // inelastic contact with the border
      p = std::copysign(lim, p);
      x[2 * i + 1] = 0.0;
      clamped = true;
    }
  }
  return clamped;
}

bool RollingBallModel::clampEstimate(StateEstimate& s) const {
  Eigen::VectorXd x = s.x();
  if (!clamp(x)) return false;
  s.setMean(x);
  return true;
}

void RollingBallModel::predictClamped(StateEstimate& s, double dt, const Eigen::Vector2d& a_xy) const {
  predict(s, transition(dt, a_xy));
  clampEstimate(s);
}

std::vector<Eigen::Vector2d> RollingBallModel::predictPositions(const Eigen::VectorXd& x0, double dt,
                                                                const Eigen::Vector2d& a_xy, int steps) const {
  return predictPositions(x0, transition(dt, a_xy), steps);
}

std::vector<Eigen::Vector2d> RollingBallModel::predictPositions(const Eigen::VectorXd& x0, const LinearTransition& tr,
                                                                int steps) const {
  core::requireSize(x0, 6, 1, "RollingBallModel::predictPositions: state");
  core::requireFinite(x0, "RollingBallModel::predictPositions: state");
  core::requireSize(tr.Phi, 6, 6, "RollingBallModel::predictPositions: Phi");
  const int n = steps < 1 ? prediction_steps : steps;
  const Eigen::VectorXd gu = tr.Gamma * tr.u;
  Eigen::VectorXd x = x0;
  std::vector<Eigen::Vector2d> out;
  out.reserve(static_cast<std::size_t>(n));
  for (int k = 0; k < n; ++k) {
    x = tr.Phi * x + gu;
    clamp(x);
    out.emplace_back(x[0], x[2]);
  }
  return out;
}

StationaryFilter RollingBallModel::stationaryFilter(double dt) const {
  const LinearTransition tr = transition(dt, Eigen::Vector2d::Zero());
  const LinearMeasurement m = measurement(Eigen::Vector2d::Zero());
  return solveDare(tr.Phi, m.C, tr.Q, m.R);
}

Eigen::VectorXd RollingBallModel::stationaryStep(const StationaryFilter& sf, const LinearTransition& tr,
                                                 const Eigen::VectorXd& x, const Eigen::Vector2d& y) const {
  core::requireSize(sf.Kf, 6, 2, "RollingBallModel::stationaryStep: gain Kf");
  core::requireSize(tr.Phi, 6, 6, "RollingBallModel::stationaryStep: Phi");
  core::requireSize(x, 6, 1, "RollingBallModel::stationaryStep: state");
  core::requireFinite(x, "RollingBallModel::stationaryStep: state");
  core::requireFinite(y, "RollingBallModel::stationaryStep: measurement y");
  Eigen::VectorXd xp = tr.Phi * x;
  if (tr.u.size() > 0) xp += tr.Gamma * tr.u;
  const Eigen::Vector2d innovation(y[0] - xp[0], y[1] - xp[2]);
  Eigen::VectorXd xf = xp + sf.Kf * innovation;
  clamp(xf);
  return xf;
}

}  // namespace viewline::estimation
