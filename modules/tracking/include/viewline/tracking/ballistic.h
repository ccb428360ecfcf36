#pragma once
// Ballistic (no drag) motion model on the state x = (p, ṗ) ∈ R⁶, world frame,
// with a white-noise acceleration w of spectral density q (m²/s³) per axis:
//
//   ṗ = v,   v̇ = g + w.
//
// Exact discretisation over any interval dt (this is what Van Loan gives for
// this A, written out; tested against estimation::discretize):
//
//   Φ = [I  dt I; 0  I],   Γ u = [dt²/2 I; dt I] g,
//   Q = q [dt³/3 I  dt²/2 I; dt²/2 I  dt I].
//
// [L] eq 20 is the special case g = (0, −9.81, 0) (y up) and q = 0.
// Kept local to tracking so it does not wait for the motion-model library.

#include <Eigen/Core>

#include "viewline/estimation/kalman_filter.h"

namespace viewline::tracking {

/// Ballistic state (p, v) in the world frame, m and m/s.
using Vector6 = Eigen::Matrix<double, 6, 1>;
/// 6 x 6 matrix on the ballistic state (covariances, transitions).
using Matrix6 = Eigen::Matrix<double, 6, 6>;

/// Drag-free ballistic motion with white acceleration noise on x = (p, v), world frame (exact discretisation).
struct BallisticModel {
  Eigen::Vector3d gravity_w{0.0, 0.0, -9.81};  ///< m/s², world frame
  double accel_psd = 0.0;                       ///< q, m²/s³ (white acceleration), >= 0

  /// Φ, Γ, u = g, Q for the interval dt >= 0 (dt = 0 gives the identity with Q = 0).
  estimation::LinearTransition transition(double dt) const;
  /// Noise-free propagation of a state over dt.
  Vector6 propagate(const Vector6& x, double dt) const;
  /// Q(dt) alone (6x6).
  Matrix6 processNoise(double dt) const;
};

}  // namespace viewline::tracking
