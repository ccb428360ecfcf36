#pragma once
// Chi-square quantiles and two-sided acceptance intervals (Boost.Math), used
// for NEES/NIS consistency bands and the Mahalanobis outlier gate.

namespace viewline::core {

/// Quantile of the chi-square distribution with `dof` degrees of freedom: P(X <= q) = p.
double chiSquareQuantile(double dof, double p);

/// Upper-tail probability P(X > x) of chi-square(dof).
double chiSquareSurvival(double dof, double x);

struct Interval {
  double lo = 0.0;
  double hi = 0.0;
  bool contains(double v) const { return v >= lo && v <= hi; }
};

/// Two-sided interval for the *average* of `samples` independent chi-square(dof)
/// variables at confidence `confidence` (e.g. 0.99): the sum is chi-square(samples*dof),
/// the interval is [q((1-c)/2), q((1+c)/2)] / samples. With samples = 1 it is the
/// interval of a single NEES/NIS value.
Interval averagedChiSquareInterval(double dof, double samples, double confidence = 0.99);

}  // namespace viewline::core
