#include "viewline/estimation/kalman_filter.h"

#include <Eigen/Cholesky>

#include "viewline/core/checks.h"
#include "viewline/estimation/square_root.h"

namespace viewline::estimation {

namespace {

void requireState(const StateEstimate& s) {
  if (s.dim() == 0) throw core::InvalidInput("filter state is empty (initialise it with a mean and covariance)");
}

}  // namespace

void validateTransition(const StateEstimate& s, const LinearTransition& tr) {
  requireState(s);
  const Eigen::Index n = s.dim();
  core::requireSize(tr.Phi, n, n, "transition Phi");
  core::requireFinite(tr.Phi, "transition Phi");
  core::requireSize(tr.Q, n, n, "process noise Q (R1)");
  core::requireSymmetricPositiveSemiDefinite(tr.Q, "process noise Q (R1)");
  core::requireFinite(tr.dt, "transition dt");
  if (tr.dt < 0.0) throw core::InvalidInput("transition dt is negative (expected >= 0)");
  if (tr.Gamma.size() > 0 || tr.u.size() > 0) {
    core::requireSize(tr.Gamma, n, tr.u.size(), "input matrix Gamma");
    core::requireFinite(tr.Gamma, "input matrix Gamma");
    core::requireFinite(tr.u, "input u");
  }
}

void validateMeasurement(const StateEstimate& s, const LinearMeasurement& m) {
  requireState(s);
  const Eigen::Index n = s.dim();
  const Eigen::Index rows = m.y.size();
  core::requireSize(m.C, rows, n, "measurement matrix C");
  core::requireFinite(m.C, "measurement matrix C");
  core::requireFinite(m.y, "measurement y");
  core::requireSize(m.R, rows, rows, "measurement noise R (R2)");
  core::requireSymmetricPositiveDefinite(m.R, "measurement noise R (R2)");
}

void predict(StateEstimate& s, const LinearTransition& tr) {
  validateTransition(s, tr);
  const Eigen::Index n = s.dim();
  Eigen::VectorXd x = tr.Phi * s.x();
  if (tr.u.size() > 0) x += tr.Gamma * tr.u;
  Eigen::MatrixXd pre(n, 2 * n);
  pre.leftCols(n) = tr.Phi * s.sqrtP();
  pre.rightCols(n) = psdSqrt(tr.Q, "process noise Q (R1)");
  Eigen::MatrixXd L = lowerTriangularize(pre);
  if (!x.allFinite() || !L.allFinite()) throw core::NumericalError("predict produced non-finite values");
  s.assign(std::move(x), std::move(L), s.t() + tr.dt);
}

namespace {

// The shared array step. With phi == nullptr this is the filter-form update (Φ = I, R1 = 0, R12 = 0).
UpdateReport arrayStep(StateEstimate& s, const LinearTransition* tr, const LinearMeasurement& m,
                       const Eigen::MatrixXd* R12) {
  const Eigen::Index n = s.dim();
  const Eigen::Index rows = m.y.size();
  UpdateReport rep;
  rep.rows = rows;

  // Joint noise factor G = [Gv; Ge] of [[R1, R12], [R12ᵀ, R2]].
  Eigen::MatrixXd Gv, Ge;
  if (tr != nullptr) {
    Eigen::MatrixXd joint(n + rows, n + rows);
    joint.topLeftCorner(n, n) = tr->Q;
    joint.topRightCorner(n, rows) = *R12;
    joint.bottomLeftCorner(rows, n) = R12->transpose();
    joint.bottomRightCorner(rows, rows) = m.R;
    const Eigen::MatrixXd G = psdSqrt(joint, "joint noise covariance [[R1, R12], [R12', R2]]");
    Gv = G.topRows(n);
    Ge = G.bottomRows(rows);
  } else {
    Ge = psdSqrt(m.R, "measurement noise R (R2)");
    Gv = Eigen::MatrixXd::Zero(n, rows);
  }

  const Eigen::MatrixXd& L = s.sqrtP();
  const Eigen::Index cols = n + Ge.cols();
  Eigen::MatrixXd pre(rows + n, cols);
  pre.topLeftCorner(rows, n) = m.C * L;
  pre.topRightCorner(rows, Ge.cols()) = Ge;
  pre.bottomLeftCorner(n, n) = (tr != nullptr) ? Eigen::MatrixXd(tr->Phi * L) : L;
  pre.bottomRightCorner(n, Gv.cols()) = Gv;
  const Eigen::MatrixXd post = lowerTriangularize(pre);

  const Eigen::MatrixXd sqrtS = post.topLeftCorner(rows, rows);
  const Eigen::MatrixXd Kbar = post.bottomLeftCorner(n, rows);
  Eigen::MatrixXd Lplus = post.bottomRightCorner(n, n);

  rep.innovation = m.y - m.C * s.x();
  rep.S = sqrtS * sqrtS.transpose();
  if (rows > 0 && (sqrtS.diagonal().array() <= 0.0).any()) {
    throw core::NumericalError("innovation covariance R2 + C P C' is singular");
  }
  // w = S^-½ d (triangular solve): NIS = |w|², correction = K̄ w.
  const Eigen::VectorXd w = sqrtS.triangularView<Eigen::Lower>().solve(rep.innovation);
  rep.nis = w.squaredNorm();

  Eigen::VectorXd x = (tr != nullptr) ? Eigen::VectorXd(tr->Phi * s.x()) : s.x();
  if (tr != nullptr && tr->u.size() > 0) x += tr->Gamma * tr->u;
  if (rows > 0) x += Kbar * w;
  if (!x.allFinite() || !Lplus.allFinite()) throw core::NumericalError("update produced non-finite values");
  const double t = s.t() + ((tr != nullptr) ? tr->dt : 0.0);
  s.assign(std::move(x), std::move(Lplus), t);
  return rep;
}

}  // namespace

UpdateReport update(StateEstimate& s, const LinearMeasurement& m) {
  validateMeasurement(s, m);
  if (m.y.size() == 0) return UpdateReport{};
  return arrayStep(s, nullptr, m, nullptr);
}

UpdateReport predictorStep(StateEstimate& s, const LinearTransition& tr, const LinearMeasurement& m,
                           const Eigen::MatrixXd& R12) {
  validateTransition(s, tr);
  validateMeasurement(s, m);
  core::requireSize(R12, s.dim(), m.y.size(), "cross-covariance R12");
  core::requireFinite(R12, "cross-covariance R12");
  return arrayStep(s, &tr, m, &R12);
}

Eigen::MatrixXd innovationCovariance(const StateEstimate& s, const Eigen::MatrixXd& C,
                                     const Eigen::MatrixXd& R) {
  core::requireSize(C, R.rows(), s.dim(), "measurement matrix C");
  const Eigen::MatrixXd CL = C * s.sqrtP();
  return R + CL * CL.transpose();
}

}  // namespace viewline::estimation
