#pragma once
// Coordinated-turn (CT) model on a plane: constant speed, turn rate ω a slowly varying state.
//
// State x = (px, py, vx, vy, ω). Over a step T, with s = sin ωT, c = cos ωT (exact solution of
// ṗ = v, v̇ = ω J v, ω̇ = 0, J = [0 −1; 1 0]):
//
//   px' = px + (s/ω) vx − ((1 − c)/ω) vy        vx' = c vx − s vy
//   py' = py + ((1 − c)/ω) vx + (s/ω) vy        vy' = s vx + c vy          ω' = ω
//
// (ω → 0: the constant-velocity model; the series s/ω ≈ T − ω²T³/6, (1 − c)/ω ≈ ωT²/2 − ω³T⁴/24
// are used for |ωT| < 1e-4). Process noise: white acceleration of density q_a (m²/s³) on each
// velocity axis (the CV blocks q_a [T³/3 T²/2; T²/2 T], exact for ω = 0 and used as is for small
// ωT) and a random walk of density q_ω (rad²/s³) on ω: Q_ωω = q_ω T. Bar-Shalom, Li, Kirubarajan,
// "Estimation with applications to tracking and navigation", §11.7.
//
// The Jacobian F = ∂f/∂x is analytic (checked against a central difference in the test).

#include <Eigen/Core>

#include "viewline/estimation/nonlinear.h"

namespace viewline::estimation::models {

/// Process-noise densities of the coordinated-turn model.
struct CoordinatedTurnParams {
  double q_accel = 1e-3;  ///< m²/s³, white acceleration density per axis
  double q_omega = 1e-3;  ///< rad²/s³, random-walk density of the turn rate
  void validate() const;  ///< throws core::InvalidInput naming the field
};

/// f(x) over dt (x has 5 entries).
Eigen::VectorXd coordinatedTurnStep(const Eigen::VectorXd& x, double dt);
/// ∂f/∂x at x over dt (5 x 5).
Eigen::MatrixXd coordinatedTurnJacobian(const Eigen::VectorXd& x, double dt);
/// Process noise over dt (5 x 5).
Eigen::MatrixXd coordinatedTurnNoise(const CoordinatedTurnParams& p, double dt);
/// The EKF/UKF transition over dt.
NonlinearTransition coordinatedTurnTransition(const CoordinatedTurnParams& p, double dt);

}  // namespace viewline::estimation::models
