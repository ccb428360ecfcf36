#include "viewline/core/statistics.h"

#include <algorithm>
#include <boost/math/distributions/chi_squared.hpp>
#include <cmath>
#include <limits>
#include <sstream>

#include "viewline/core/checks.h"

namespace viewline::core {

double chiSquareQuantile(double dof, double p) {
  requirePositive(dof, "chiSquareQuantile: dof");
  if (!(p > 0.0 && p < 1.0)) {
    std::ostringstream s;
    s << "chiSquareQuantile: probability " << p << " (expected 0 < p < 1)";
    throw InvalidInput(s.str());
  }
  return boost::math::quantile(boost::math::chi_squared(dof), p);
}

double chiSquareSurvival(double dof, double x) {
  requirePositive(dof, "chiSquareSurvival: dof");
  if (x <= 0.0) return 1.0;
  return boost::math::cdf(boost::math::complement(boost::math::chi_squared(dof), x));
}

Interval averagedChiSquareInterval(double dof, double samples, double confidence) {
  requirePositive(samples, "averagedChiSquareInterval: samples");
  const double total = dof * samples;
  const double a = 0.5 * (1.0 - confidence);
  return {chiSquareQuantile(total, a) / samples, chiSquareQuantile(total, 1.0 - a) / samples};
}

namespace {
constexpr double kNaN = std::numeric_limits<double>::quiet_NaN();
}

double percentile(std::vector<double> v, double q) {
  if (v.empty()) return kNaN;
  std::sort(v.begin(), v.end());
  const double pos = std::clamp(q, 0.0, 1.0) * static_cast<double>(v.size() - 1);
  const auto lo = static_cast<std::size_t>(std::floor(pos));
  const std::size_t hi = std::min(lo + 1, v.size() - 1);
  return v[lo] + (pos - static_cast<double>(lo)) * (v[hi] - v[lo]);
}

double percentileNearestRank(std::vector<double> v, double q) {
  if (v.empty()) return kNaN;
  std::sort(v.begin(), v.end());
  const auto k = static_cast<std::size_t>(std::ceil(std::clamp(q, 0.0, 1.0) * static_cast<double>(v.size())));
  return v[std::min(v.size() - 1, k == 0 ? 0 : k - 1)];
}

double rmsFromSum(double sum_sq, long n) { return n > 0 ? std::sqrt(sum_sq / static_cast<double>(n)) : kNaN; }

double rms(const std::vector<double>& v) {
  double s = 0.0;
  for (double x : v) s += x * x;
  return rmsFromSum(s, static_cast<long>(v.size()));
}

}  // namespace viewline::core
