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
// Held input noise (optional; [K]'s object model). [K] drives the object with v_k = v̄(k) + εv,k
// and ω_k = ω̄(k) + εω,k, the ε drawn once per input period T (100 ms) and held over it: white
// from one period to the next, not a random walk. The state's (v, ω) is then the smooth part
// (v̄, ω̄) (random walks q_v, q_ω as above) and the held ε moves the pose over the step as an
// input would: with G = ∂(x⁺, y⁺, θ⁺)/∂(v, ω) (the v and ω columns of F above, rows x, y, θ),
//
//   Q = diag(0, 0, 0, q_v dt, q_ω dt) + [G Σ_ε Gᵀ 0; 0 0],  Σ_ε = diag(σ_εv², σ_εω²) · min(1, T/dt),
//
// G taken at the prior mean (the EKF's usual treatment of control noise: Thrun, Burgard & Fox,
// Probabilistic Robotics, 2005, Table 7.2, V_t M_t V_tᵀ). Exact to first order when the step is
// one aligned input period (dt = T); over n = dt/T periods the n independent ε average to Σ_ε/n
// (exact for θ and for the speed's effect on position; the lever arm of an early heading error on
// the later position is left out); within one period they are fully correlated (Σ_ε).
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
  double input_sigma_v = 0.0;  ///< σ_εv, held speed noise per input period [m/s], >= 0 (0: none)
  double input_sigma_w = 0.0;  ///< σ_εω, held turn-rate noise per input period [rad/s], >= 0 (0: none)
  double input_period = 0.1;   ///< T, the period over which ε is held [s], > 0

  /// State dimension n = 5.
  static constexpr Eigen::Index kStateDim = 5;

  /// Noise-free step f(x) over dt (> 0); θ is not wrapped (normalize does it).
  Eigen::VectorXd propagate(const Eigen::VectorXd& x, double dt) const;
  /// F = ∂f/∂x (analytic).
  Eigen::MatrixXd jacobian(const Eigen::VectorXd& x, double dt) const;
  /// The random walks' Q = diag(0, 0, 0, q_v dt, q_w dt); throws when held input noise is set
  /// (its Q depends on the state: the overload below).
  Eigen::MatrixXd processNoise(double dt) const;
  /// Q with the held input noise, G taken at the state x (the prior mean).
  Eigen::MatrixXd processNoise(const Eigen::VectorXd& x, double dt) const;
  /// True when held input noise is set (σ_εv or σ_εω > 0).
  bool hasInputNoise() const { return input_sigma_v > 0.0 || input_sigma_w > 0.0; }
  /// f, F, Q, dt and the θ wrapping (random walks only; throws when held input noise is set).
  NonlinearTransition transition(double dt) const;
  /// f, F, dt, the θ wrapping and Q with the held input noise linearised at x (the prior mean).
  NonlinearTransition transition(double dt, const Eigen::VectorXd& x) const;
  /// h(x) = (x, y), H = [I₂ 0], R = sigma² I.
  static NonlinearMeasurement positionMeasurement(const Eigen::Vector2d& y, double sigma);
  /// a − b with the heading difference wrapped (for errors and NEES).
  static Eigen::VectorXd difference(const Eigen::VectorXd& a, const Eigen::VectorXd& b);
  /// Throws core::InvalidInput naming the field (q_v, q_w, input_sigma_v, input_sigma_w negative
  /// or not finite; input_period not positive).
  void validate() const;
};

}  // namespace viewline::estimation
