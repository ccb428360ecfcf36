#pragma once
// Filter consistency: NEES (state error against P, needs truth) and NIS
// (innovation against S), with two-sided chi-square bands (SPEC §1.1).
//
// For N independent samples of a consistent n-dimensional quantity the sum of
// the NEES values is chi-square(N n); the band for the average at confidence c
// is [χ²((1−c)/2, N n), χ²((1+c)/2, N n)] / N (Bar-Shalom, Li, Kirubarajan,
// "Estimation with Applications to Tracking and Navigation", §5.4). Samples
// taken from one run at successive times are correlated; use one value per run
// (or the per-time-step average over runs) when a band is to be trusted.

#include <Eigen/Core>
#include <vector>

#include "viewline/core/statistics.h"
#include "viewline/estimation/state.h"

namespace viewline::estimation {

/// eᵀ P⁻¹ e with e = x_true − x̂ (Cholesky solve, never an inverse).
double nees(const StateEstimate& s, const Eigen::VectorXd& x_true);
/// Same for a sub-block (e.g. position only): indices select entries of x and P.
double nees(const StateEstimate& s, const Eigen::VectorXd& x_true, const std::vector<Eigen::Index>& indices);
/// dᵀ S⁻¹ d.
double nis(const Eigen::VectorXd& innovation, const Eigen::MatrixXd& S);

/// Running mean of NEES or NIS values with their degrees of freedom, and the band for it.
class ConsistencyStats {
public:
  /// Adds one NEES or NIS value with its degrees of freedom (its chi-square dof).
  void add(double value, double dof);
  /// Number of values added.
  std::size_t count() const { return count_; }
  /// Mean of the values added (0 when none).
  double mean() const;
  /// Mean degrees of freedom of the samples added.
  double meanDof() const;
  /// Two-sided band for the mean at `confidence`, treating the samples as independent.
  core::Interval bounds(double confidence = 0.99) const;
  /// True when the mean lies inside the two-sided chi-square band at `confidence`.
  bool consistent(double confidence = 0.99) const { return bounds(confidence).contains(mean()); }

private:
  double sum_ = 0.0;
  double dof_sum_ = 0.0;
  std::size_t count_ = 0;
};

}  // namespace viewline::estimation
