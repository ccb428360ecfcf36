#pragma once
// Stationary Kalman gain from the discrete algebraic Riccati equation
// ([M] eqs 2.11, 4.31-4.32, with [M]'s misprint A P A corrected to A P Aᵀ):
//
//   P = A P Aᵀ + Q − A P Cᵀ (C P Cᵀ + R)⁻¹ C P Aᵀ     (a-priori covariance)
//   Kf = P Cᵀ (C P Cᵀ + R)⁻¹                          (filter-form gain)
//
// Solved with the structure-preserving doubling algorithm (Chu, Fan, Lin 2005)
// on the dual (control) form: A₀ = Aᵀ, G₀ = Cᵀ R⁻¹ C, H₀ = Q,
//   W = I + G H,  A⁺ = A W⁻¹ A,  G⁺ = G + A W⁻¹ G Aᵀ,  H⁺ = H + Aᵀ H W⁻¹ A,
// H → P quadratically for a stabilisable, detectable pair. The result is
// checked by its residual.

#include <Eigen/Core>

namespace viewline::estimation {

/// Stationary Kalman filter of a DARE solution: a-priori and a-posteriori covariances and the filter gain.
struct StationaryFilter {
  Eigen::MatrixXd P;   ///< a-priori (predicted) covariance
  Eigen::MatrixXd Pf;  ///< a-posteriori (filtered) covariance P − Kf C P
  Eigen::MatrixXd Kf;  ///< filter-form gain
  int iterations = 0;  ///< doubling iterations used until convergence
  double residual = 0.0;  ///< max |DARE(P) − P| relative to max(1, |P|)
};

/// Throws core::InvalidInput for bad sizes/covariances and core::NumericalError when the
/// doubling does not converge (e.g. an undetectable unstable mode).
StationaryFilter solveDare(const Eigen::MatrixXd& A, const Eigen::MatrixXd& C, const Eigen::MatrixXd& Q,
                           const Eigen::MatrixXd& R, int max_iterations = 100, double tol = 1e-12);

}  // namespace viewline::estimation
