#include "viewline/estimation/fixed_kalman.h"

#include <string>

#include "viewline/core/checks.h"
#include "viewline/estimation/square_root.h"

namespace viewline::estimation::fixed_detail {

// The failure paths of the fixed-size filter, out of line: they build the dynamic path's messages
// through the same core checks (kalman_filter.cpp), so both paths report a bad input alike.

void throwNotFinite(const char* what) {
  throw core::InvalidInput(std::string(what) + " contains NaN or Inf (expected finite values)");
}

void throwNotFiniteScalar(const char* what) {
  throw core::InvalidInput(std::string(what) + " is NaN or Inf (expected a finite value)");
}

void throwBadCovariance(const Eigen::MatrixXd& M, const char* what, bool definite) {
  if (definite) core::requireSymmetricPositiveDefinite(M, what);
  core::requireSymmetricPositiveSemiDefinite(M, what);
  // The checks above accept what the one-pass rule refused only at the tolerance's edge.
  throw core::InvalidInput(std::string(what) + " is not symmetric positive " + (definite ? "definite" : "semi-definite"));
}

void throwNegativeDt() { throw core::InvalidInput("transition dt is negative (expected >= 0)"); }

void throwNonFiniteResult(const char* step) {
  throw core::NumericalError(std::string(step) + " produced non-finite values");
}

void throwSingularInnovation() { throw core::NumericalError("innovation covariance R2 + C P C' is singular"); }

Eigen::MatrixXd psdFactor(const Eigen::MatrixXd& M, const char* what) { return psdSqrt(M, what); }

}  // namespace viewline::estimation::fixed_detail
