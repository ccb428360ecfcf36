#pragma once
// Linear Kalman filter, [L] eqs 1-10 (SPEC §1.1):
//
//   x(k+1) = Φ x(k) + Γ u(k) + v(k),   y(k) = C(k) x(k) + e(k),
//   cov v = R1, cov(v, e) = R12, cov e = R2.
//
// Measurement update (filter form):
//   Kf = P Cᵀ (R2 + C P Cᵀ)⁻¹,  x ← x + Kf (y − C x),  P ← P − Kf C P
// One-step predictor form (carries R12):
//   K = (Φ P Cᵀ + R12)(R2 + C P Cᵀ)⁻¹
//   x(k+1|k) = Φ x + Γ u + K (y − C x),  P(k+1|k) = Φ P Φᵀ + R1 − K (Φ P Cᵀ + R12)ᵀ
//
// Implementation: square-root array algorithms. With the joint noise factor
// G = [Gv; Ge], G Gᵀ = [[R1, R12], [R12ᵀ, R2]], the pre-array
//     A = [ C L   Ge ]
//         [ Φ L   Gv ]
// is triangularised by an orthogonal Θ (Householder QR of Aᵀ):
//     A Θ = [ S^½   0  ]      S^½ S^½ᵀ = R2 + C P Cᵀ          (innovation covariance)
//           [ K̄     L⁺ ]      K̄ = (Φ P Cᵀ + R12) S^-ᵀ/²,  L⁺ L⁺ᵀ = P(k+1|k)
// so K = K̄ S^-½ and x(k+1|k) = Φ x + Γ u + K̄ S^-½ (y − C x): S is only ever
// used through triangular solves with its factor (never inverted). The filter
// update is the special case Φ = I, R1 = 0, R12 = 0.
//
// Any number of measurement rows is allowed, including zero (pure
// prediction). Every function validates its input (finite values, sizes,
// symmetric positive (semi-)definite covariances, dt) and throws
// core::InvalidInput naming the offending quantity, leaving the state
// unchanged.

#include <Eigen/Core>

#include "viewline/estimation/state.h"

namespace viewline::estimation {

/// One discrete transition x ← Φ x + Γ u + v, cov v = Q (= R1), over dt seconds.
struct LinearTransition {
  Eigen::MatrixXd Phi;  ///< n x n state transition Φ over dt
  Eigen::MatrixXd Gamma;  ///< n x p, may be empty (no input)
  Eigen::VectorXd u;      ///< p, may be empty
  Eigen::MatrixXd Q;      ///< n x n, symmetric positive semi-definite
  double dt = 0.0;        ///< seconds; added to the state's time (0 for a pure index step)
};

/// y = C x + e, cov e = R (= R2); m >= 0 rows. `t` is the capture time (informational here:
/// the caller has propagated the state to it, see the tracking module for asynchronous data).
struct LinearMeasurement {
  Eigen::MatrixXd C;  ///< m x n
  Eigen::VectorXd y;  ///< m
  Eigen::MatrixXd R;  ///< m x m, symmetric positive definite
};

/// What an update saw: innovation, its covariance and the normalised innovation squared.
struct UpdateReport {
  Eigen::VectorXd innovation;  ///< d = y − C x(k|k−1)
  Eigen::MatrixXd S;           ///< R2 + C P Cᵀ
  double nis = 0.0;            ///< dᵀ S⁻¹ d (chi-square with m dof for a consistent filter)
  Eigen::Index rows = 0;  ///< m, the number of measurement rows used (0: nothing was updated)
};

/// Time update: x ← Φ x + Γ u, P ← Φ P Φᵀ + Q, t ← t + dt.
void predict(StateEstimate& s, const LinearTransition& tr);

/// Measurement update (filter form). With zero rows it does nothing and reports nis = 0.
UpdateReport update(StateEstimate& s, const LinearMeasurement& m);

/// One-step predictor form with the cross-covariance R12 (n x m) between process and
/// measurement noise: s holds x(k|k−1), P(k|k−1) on entry and x(k+1|k), P(k+1|k) on return.
UpdateReport predictorStep(StateEstimate& s, const LinearTransition& tr, const LinearMeasurement& m,
                           const Eigen::MatrixXd& R12);

/// Innovation covariance S = R + C P Cᵀ for the current state (used by outlier gates).
Eigen::MatrixXd innovationCovariance(const StateEstimate& s, const Eigen::MatrixXd& C,
                                     const Eigen::MatrixXd& R);

/// Validation shared by the linear and nonlinear filters (throw core::InvalidInput).
void validateTransition(const StateEstimate& s, const LinearTransition& tr);
/// Throws core::InvalidInput unless C is m x n, y has m entries and R is m x m symmetric positive definite, all finite.
void validateMeasurement(const StateEstimate& s, const LinearMeasurement& m);

}  // namespace viewline::estimation
