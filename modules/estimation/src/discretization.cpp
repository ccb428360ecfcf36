#include "viewline/estimation/discretization.h"

#include <unsupported/Eigen/MatrixFunctions>

#include "viewline/core/checks.h"

namespace viewline::estimation {

LinearTransition discretize(const ContinuousLinearModel& model, double dt, const Eigen::VectorXd& u) {
  core::requirePositive(dt, "discretize: dt");
  const Eigen::Index n = model.A.rows();
  core::requireSize(model.A, n, n, "continuous model A");
  core::requireFinite(model.A, "continuous model A");
  core::requireSize(model.G, n, model.G.cols(), "continuous model G");
  core::requireFinite(model.G, "continuous model G");
  core::requireSize(model.Qc, model.G.cols(), model.G.cols(), "continuous model Qc");
  core::requireSymmetricPositiveSemiDefinite(model.Qc, "continuous model Qc");
  const Eigen::Index p = model.B.cols();
  if (p > 0) {
    core::requireSize(model.B, n, p, "continuous model B");
    core::requireFinite(model.B, "continuous model B");
    core::requireSize(u, p, 1, "input u");
    core::requireFinite(u, "input u");
  }

  Eigen::MatrixXd M = Eigen::MatrixXd::Zero(2 * n, 2 * n);
  M.topLeftCorner(n, n) = -model.A * dt;
  M.topRightCorner(n, n) = model.G * model.Qc * model.G.transpose() * dt;
  M.bottomRightCorner(n, n) = model.A.transpose() * dt;
  const Eigen::MatrixXd E = M.exp();

  LinearTransition tr;
  tr.Phi = E.bottomRightCorner(n, n).transpose();
  tr.Q = tr.Phi * E.topRightCorner(n, n);
  core::symmetrize(tr.Q);
  tr.dt = dt;
  if (p > 0) {
    Eigen::MatrixXd Mb = Eigen::MatrixXd::Zero(n + p, n + p);
    Mb.topLeftCorner(n, n) = model.A * dt;
    Mb.topRightCorner(n, p) = model.B * dt;
    tr.Gamma = Mb.exp().topRightCorner(n, p);
    tr.u = u;
  }
  return tr;
}

LinearTransition discretizeFirstOrderHold(const ContinuousLinearModel& model, double dt, const Eigen::VectorXd& u0,
                                          const Eigen::VectorXd& u1) {
  const Eigen::Index p = model.B.cols();
  if (p == 0) throw core::InvalidInput("discretizeFirstOrderHold: the model has no input (B has no columns)");
  core::requireSize(u1, p, 1, "input u1");
  core::requireFinite(u1, "input u1");
  LinearTransition tr = discretize(model, dt, u0);  // Φ, Q and the checks of A, B, G, Qc, u0
  const Eigen::Index n = model.A.rows();
  Eigen::MatrixXd M = Eigen::MatrixXd::Zero(n + 2 * p, n + 2 * p);
  M.topLeftCorner(n, n) = model.A * dt;
  M.block(0, n, n, p) = model.B * dt;
  M.block(n, n + p, p, p) = Eigen::MatrixXd::Identity(p, p) * dt;
  const Eigen::MatrixXd E = M.exp();
  const Eigen::MatrixXd Gamma = E.block(0, n, n, p);
  const Eigen::MatrixXd Lambda_dt = E.block(0, n + p, n, p) / dt;  // Λ / dt
  tr.Gamma.resize(n, 2 * p);
  tr.Gamma << Gamma - Lambda_dt, Lambda_dt;
  tr.u.resize(2 * p);
  tr.u << u0, u1;
  return tr;
}

}  // namespace viewline::estimation
