#include "viewline/estimation/nonlinear.h"

#include <Eigen/Cholesky>
#include <cmath>

#include "viewline/core/checks.h"
#include "viewline/estimation/square_root.h"

namespace viewline::estimation {

namespace {

void validate(const StateEstimate& s, const NonlinearTransition& tr, bool need_jacobian) {
  if (s.dim() == 0) throw core::InvalidInput("filter state is empty (initialise it first)");
  if (!tr.f) throw core::InvalidInput("nonlinear transition has no f");
  if (need_jacobian && !tr.F) throw core::InvalidInput("nonlinear transition has no Jacobian F (EKF)");
  core::requireSize(tr.Q, s.dim(), s.dim(), "process noise Q");
  core::requireSymmetricPositiveSemiDefinite(tr.Q, "process noise Q");
  core::requireFinite(tr.dt, "transition dt");
  if (tr.dt < 0.0) throw core::InvalidInput("transition dt is negative (expected >= 0)");
}

void validate(const StateEstimate& s, const NonlinearMeasurement& m, bool need_jacobian) {
  if (s.dim() == 0) throw core::InvalidInput("filter state is empty (initialise it first)");
  if (!m.h) throw core::InvalidInput("nonlinear measurement has no h");
  if (need_jacobian && !m.H) throw core::InvalidInput("nonlinear measurement has no Jacobian H (EKF)");
  core::requireFinite(m.y, "measurement y");
  core::requireSize(m.R, m.y.size(), m.y.size(), "measurement noise R");
  core::requireSymmetricPositiveDefinite(m.R, "measurement noise R");
}

Eigen::VectorXd residualOf(const NonlinearMeasurement& m, const Eigen::VectorXd& y, const Eigen::VectorXd& yhat) {
  return m.residual ? m.residual(y, yhat) : Eigen::VectorXd(y - yhat);
}

struct Sigma {
  Eigen::MatrixXd X;
  Eigen::VectorXd wm, wc;
};

Sigma sigmaPoints(const StateEstimate& s, const UnscentedParams& p) {
  const Eigen::Index n = s.dim();
  const double nd = static_cast<double>(n);
  const double lambda = p.alpha * p.alpha * (nd + p.kappa) - nd;
  const double gamma = std::sqrt(nd + lambda);
  Sigma sg;
  sg.X.resize(n, 2 * n + 1);
  sg.X.col(0) = s.x();
  for (Eigen::Index i = 0; i < n; ++i) {
    sg.X.col(1 + i) = s.x() + gamma * s.sqrtP().col(i);
    sg.X.col(1 + n + i) = s.x() - gamma * s.sqrtP().col(i);
  }
  sg.wm = Eigen::VectorXd::Constant(2 * n + 1, 0.5 / (nd + lambda));
  sg.wc = sg.wm;
  sg.wm[0] = lambda / (nd + lambda);
  sg.wc[0] = sg.wm[0] + (1.0 - p.alpha * p.alpha + p.beta);
  return sg;
}

}  // namespace

void ekfPredict(StateEstimate& s, const NonlinearTransition& tr) {
  validate(s, tr, true);
  const Eigen::Index n = s.dim();
  Eigen::VectorXd x = tr.f(s.x());
  const Eigen::MatrixXd F = tr.F(s.x());
  core::requireSize(F, n, n, "Jacobian F");
  if (tr.normalize) x = tr.normalize(x);
  Eigen::MatrixXd pre(n, 2 * n);
  pre.leftCols(n) = F * s.sqrtP();
  pre.rightCols(n) = psdSqrt(tr.Q, "process noise Q");
  Eigen::MatrixXd L = lowerTriangularize(pre);
  if (!x.allFinite() || !L.allFinite()) throw core::NumericalError("EKF predict produced non-finite values");
  s.assign(std::move(x), std::move(L), s.t() + tr.dt);
}

UpdateReport ekfUpdate(StateEstimate& s, const NonlinearMeasurement& m) {
  validate(s, m, true);
  if (m.y.size() == 0) return UpdateReport{};
  const Eigen::VectorXd yhat = m.h(s.x());
  core::requireSize(yhat, m.y.size(), 1, "predicted measurement h(x)");
  const Eigen::MatrixXd H = m.H(s.x());
  // Linearised measurement in innovation form: y_lin = H x̂ + (y ⊖ h(x̂)), so y_lin − H x̂ is the innovation.
  LinearMeasurement lin;
  lin.C = H;
  lin.y = H * s.x() + residualOf(m, m.y, yhat);
  lin.R = m.R;
  return update(s, lin);
}

void ukfPredict(StateEstimate& s, const NonlinearTransition& tr, const UnscentedParams& p) {
  validate(s, tr, false);
  const Eigen::Index n = s.dim();
  const Sigma sg = sigmaPoints(s, p);
  Eigen::MatrixXd Y(n, sg.X.cols());
  for (Eigen::Index i = 0; i < sg.X.cols(); ++i) Y.col(i) = tr.f(sg.X.col(i));
  Eigen::VectorXd x = Y * sg.wm;
  Eigen::MatrixXd P = tr.Q;
  for (Eigen::Index i = 0; i < Y.cols(); ++i) {
    const Eigen::VectorXd d = Y.col(i) - x;
    P += sg.wc[i] * d * d.transpose();
  }
  core::symmetrize(P);
  if (tr.normalize) x = tr.normalize(x);
  Eigen::LLT<Eigen::MatrixXd> llt(P);
  if (!x.allFinite() || llt.info() != Eigen::Success)
    throw core::NumericalError("UKF predict: covariance lost positive definiteness");
  s.assign(std::move(x), llt.matrixL(), s.t() + tr.dt);
}

UpdateReport ukfUpdate(StateEstimate& s, const NonlinearMeasurement& m, const UnscentedParams& p) {
  validate(s, m, false);
  UpdateReport rep;
  const Eigen::Index rows = m.y.size();
  if (rows == 0) return rep;
  const Sigma sg = sigmaPoints(s, p);
  const Eigen::Index k = sg.X.cols();
  Eigen::MatrixXd Y(rows, k);
  for (Eigen::Index i = 0; i < k; ++i) Y.col(i) = m.h(sg.X.col(i));
  // Mean of the predicted measurement; residuals relative to the central point handle wrapping.
  const Eigen::VectorXd y0 = Y.col(0);
  Eigen::VectorXd dmean = Eigen::VectorXd::Zero(rows);
  for (Eigen::Index i = 0; i < k; ++i) dmean += sg.wm[i] * residualOf(m, Y.col(i), y0);
  const Eigen::VectorXd ymean = y0 + dmean;
  Eigen::MatrixXd S = m.R;
  Eigen::MatrixXd Pxy = Eigen::MatrixXd::Zero(s.dim(), rows);
  for (Eigen::Index i = 0; i < k; ++i) {
    const Eigen::VectorXd dy = residualOf(m, Y.col(i), ymean);
    const Eigen::VectorXd dx = sg.X.col(i) - s.x();
    S += sg.wc[i] * dy * dy.transpose();
    Pxy += sg.wc[i] * dx * dy.transpose();
  }
  core::symmetrize(S);
  const Eigen::LLT<Eigen::MatrixXd> sllt(S);
  if (sllt.info() != Eigen::Success) throw core::NumericalError("UKF update: innovation covariance not positive definite");
  rep.rows = rows;
  rep.S = S;
  rep.innovation = residualOf(m, m.y, ymean);
  rep.nis = rep.innovation.dot(sllt.solve(rep.innovation));
  const Eigen::MatrixXd K = sllt.solve(Pxy.transpose()).transpose();
  Eigen::VectorXd x = s.x() + K * rep.innovation;
  Eigen::MatrixXd P = s.P() - K * S * K.transpose();
  core::symmetrize(P);
  Eigen::LLT<Eigen::MatrixXd> llt(P);
  if (!x.allFinite() || llt.info() != Eigen::Success)
    throw core::NumericalError("UKF update: covariance lost positive definiteness");
  s.assign(std::move(x), llt.matrixL(), s.t());
  return rep;
}

Eigen::MatrixXd numericalJacobian(const VectorFn& f, const Eigen::VectorXd& x, double rel_step) {
  const Eigen::VectorXd f0 = f(x);
  Eigen::MatrixXd J(f0.size(), x.size());
  for (Eigen::Index j = 0; j < x.size(); ++j) {
    const double h = rel_step * std::max(1.0, std::abs(x[j]));
    Eigen::VectorXd xp = x, xm = x;
    xp[j] += h;
    xm[j] -= h;
    J.col(j) = (f(xp) - f(xm)) / (2.0 * h);
  }
  return J;
}

}  // namespace viewline::estimation
