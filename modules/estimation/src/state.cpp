#include "viewline/estimation/state.h"

#include <Eigen/Cholesky>
#include <cmath>

#include "viewline/core/checks.h"
#include "viewline/estimation/square_root.h"

namespace viewline::estimation {

namespace {
// requireSymmetricPositiveDefinite's test without its message (a std::string, built only when
// the test fails: the tracker and the flight fit build estimates on every image).
bool symmetricPositiveDefinite(const Eigen::MatrixXd& P) {
  return P.allFinite() && core::isSymmetric(P) && (P.size() == 0 || Eigen::LLT<Eigen::MatrixXd>(P).info() == Eigen::Success);
}
}  // namespace

StateEstimate::StateEstimate(const Eigen::VectorXd& x, const Eigen::MatrixXd& P, core::Timestamp t) {
  if (!x.allFinite()) core::requireFinite(x, "state mean x");
  if (P.rows() != x.size() || P.cols() != x.size()) core::requireSize(P, x.size(), x.size(), "state covariance P");
  if (!symmetricPositiveDefinite(P)) core::requireSymmetricPositiveDefinite(P, "state covariance P");
  if (!std::isfinite(t)) core::requireFinite(t, "state time t");
  x_ = x;
  L_ = psdSqrt(P, "state covariance P");
  t_ = t;
}

StateEstimate StateEstimate::fromSqrt(const Eigen::VectorXd& x, const Eigen::MatrixXd& sqrtP,
                                      core::Timestamp t) {
  core::requireFinite(x, "state mean x");
  core::requireFinite(sqrtP, "state covariance factor");
  core::requireSize(sqrtP, x.size(), sqrtP.cols(), "state covariance factor");
  core::requireFinite(t, "state time t");
  StateEstimate s;
  s.assign(x, lowerTriangularize(sqrtP), t);
  return s;
}

void StateEstimate::setMean(const Eigen::VectorXd& x) {
  core::requireFinite(x, "state mean x");
  core::requireSize(x, L_.rows(), 1, "state mean x");
  x_ = x;
}

void StateEstimate::setCovariance(const Eigen::MatrixXd& P) {
  core::requireSize(P, x_.size(), x_.size(), "state covariance P");
  core::requireSymmetricPositiveDefinite(P, "state covariance P");
  L_ = psdSqrt(P, "state covariance P");
}

void StateEstimate::assign(Eigen::VectorXd x, Eigen::MatrixXd L, core::Timestamp t) {
  x_ = std::move(x);
  L_ = std::move(L);
  t_ = t;
}

}  // namespace viewline::estimation
