#pragma once
// Constant velocity (white-noise acceleration) model, [T] eq 7, in d = 1, 2 or 3
// spatial dimensions.
//
// State (n = 2d), block layout:  x = (p, ṗ)  [m, m/s], p = (p_x[, p_y[, p_z]]).
// Continuous model: p̈ = w, w white with spectral density q [m²/s³] per axis.
// Exact discretisation over dt (Bar-Shalom, Li, Kirubarajan §6.2.2):
//
//   Φ = [ I  dt I ]        Q = q [ dt³/3 I   dt²/2 I ]
//       [ 0    I  ]              [ dt²/2 I   dt    I ]
//
// No input (Γ, u empty). Measurement: positions, see position_measurement.h.

#include <Eigen/Core>

#include "viewline/estimation/kalman_filter.h"

namespace viewline::estimation {

/// Constant velocity model with white acceleration: state (p, v) per axis in d = 1..3 dimensions ([T] eq 7).
struct ConstantVelocityModel {
  int dim = 3;     ///< spatial dimensions d (1, 2 or 3)
  double q = 1.0;  ///< acceleration spectral density [m²/s³], >= 0

  /// State dimension n = 2d.
  Eigen::Index stateDim() const { return 2 * dim; }
  /// Φ, Q for dt > 0. Throws core::InvalidInput naming the bad field (dim, q, dt).
  LinearTransition transition(double dt) const;
  /// Throws core::InvalidInput naming the bad field.
  void validate() const;
};

}  // namespace viewline::estimation
