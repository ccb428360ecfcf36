#include "viewline/core/statistics.h"

#include <boost/math/distributions/chi_squared.hpp>
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

}  // namespace viewline::core
