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
//
// First-order hold (an input that ramps linearly from u0 to u1 over the interval, e.g. a tilt
// measured at both ends of a frame interval while the table turns between them):
//
//   x(dt) = Φ x(0) + Γ u0 + Λ (u1 − u0) / dt,   Λ = ∫₀^dt e^{A(dt−s)} B s ds,
//
// with Γ and Λ the top-right blocks of e^{[[A, B, 0], [0, 0, I], [0, 0, 0]] dt} = [[Φ, Γ, Λ], ...]
// (Franklin, Powell and Workman, "Digital Control of Dynamic Systems", 3rd ed., §6.3.2, the
// triangle-hold equivalent). The transition carries Γ_FOH = [Γ − Λ/dt, Λ/dt] and u = (u0, u1).

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

/// Φ, Γ, Q for the interval dt (> 0) with the input ramping linearly from u0 to u1 (first-order
/// hold): Gamma is n x 2p and u = (u0, u1), so Φ x + Γ u is the exact mean step; Φ and Q as
/// discretize(). Needs an input (B with p >= 1 columns, u0 and u1 of size p).
LinearTransition discretizeFirstOrderHold(const ContinuousLinearModel& model, double dt, const Eigen::VectorXd& u0,
                                          const Eigen::VectorXd& u1);

}  // namespace viewline::estimation
