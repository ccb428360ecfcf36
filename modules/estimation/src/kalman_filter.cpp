#include "viewline/estimation/kalman_filter.h"

#include <Eigen/Cholesky>
#include <algorithm>
#include <cmath>

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

// ---------------------------------------------------------------- hot path
//
// predict/update/predictorStep validate exactly what validateTransition and
// validateMeasurement validate (same checks, same messages), but build a
// message only on failure, validate a covariance and factor it with one
// Cholesky, and reuse the factor of a covariance that is bit-for-bit the one
// validated and factored by the previous call of this thread (the common case:
// one model transition and one R per camera reused at every step). The
// pre-arrays live in thread-local buffers and are triangularised in place.

namespace {

void checkSize(const Eigen::MatrixXd& m, Eigen::Index rows, Eigen::Index cols, const char* what) {
  if (m.rows() != rows || m.cols() != cols) core::requireSize(m, rows, cols, what);
}

void checkFinite(const Eigen::MatrixXd& m, const char* what) {
  if (!m.allFinite()) core::requireFinite(m, what);
}

// Same rule as core::isSymmetric (|m − mᵀ| <= 1e-9 max(1, max|m|)), plus finiteness, in one pass.
bool finiteAndSymmetric(const Eigen::MatrixXd& m) {
  const Eigen::Index n = m.rows();
  double scale = 1.0, asym = 0.0;
  for (Eigen::Index j = 0; j < n; ++j) {
    for (Eigen::Index i = 0; i < n; ++i) {
      const double a = m(i, j);
      if (!std::isfinite(a)) return false;
      scale = std::max(scale, std::abs(a));
      if (i > j) asym = std::max(asym, std::abs(a - m(j, i)));
    }
  }
  return asym <= 1e-9 * scale;
}

// A validated covariance and its factor, remembered per thread and per role.
struct FactorCache {
  Eigen::MatrixXd M;
  Eigen::MatrixXd G;
  bool valid = false;
};

bool sameContent(const Eigen::MatrixXd& a, const Eigen::MatrixXd& b) {
  return a.rows() == b.rows() && a.cols() == b.cols() &&
         std::equal(a.data(), a.data() + a.size(), b.data());
}

// Square-root factor G (G Gᵀ = M) of a covariance that must be square, finite, symmetric and
// positive definite (`definite`) or semi-definite; throws core::InvalidInput (same messages as
// core::requireSymmetricPositive(Semi)Definite) otherwise.
const Eigen::MatrixXd& validatedFactor(FactorCache& cache, const Eigen::MatrixXd& M, const char* what,
                                       bool definite) {
  if (cache.valid && sameContent(cache.M, M)) return cache.G;
  cache.valid = false;
  if (M.rows() != M.cols() || !finiteAndSymmetric(M)) {
    if (definite) core::requireSymmetricPositiveDefinite(M, what);
    core::requireSymmetricPositiveSemiDefinite(M, what);
  }
  cache.G = M;
  Eigen::LLT<Eigen::Ref<Eigen::MatrixXd>> llt(cache.G);  // in place
  if (llt.info() == Eigen::Success) {
    cache.G.triangularView<Eigen::StrictlyUpper>().setZero();
  } else {
    if (definite) core::requireSymmetricPositiveDefinite(M, what);  // throws: not positive definite
    cache.G = psdSqrt(M, what);                                      // checks semi-definiteness
  }
  cache.M = M;
  cache.valid = true;
  return cache.G;
}

struct Workspace {
  FactorCache q, r, joint;
  RowMatrixXd pre;
  Eigen::MatrixXd phiL;
};

Workspace& workspace() {
  thread_local Workspace ws;
  return ws;
}

// The checks of validateTransition, in the same order; returns the factor of Q.
const Eigen::MatrixXd& checkTransition(Workspace& ws, const StateEstimate& s, const LinearTransition& tr) {
  requireState(s);
  const Eigen::Index n = s.dim();
  checkSize(tr.Phi, n, n, "transition Phi");
  checkFinite(tr.Phi, "transition Phi");
  checkSize(tr.Q, n, n, "process noise Q (R1)");
  const Eigen::MatrixXd& Gq = validatedFactor(ws.q, tr.Q, "process noise Q (R1)", false);
  if (!std::isfinite(tr.dt)) core::requireFinite(tr.dt, "transition dt");
  if (tr.dt < 0.0) throw core::InvalidInput("transition dt is negative (expected >= 0)");
  if (tr.Gamma.size() > 0 || tr.u.size() > 0) {
    checkSize(tr.Gamma, n, tr.u.size(), "input matrix Gamma");
    checkFinite(tr.Gamma, "input matrix Gamma");
    checkFinite(tr.u, "input u");
  }
  return Gq;
}

// The checks of validateMeasurement, in the same order; returns the factor of R.
const Eigen::MatrixXd& checkMeasurement(Workspace& ws, const StateEstimate& s, const LinearMeasurement& m) {
  requireState(s);
  const Eigen::Index n = s.dim();
  const Eigen::Index rows = m.y.size();
  checkSize(m.C, rows, n, "measurement matrix C");
  checkFinite(m.C, "measurement matrix C");
  checkFinite(m.y, "measurement y");
  checkSize(m.R, rows, rows, "measurement noise R (R2)");
  return validatedFactor(ws.r, m.R, "measurement noise R (R2)", true);
}

}  // namespace

