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

using VectorFn = std::function<Eigen::VectorXd(const Eigen::VectorXd&)>;
using JacobianFn = std::function<Eigen::MatrixXd(const Eigen::VectorXd&)>;

struct NonlinearTransition {
  VectorFn f;          ///< x ↦ f(x) over the step
  JacobianFn F;        ///< ∂f/∂x (EKF only)
  Eigen::MatrixXd Q;   ///< process noise of the step
  double dt = 0.0;     ///< seconds added to the state's time
  VectorFn normalize;  ///< optional: wraps angle states after each step
};

struct NonlinearMeasurement {
  VectorFn h;                ///< x ↦ predicted measurement
  JacobianFn H;              ///< ∂h/∂x (EKF only)
  Eigen::VectorXd y;         ///< measured value
  Eigen::MatrixXd R;         ///< noise covariance, symmetric positive definite
  std::function<Eigen::VectorXd(const Eigen::VectorXd&, const Eigen::VectorXd&)> residual;  ///< optional y ⊖ ŷ
};

void ekfPredict(StateEstimate& s, const NonlinearTransition& tr);
UpdateReport ekfUpdate(StateEstimate& s, const NonlinearMeasurement& m);

struct UnscentedParams {
  double alpha = 1.0;
  double beta = 2.0;
  double kappa = 0.0;
};

void ukfPredict(StateEstimate& s, const NonlinearTransition& tr, const UnscentedParams& p = {});
UpdateReport ukfUpdate(StateEstimate& s, const NonlinearMeasurement& m, const UnscentedParams& p = {});

/// Central-difference Jacobian of f at x (step scaled per entry); used to check analytic Jacobians.
Eigen::MatrixXd numericalJacobian(const VectorFn& f, const Eigen::VectorXd& x, double rel_step = 1e-6);

}  // namespace viewline::estimation
