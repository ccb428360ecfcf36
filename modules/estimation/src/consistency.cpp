#include "viewline/estimation/consistency.h"

#include <Eigen/Cholesky>

#include "viewline/core/checks.h"

namespace viewline::estimation {

double nees(const StateEstimate& s, const Eigen::VectorXd& x_true) {
  core::requireSize(x_true, s.dim(), 1, "nees: true state");
  core::requireFinite(x_true, "nees: true state");
  const Eigen::VectorXd e = x_true - s.x();
  return s.sqrtP().triangularView<Eigen::Lower>().solve(e).squaredNorm();
}

double nees(const StateEstimate& s, const Eigen::VectorXd& x_true, const std::vector<Eigen::Index>& indices) {
  core::requireSize(x_true, s.dim(), 1, "nees: true state");
  const Eigen::MatrixXd P = s.P();
  const auto k = static_cast<Eigen::Index>(indices.size());
  Eigen::VectorXd e(k);
  Eigen::MatrixXd Pk(k, k);
  for (Eigen::Index i = 0; i < k; ++i) {
    if (indices[static_cast<std::size_t>(i)] < 0 || indices[static_cast<std::size_t>(i)] >= s.dim())
      throw core::InvalidInput("nees: index out of range");
    e[i] = x_true[indices[static_cast<std::size_t>(i)]] - s.x()[indices[static_cast<std::size_t>(i)]];
    for (Eigen::Index j = 0; j < k; ++j)
      Pk(i, j) = P(indices[static_cast<std::size_t>(i)], indices[static_cast<std::size_t>(j)]);
  }
  return nis(e, Pk);
}

double nis(const Eigen::VectorXd& innovation, const Eigen::MatrixXd& S) {
  core::requireSize(S, innovation.size(), innovation.size(), "nis: covariance");
  if (innovation.size() == 0) return 0.0;
  const Eigen::LLT<Eigen::MatrixXd> llt(S);
  if (llt.info() != Eigen::Success) throw core::InvalidInput("nis: covariance is not positive definite");
  return innovation.dot(llt.solve(innovation));
}

void ConsistencyStats::add(double value, double dof) {
  core::requireFinite(value, "consistency sample");
  core::requirePositive(dof, "consistency degrees of freedom");
  sum_ += value;
  dof_sum_ += dof;
  ++count_;
}

double ConsistencyStats::mean() const { return count_ == 0 ? 0.0 : sum_ / static_cast<double>(count_); }

double ConsistencyStats::meanDof() const {
  return count_ == 0 ? 0.0 : dof_sum_ / static_cast<double>(count_);
}

core::Interval ConsistencyStats::bounds(double confidence) const {
  if (count_ == 0) throw core::InvalidInput("consistency bounds of an empty sample");
  // Sum of chi-square(dof_i) is chi-square(sum dof_i); the mean's band divides by the count.
  const double n = static_cast<double>(count_);
  const double a = 0.5 * (1.0 - confidence);
  return {core::chiSquareQuantile(dof_sum_, a) / n, core::chiSquareQuantile(dof_sum_, 1.0 - a) / n};
}

}  // namespace viewline::estimation
