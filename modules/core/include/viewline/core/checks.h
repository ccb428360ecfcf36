#pragma once
// Precondition checks that turn bad numbers into InvalidInput with a message
// naming the offending quantity. Used at every public boundary of the math
// modules so that a NaN never propagates silently.

#include <Eigen/Core>
#include <string>

#include "viewline/core/error.h"

namespace viewline::core {

/// Throws InvalidInput("<what> contains NaN or Inf ...") unless all entries are finite.
void requireFinite(const Eigen::Ref<const Eigen::MatrixXd>& m, const std::string& what);
/// Throws InvalidInput naming `what` unless `value` is finite.
void requireFinite(double value, const std::string& what);

/// Throws unless value > 0 and finite.
void requirePositive(double value, const std::string& what);

/// Throws unless value >= 0 and finite.
void requireNonNegative(double value, const std::string& what);

/// Throws unless m is rows x cols.
void requireSize(const Eigen::Ref<const Eigen::MatrixXd>& m, Eigen::Index rows, Eigen::Index cols,
                 const std::string& what);

/// Throws unless m is square, finite, symmetric (relative tolerance) and positive definite
/// (an LLT succeeds).
void requireSymmetricPositiveDefinite(const Eigen::Ref<const Eigen::MatrixXd>& m,
                                      const std::string& what, double rel_tol = 1e-9);

/// Throws unless m is square, finite, symmetric and positive semi-definite (LDLT with
/// non-negative pivots, up to a tolerance relative to the largest diagonal entry).
void requireSymmetricPositiveSemiDefinite(const Eigen::Ref<const Eigen::MatrixXd>& m,
                                          const std::string& what, double rel_tol = 1e-9);

/// True when |m - mᵀ| <= rel_tol * max(1, max|m|) entry-wise.
bool isSymmetric(const Eigen::Ref<const Eigen::MatrixXd>& m, double rel_tol = 1e-9);

/// (m + mᵀ)/2, applied in place.
void symmetrize(Eigen::MatrixXd& m);

}  // namespace viewline::core
