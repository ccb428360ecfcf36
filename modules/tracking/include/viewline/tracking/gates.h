#pragma once
// Outlier gates for the rows of one image ([L] §V and the standard test).
//
// With the rows C, y, R2 of one image and the filter's x̂, P:
//   ŷ = C x̂,  Rŷ = C P Cᵀ,  d = y − ŷ,  R = R2 + Rŷ.
// Directional gate ([L] §V): the variance in the direction of d is
//   σ² = dᵀ R d / dᵀ d,  and the image is an outlier when |d| > p σ.
// Mahalanobis gate: outlier when dᵀ R⁻¹ d > χ²(m, 1 − α) (m rows, α the
// probability of rejecting a good measurement).
//
// Both statistics are always computed and reported, so both gates can be
// compared on the same data; the configured kind decides.

#include <Eigen/Core>
#include <string>

namespace viewline::tracking {

/// Outlier gate of the viewline tracker: none, directional ([L] §V) or chi-square (Mahalanobis).
enum class GateKind { None, Directional, Mahalanobis };

/// Lower-case name of a gate kind ("none", "directional", "mahalanobis").
const char* toString(GateKind k);
/// "none", "directional", "mahalanobis"; throws core::InvalidInput naming `what` otherwise.
GateKind gateKindFromString(const std::string& s, const std::string& what = "gate kind");

/// Which outlier gate decides, and its threshold.
struct GateConfig {
  GateKind kind = GateKind::Mahalanobis;  ///< the gate whose decision is applied
  double directional_p = 4.0;       ///< p of [L] §V
  double mahalanobis_alpha = 1e-3;  ///< false-rejection probability of the chi-square gate
};

/// Both gates' statistics for one innovation, and the decision of the configured one.
struct GateReport {
  double distance = 0.0;        ///< |d|
  double sigma_dir = 0.0;       ///< σ in the direction of d
  double directional_threshold = 0.0;  ///< p σ
  double mahalanobis = 0.0;     ///< dᵀ R⁻¹ d
  double chi2_threshold = 0.0;  ///< χ²(m, 1 − α)
  bool directional_outlier = false;  ///< |d| > p σ (whatever gate is configured)
  bool mahalanobis_outlier = false;  ///< dᵀ R⁻¹ d > χ²(m, 1 − α) (whatever gate is configured)
  bool rejected = false;        ///< decision of the configured gate
  GateKind decided_by = GateKind::None;  ///< the gate that decided (None: no gate)
  /// Human-readable reason ("directional: |d| = ... > p σ = ...").
  std::string reason() const;
};

/// Evaluates both gates for innovation d and its covariance R = R2 + C P Cᵀ (symmetric positive
/// definite; solved by Cholesky, never inverted).
GateReport evaluateGate(const Eigen::VectorXd& d, const Eigen::MatrixXd& R, const GateConfig& cfg);

}  // namespace viewline::tracking
