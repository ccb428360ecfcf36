#pragma once
// Ballistic flight without drag ([L] eqs 19-20).
//
// State (n = 6): x = (p, ṗ) = (p_x, p_y, p_z, v_x, v_y, v_z)  [m, m/s], world frame.
// Continuous model: p̈ = −g·up + w, with `up` the unit world "up" axis, g [m/s²]
// and w white acceleration noise of spectral density q [m²/s³] per axis.
// Exact discretisation over h = dt:
//
//   Φ = [ I  hI ]    Γ = −g [ h²/2 · up ]    u = (1)
//       [ 0   I ]           [ h    · up ]
//   Q = q [ h³/3 I  h²/2 I ]
//         [ h²/2 I  h    I ]
//
// With up = (0, 1, 0) this is [L] eq 20 exactly: Γ = (0, −g h²/2, 0, 0, −g h, 0)ᵀ.
// The default world has z up. Measurement: positions (position_measurement.h)
// or viewline planes (tracking module).

#include <Eigen/Core>

#include "viewline/estimation/kalman_filter.h"

namespace viewline::estimation {

/// Drag-free ballistic flight in the world frame: state (p, v) [m, m/s], gravity along −up ([L] eqs 19-20).
struct BallisticModel {
  Eigen::Vector3d up = Eigen::Vector3d::UnitZ();  ///< world up axis (normalised on use; non-zero)
  double g = 9.81;                                 ///< gravity [m/s²], >= 0
  double q = 1.0;                                  ///< acceleration noise spectral density [m²/s³], >= 0

  /// State dimension n = 6.
  static constexpr Eigen::Index kStateDim = 6;
  /// Φ, Γ (6x1), u = (1), Q for dt > 0.
  LinearTransition transition(double dt) const;
  /// Gravity vector −g·up/|up| [m/s²].
  Eigen::Vector3d gravity() const;
  /// Throws core::InvalidInput naming the field (up zero, g or q negative or not finite).
  void validate() const;
};

}  // namespace viewline::estimation
