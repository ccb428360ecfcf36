#pragma once
// The filter state: an explicit object (models hold no state).
//
// The covariance is carried as a lower-triangular square-root factor L with
// P = L Lᵀ. Every filter operation works on L through orthogonal
// transformations (QR array algorithms), so P is symmetric positive
// semi-definite by construction and the cancellation in Φ P Φᵀ − K(...) that
// [L] §III.E warns about for a huge P(0) cannot make it indefinite.

#include <Eigen/Core>

#include "viewline/core/error.h"
#include "viewline/core/time.h"

namespace viewline::estimation {

/// Filter state: mean x, covariance as a square-root factor L (P = L Lᵀ) and the time stamp t (s).
class StateEstimate {
public:
  StateEstimate() = default;
  /// Mean x, covariance P (symmetric positive definite, checked), time t.
  StateEstimate(const Eigen::VectorXd& x, const Eigen::MatrixXd& P, core::Timestamp t = 0.0);

  /// Build from a square-root factor directly (P = sqrtP sqrtPᵀ); sqrtP need not be triangular.
  static StateEstimate fromSqrt(const Eigen::VectorXd& x, const Eigen::MatrixXd& sqrtP,
                                core::Timestamp t = 0.0);

  /// State dimension n.
  Eigen::Index dim() const { return x_.size(); }
  /// Mean x (n entries).
  const Eigen::VectorXd& x() const { return x_; }
  /// The covariance P = L Lᵀ (computed on demand).
  Eigen::MatrixXd P() const { return L_ * L_.transpose(); }
  /// The square-root factor L (lower triangular).
  const Eigen::MatrixXd& sqrtP() const { return L_; }
  /// Time stamp of the estimate (s, the run's clock).
  core::Timestamp t() const { return t_; }

  /// Replaces the mean (finite, same dimension; throws core::InvalidInput otherwise).
  void setMean(const Eigen::VectorXd& x);
  /// Replaces the covariance (symmetric positive definite, checked) and refactors L.
  void setCovariance(const Eigen::MatrixXd& P);
  /// Sets the time stamp (s) without propagating the state.
  void setTime(core::Timestamp t) { t_ = t; }

  /// Used by the filter functions after they validated everything (no checks).
  void assign(Eigen::VectorXd x, Eigen::MatrixXd L, core::Timestamp t);

private:
  Eigen::VectorXd x_;
  Eigen::MatrixXd L_;
  core::Timestamp t_ = 0.0;
};

}  // namespace viewline::estimation