void predict(StateEstimate& s, const LinearTransition& tr) {
  Workspace& ws = workspace();
  const Eigen::MatrixXd& Gq = checkTransition(ws, s, tr);
  const Eigen::Index n = s.dim();
  Eigen::VectorXd x(n);
  x.noalias() = tr.Phi * s.x();
  if (tr.u.size() > 0) x.noalias() += tr.Gamma * tr.u;
  // Pre-array [Φ L  Gq] (n x 2n) -> [L⁺ 0].
  ws.pre.resize(n, 2 * n);
  ws.pre.leftCols(n).noalias() = tr.Phi * s.sqrtP();
  ws.pre.rightCols(n) = Gq;
  lowerTriangularizeInPlace(ws.pre);
  Eigen::MatrixXd L = ws.pre.leftCols(n);
  if (!x.allFinite() || !L.allFinite()) throw core::NumericalError("predict produced non-finite values");
  s.assign(std::move(x), std::move(L), s.t() + tr.dt);
}

namespace {

// The shared array step. With tr == nullptr this is the filter-form update (Φ = I, R1 = 0,
// R12 = 0) and Ge is the factor of R; otherwise G = [Gv; Ge] is the factor of the joint noise
// covariance [[R1, R12], [R12ᵀ, R2]].
UpdateReport arrayStep(Workspace& ws, StateEstimate& s, const LinearTransition* tr, const LinearMeasurement& m,
                       const Eigen::MatrixXd& G) {
  const Eigen::Index n = s.dim();
  const Eigen::Index rows = m.y.size();
  const Eigen::Index gcols = G.cols();
  UpdateReport rep;
  rep.rows = rows;

  // Pre-array  [ C L   Ge ]  ->  [ S^½  0   ]
  //            [ Φ L   Gv ]      [ K̄    L⁺  ]
  const Eigen::MatrixXd& L = s.sqrtP();
  RowMatrixXd& pre = ws.pre;
  pre.resize(rows + n, n + gcols);
  if (tr != nullptr) {
    ws.phiL.resize(n, n);
    ws.phiL.noalias() = tr->Phi * L;
    pre.topLeftCorner(rows, n).noalias() = m.C * L;
    pre.topRightCorner(rows, gcols) = G.bottomRows(rows);
    pre.bottomLeftCorner(n, n) = ws.phiL;
    pre.bottomRightCorner(n, gcols) = G.topRows(n);
  } else {
    pre.topLeftCorner(rows, n).noalias() = m.C * L;
    pre.topRightCorner(rows, gcols) = G;
    pre.bottomLeftCorner(n, n) = L;
    pre.bottomRightCorner(n, gcols).setZero();
  }
  lowerTriangularizeInPlace(pre);

  const auto sqrtS = pre.topLeftCorner(rows, rows);
  const auto Kbar = pre.bottomLeftCorner(n, rows);
  if ((sqrtS.diagonal().array() <= 0.0).any()) {
    throw core::NumericalError("innovation covariance R2 + C P C' is singular");
  }
  rep.innovation = m.y;
  rep.innovation.noalias() -= m.C * s.x();
  rep.S.resize(rows, rows);
  rep.S.noalias() = sqrtS * sqrtS.transpose();
  // w = S^-½ d (triangular solve): NIS = |w|², correction = K̄ w.
  Eigen::VectorXd w = rep.innovation;
  sqrtS.triangularView<Eigen::Lower>().solveInPlace(w);
  rep.nis = w.squaredNorm();

  Eigen::VectorXd x(n);
  if (tr != nullptr) {
    x.noalias() = tr->Phi * s.x();
    if (tr->u.size() > 0) x.noalias() += tr->Gamma * tr->u;
  } else {
    x = s.x();
  }
  x.noalias() += Kbar * w;
  Eigen::MatrixXd Lplus = pre.block(rows, rows, n, n);
  if (!x.allFinite() || !Lplus.allFinite()) throw core::NumericalError("update produced non-finite values");
  const double t = s.t() + ((tr != nullptr) ? tr->dt : 0.0);
  s.assign(std::move(x), std::move(Lplus), t);
  return rep;
}

}  // namespace

UpdateReport update(StateEstimate& s, const LinearMeasurement& m) {
  Workspace& ws = workspace();
  const Eigen::MatrixXd& Ge = checkMeasurement(ws, s, m);
  if (m.y.size() == 0) return UpdateReport{};
  return arrayStep(ws, s, nullptr, m, Ge);
}

UpdateReport predictorStep(StateEstimate& s, const LinearTransition& tr, const LinearMeasurement& m,
                           const Eigen::MatrixXd& R12) {
  Workspace& ws = workspace();
  checkTransition(ws, s, tr);
  checkMeasurement(ws, s, m);
  const Eigen::Index n = s.dim();
  const Eigen::Index rows = m.y.size();
  checkSize(R12, n, rows, "cross-covariance R12");
  checkFinite(R12, "cross-covariance R12");
  Eigen::MatrixXd joint(n + rows, n + rows);
  joint.topLeftCorner(n, n) = tr.Q;
  joint.topRightCorner(n, rows) = R12;
  joint.bottomLeftCorner(rows, n) = R12.transpose();
  joint.bottomRightCorner(rows, rows) = m.R;
  const Eigen::MatrixXd& G =
      validatedFactor(ws.joint, joint, "joint noise covariance [[R1, R12], [R12', R2]]", false);
  return arrayStep(ws, s, &tr, m, G);
}

Eigen::MatrixXd innovationCovariance(const StateEstimate& s, const Eigen::MatrixXd& C,
                                     const Eigen::MatrixXd& R) {
  // Test first: the message is a std::string (a heap allocation on every image otherwise).
  if (C.rows() != R.rows() || C.cols() != s.dim()) core::requireSize(C, R.rows(), s.dim(), "measurement matrix C");
  const Eigen::MatrixXd CL = C * s.sqrtP();
  return R + CL * CL.transpose();
}

}  // namespace viewline::estimation
