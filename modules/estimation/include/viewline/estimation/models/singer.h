#pragma once
// Singer model ([T]; Singer 1970): the acceleration is a first-order
// Gauss-Markov process, in d = 1, 2 or 3 spatial dimensions.
//
// State (n = 3d), block layout: x = (p, ṗ, p̈)  [m, m/s, m/s²].
// Continuous model, per axis, α = 1/τ:
//
//   ṗ = v,  v̇ = a,  ȧ = −α a + w,   w white with spectral density 2 α σm²,
//
// so the stationary acceleration has std σm and autocorrelation σm² e^{−|t|/τ}.
// Exact discretisation over dt (T = dt):
//
//   Φ = [ 1  T  (αT − 1 + e^{−αT})/α² ]
//       [ 0  1  (1 − e^{−αT})/α        ]
//       [ 0  0  e^{−αT}                ]
//   Q = ∫₀ᵀ e^{As} G Qc Gᵀ e^{Aᵀs} ds  (Singer's closed form).
//
// Φ and Q are computed without cancellation for every τ: Φ = e^{AT} by Padé
// scaling and squaring, and Q from vec Q = ∫₀ᵀ e^{(A⊕A)s} ds vec(G Qc Gᵀ), the
// upper-right block of exp([[A⊕A, vec W], [0, 0]] T). Unlike Van Loan's
// [[−A, W], [0, Aᵀ]] this never exponentiates +αT, so τ → 0 does not overflow.
//
// Limits (tested): τ → ∞ with σm² = q τ/2 gives the Wiener-acceleration model
// (ConstantAccelerationModel with jerk density q); τ → 0 with σm² = q/(2τ)
// makes the acceleration white with density q on the velocity, i.e. the
// constant-velocity model (ConstantVelocityModel with density q).

#include <Eigen/Core>

#include "viewline/estimation/kalman_filter.h"

namespace viewline::estimation {

/// Singer model: first-order Gauss-Markov acceleration, state (p, v, a) per axis in d = 1..3 dimensions.
struct SingerModel {
  int dim = 3;          ///< spatial dimensions d (1, 2 or 3)
  double tau = 1.0;     ///< manoeuvre time constant τ [s], > 0
  double sigma_m = 1.0; ///< acceleration std σm [m/s²], >= 0

  /// State dimension n = 3d.
  Eigen::Index stateDim() const { return 3 * dim; }
  /// Φ, Q for dt > 0 (exact discretisation, stable for every τ > 0).
  LinearTransition transition(double dt) const;
  /// Throws core::InvalidInput naming the bad field (dim, tau, sigma_m).
  void validate() const;
};

}  // namespace viewline::estimation
