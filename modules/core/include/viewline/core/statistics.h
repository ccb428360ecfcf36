#pragma once
// Chi-square quantiles and two-sided acceptance intervals (Boost.Math), used
// for NEES/NIS consistency bands and the Mahalanobis outlier gate; the sample
// statistics every scenario's metrics use (percentiles, RMS).

#include <vector>

namespace viewline::core {

/// Quantile of the chi-square distribution with `dof` degrees of freedom: P(X <= q) = p.
double chiSquareQuantile(double dof, double p);

/// Upper-tail probability P(X > x) of chi-square(dof).
double chiSquareSurvival(double dof, double x);

/// Closed interval [lo, hi] (e.g. a two-sided chi-square acceptance band).
struct Interval {
  double lo = 0.0;  ///< Lower bound (inclusive).
  double hi = 0.0;  ///< Upper bound (inclusive).
  /// True when lo <= v <= hi.
  bool contains(double v) const { return v >= lo && v <= hi; }
};

/// Two-sided interval for the *average* of `samples` independent chi-square(dof)
/// variables at confidence `confidence` (e.g. 0.99): the sum is chi-square(samples*dof),
/// the interval is [q((1-c)/2), q((1+c)/2)] / samples. With samples = 1 it is the
/// interval of a single NEES/NIS value.
Interval averagedChiSquareInterval(double dof, double samples, double confidence = 0.99);

/// Percentile q in [0, 1] of a sample by linear interpolation between order statistics
/// (Hyndman and Fan's type 7, NumPy's and R's default): with the sorted sample v and
/// h = q (n − 1), v[⌊h⌋] + (h − ⌊h⌋)(v[⌊h⌋+1] − v[⌊h⌋]). NaN for an empty sample; q is clamped.
double percentile(std::vector<double> v, double q);

/// Percentile q in (0, 1] by the nearest-rank rule: the ⌈q n⌉-th smallest value (type 1; the
/// value itself, never an interpolation: "p95 of the convergence counts" stays a count).
/// NaN for an empty sample.
double percentileNearestRank(std::vector<double> v, double q);

/// Root mean square from a sum of squares over n samples: √(sum_sq / n); NaN when n == 0.
double rmsFromSum(double sum_sq, long n);

/// Root mean square of a sample; NaN when empty.
double rms(const std::vector<double>& v);

}  // namespace viewline::core
