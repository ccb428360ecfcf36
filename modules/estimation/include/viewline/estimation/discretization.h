#pragma once
// Exact discretisation of a continuous-time linear model
//
//   ẋ = A x + B u + G w,   w white with spectral density Qc (E w(t)w(s)ᵀ = Qc δ(t−s)),
//
// over an interval dt with u held constant (zero-order hold):
//
//   Φ = e^{A dt},   Γ = ∫₀^dt e^{Aτ} dτ B,   Q = ∫₀^dt e^{Aτ} G Qc Gᵀ e^{Aᵀτ} dτ.
//
// Van Loan (1978): with M = [[−A, G Qc Gᵀ], [0, Aᵀ]] dt, e^M = [[·, Φ⁻¹ Q], [0, Φᵀ]],
// so Φ = (lower-right block)ᵀ and Q = Φ · (upper-right block). Γ comes from
// e^{[[A, B], [0, 0]] dt} = [[Φ, Γ], [0, I]]. Matrix exponentials by Eigen's
// MatrixFunctions (scaling and squaring with Padé). Used for aperiodic samples:
// rebuild Φ, Γ and Q for the actual interval of every step ([L] §VII).

#include <Eigen/Core>

#include "viewline/estimation/kalman_filter.h"

namespace viewline::estimation {

/// Continuous-time linear model ẋ = A x + B u + G w with white noise w of spectral density Qc.
struct ContinuousLinearModel {
  Eigen::MatrixXd A;   ///< n x n
  Eigen::MatrixXd B;   ///< n x p (may be empty)
  Eigen::MatrixXd G;   ///< n x q noise input
  Eigen::MatrixXd Qc;  ///< q x q spectral density, symmetric PSD
};

/// Φ, Γ, Q for the interval dt (> 0); u is copied into the transition.
LinearTransition discretize(const ContinuousLinearModel& model, double dt,
                            const Eigen::VectorXd& u = Eigen::VectorXd());

}  // namespace viewline::estimation
