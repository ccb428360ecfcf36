#pragma once
// Constant acceleration model with Wiener-process acceleration ([T]; Bar-Shalom,
// Li, Kirubarajan §6.2.3), in d = 1, 2 or 3 spatial dimensions.
//
// State (n = 3d), block layout: x = (p, ṗ, p̈)  [m, m/s, m/s²].
// Continuous model: d³p/dt³ = w, w white with spectral density q [m²/s⁵] per axis.
// Exact discretisation over dt (per axis, ⊗ I_d):
//
//   Φ = [ 1  dt  dt²/2 ]        Q = q [ dt⁵/20  dt⁴/8  dt³/6 ]
//       [ 0   1  dt    ]              [ dt⁴/8   dt³/3  dt²/2 ]
//       [ 0   0  1     ]              [ dt³/6   dt²/2  dt    ]

#include <Eigen/Core>

#include "viewline/estimation/kalman_filter.h"

namespace viewline::estimation {

/// Constant acceleration model with white jerk: state (p, v, a) per axis in d = 1..3 dimensions.
struct ConstantAccelerationModel {
  int dim = 3;     ///< spatial dimensions d (1, 2 or 3)
  double q = 1.0;  ///< jerk spectral density [m²/s⁵], >= 0

  /// State dimension n = 3d.
  Eigen::Index stateDim() const { return 3 * dim; }
  /// Φ, Q for dt > 0 (exact discretisation).
  LinearTransition transition(double dt) const;
  /// Throws core::InvalidInput naming the bad field (dim, q).
  void validate() const;
};

}  // namespace viewline::estimation
