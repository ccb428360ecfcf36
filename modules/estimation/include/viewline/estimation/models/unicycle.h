#pragma once
// Curvilinear ground target (unicycle), [K] eqs 16-20.
//
// State (n = 5): x = (x, y, θ, v, ω)   [m, m, rad, m/s, rad/s], ground plane.
// Discrete model over a step dt (exact for constant v and ω to second order in
// the heading, the midpoint rule of [K]):
//
//   x⁺ = x + v dt cos(θ + ω dt/2)
//   y⁺ = y + v dt sin(θ + ω dt/2)
//   θ⁺ = θ + ω dt                    (wrapped to (−π, π] by `normalize`)
//   v⁺ = v + ξv,   ω⁺ = ω + ξω       (random walks)
//
// with ξv ~ N(0, q_v dt), ξω ~ N(0, q_ω dt) independent, so
// Q = diag(0, 0, 0, q_v dt, q_ω dt). Analytic Jacobian F = ∂x⁺/∂x, φ = θ + ω dt/2:
//
//   ∂x⁺/∂θ = −v dt sin φ   ∂x⁺/∂v = dt cos φ   ∂x⁺/∂ω = −v dt² sin φ / 2
//   ∂y⁺/∂θ =  v dt cos φ   ∂y⁺/∂v = dt sin φ   ∂y⁺/∂ω =  v dt² cos φ / 2
//   ∂θ⁺/∂ω = dt, identity elsewhere.
//
// Measurement: the ground position (x, y) + e, cov e = σ² I (e.g. from a
// camera and the ground-plane back-projection). Works with ekf*/ukf* of
// nonlinear.h. Trajectory prediction: unicycle_predictor.h.

#include <Eigen/Core>

#include "viewline/estimation/nonlinear.h"

namespace viewline::estimation {

/// Angle wrapped to (−π, π].
double wrapAngle(double a);

/// Unicycle ground target ([K] eqs 16-20): state (x, y, θ, v, ω) [m, m, rad, m/s, rad/s] on the ground plane.
struct UnicycleModel {
  double q_v = 0.1;   ///< speed random-walk intensity: var ξv = q_v dt [m²/s³], >= 0
  double q_w = 0.01;  ///< turn-rate random-walk intensity: var ξω = q_w dt [rad²/s³], >= 0

  /// State dimension n = 5.
  static constexpr Eigen::Index kStateDim = 5;

  /// Noise-free step f(x) over dt (> 0); θ is not wrapped (normalize does it).
  Eigen::VectorXd propagate(const Eigen::VectorXd& x, double dt) const;
  /// F = ∂f/∂x (analytic).
  Eigen::MatrixXd jacobian(const Eigen::VectorXd& x, double dt) const;
  /// Q = diag(0, 0, 0, q_v dt, q_w dt).
  Eigen::MatrixXd processNoise(double dt) const;
  /// f, F, Q, dt and the θ wrapping.
  NonlinearTransition transition(double dt) const;
  /// h(x) = (x, y), H = [I₂ 0], R = sigma² I.
  static NonlinearMeasurement positionMeasurement(const Eigen::Vector2d& y, double sigma);
  /// a − b with the heading difference wrapped (for errors and NEES).
  static Eigen::VectorXd difference(const Eigen::VectorXd& a, const Eigen::VectorXd& b);
  /// Throws core::InvalidInput naming the field (q_v, q_w negative or not finite).
  void validate() const;
};

}  // namespace viewline::estimation
