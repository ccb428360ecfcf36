#pragma once
// Nonlinear filters: extended (EKF) and unscented (UKF) Kalman filters for
//
//   x(k+1) = f(x(k)) + v,  cov v = Q;     y = h(x) + e,  cov e = R.
//
// The EKF linearises with the model's analytic Jacobians F = ∂f/∂x and
// H = ∂h/∂x and then uses the same square-root array algorithm as the linear
// filter (kalman_filter.h), with the innovation y − h(x̂). The UKF uses the
// scaled unscented transform (Julier & Uhlmann; Wan & van der Merwe) with
// sigma points taken from the square-root factor L: X = x̂ ± √(n+λ) L_i.
// `residual` lets angle-valued measurements wrap their innovation; `normalize`
// lets angle-valued states wrap.

#include <Eigen/Core>
#include <functional>

#include "viewline/estimation/kalman_filter.h"
#include "viewline/estimation/state.h"

namespace viewline::estimation {

/// A vector map x ↦ f(x) (transition or measurement function).
using VectorFn = std::function<Eigen::VectorXd(const Eigen::VectorXd&)>;
/// A Jacobian map x ↦ ∂f/∂x.
using JacobianFn = std::function<Eigen::MatrixXd(const Eigen::VectorXd&)>;

/// One nonlinear transition x ← f(x) + v, cov v = Q, over dt seconds.
struct NonlinearTransition {
  VectorFn f;          ///< x ↦ f(x) over the step
  JacobianFn F;        ///< ∂f/∂x (EKF only)
  Eigen::MatrixXd Q;   ///< process noise of the step
  double dt = 0.0;     ///< seconds added to the state's time
  VectorFn normalize;  ///< optional: wraps angle states after each step
};

/// A nonlinear measurement y = h(x) + e, cov e = R.
struct NonlinearMeasurement {
  VectorFn h;                ///< x ↦ predicted measurement
  JacobianFn H;              ///< ∂h/∂x (EKF only)
  Eigen::VectorXd y;         ///< measured value
  Eigen::MatrixXd R;         ///< noise covariance, symmetric positive definite
  std::function<Eigen::VectorXd(const Eigen::VectorXd&, const Eigen::VectorXd&)> residual;  ///< optional y ⊖ ŷ
};

/// EKF time update: x ← f(x), P ← F P Fᵀ + Q (square-root array form), t ← t + dt.
void ekfPredict(StateEstimate& s, const NonlinearTransition& tr);
/// EKF measurement update with H linearised at the prediction; returns innovation, S and NIS.
UpdateReport ekfUpdate(StateEstimate& s, const NonlinearMeasurement& m);

/// Scaling of the unscented transform (Wan & van der Merwe): λ = α²(n + κ) − n.
struct UnscentedParams {
  double alpha = 1.0;  ///< Spread α of the sigma points around the mean (0 < α <= 1).
  double beta = 2.0;  ///< Prior knowledge of the distribution (2 is optimal for a Gaussian).
  double kappa = 0.0;  ///< Secondary scaling κ (usually 0 or 3 − n).
};

/// UKF time update with sigma points from the square-root factor; t ← t + dt.
void ukfPredict(StateEstimate& s, const NonlinearTransition& tr, const UnscentedParams& p = {});
/// UKF measurement update; returns innovation, S and NIS.
UpdateReport ukfUpdate(StateEstimate& s, const NonlinearMeasurement& m, const UnscentedParams& p = {});

/// Central-difference Jacobian of f at x (step scaled per entry); used to check analytic Jacobians.
Eigen::MatrixXd numericalJacobian(const VectorFn& f, const Eigen::VectorXd& x, double rel_step = 1e-6);

}  // namespace viewline::estimation
