#pragma once
// Interacting multiple model (IMM) estimator (Blom & Bar-Shalom 1988; Bar-Shalom, Li,
// Kirubarajan §11.6) over M models that share one state space (dimension n).
//
// Mode switching is a continuous-time Markov chain: mode i is left after a mean sojourn time τ_i,
// towards mode j with probability J_ij (J row-stochastic, J_ii = 0). Over a step T the switching
// matrix is Π_ii = exp(−T/τ_i), Π_ij = (1 − exp(−T/τ_i)) J_ij.
//
// Step (predict to t, then update with a linear measurement y = C x + e, cov e = R):
//   mixing:      c_j = Σ_i Π_ij μ_i,   μ_{i|j} = Π_ij μ_i / c_j,
//                x0_j = Σ_i μ_{i|j} x_i,   P0_j = Σ_i μ_{i|j} (P_i + (x_i − x0_j)(x_i − x0_j)ᵀ)
//   prediction:  each mode propagates (x0_j, P0_j) with its own transition (linear or EKF); μ_j ← c_j
//   update:      each mode's Kalman update, likelihood Λ_j = N(d_j; 0, S_j), μ_j ← Λ_j μ_j / Σ
//   output:      x = Σ μ_j x_j,  P = Σ μ_j (P_j + (x_j − x)(x_j − x)ᵀ).
// Mode filters use the square-root StateEstimate (kalman_filter.h / nonlinear.h).

#include <Eigen/Core>
#include <functional>
#include <string>
#include <vector>

#include "viewline/core/time.h"
#include "viewline/estimation/kalman_filter.h"
#include "viewline/estimation/nonlinear.h"
#include "viewline/estimation/state.h"

namespace viewline::estimation {

/// One mode of an IMM: its transition and mean sojourn time.
struct ImmMode {
  std::string name;  ///< Mode name used in reports and telemetry (e.g. "cv", "ct").
  /// The mode's transition over dt > 0 (a linear model gives f(x) = Φ x, F = Φ).
  std::function<NonlinearTransition(double dt)> transition;
  double sojourn = 1.0;  ///< τ (s), mean time spent in this mode
};

/// Interacting multiple model estimator over modes sharing one state space (Blom & Bar-Shalom 1988).
class Imm {
public:
  /// `jump`: M x M row-stochastic with zero diagonal (where a mode goes when it is left);
  /// an empty matrix means "uniformly to the other modes".
  Imm(std::vector<ImmMode> modes, Eigen::MatrixXd jump = {});

  /// Number of modes M.
  std::size_t modeCount() const { return modes_.size(); }
  /// Mode j (throws std::out_of_range when j >= M).
  const ImmMode& mode(std::size_t j) const { return modes_.at(j); }
  /// True after reset(): every mode holds a state.
  bool initialized() const { return !states_.empty(); }

  /// Every mode starts at (x, P, t) with probabilities mu0 (default: uniform).
  void reset(const Eigen::VectorXd& x, const Eigen::MatrixXd& P, core::Timestamp t,
             const Eigen::VectorXd& mu0 = {});
  /// Mixing + prediction to t (no-op when t is not after the current time).
  void predict(core::Timestamp t);

  /// Diagnostics of one IMM update.
  struct Report {
    double nis = 0.0;             ///< NIS of the combined prediction (d ᵀ S⁻¹ d with the mixture moments)
    double log_likelihood = 0.0;  ///< log Σ_j c_j Λ_j
  };
  /// The mixture's innovation test for y at the current (predicted) time, without updating.
  double combinedNis(const LinearMeasurement& m) const;
  /// Kalman update of every mode and mode-probability update.
  Report update(const LinearMeasurement& m);

  /// Combined estimate (moment-matched mixture) at the current time.
  StateEstimate combined() const;
  /// Estimate of mode j after the last predict/update.
  const StateEstimate& modeState(std::size_t j) const { return states_.at(j); }
  /// Mode probabilities μ (M entries, sum 1).
  const Eigen::VectorXd& probabilities() const { return mu_; }
  /// Time of the current estimates (s, the run's clock).
  core::Timestamp time() const;
  /// Switching matrix over dt (M x M, row-stochastic).
  Eigen::MatrixXd switching(double dt) const;

private:
  std::vector<ImmMode> modes_;
  Eigen::MatrixXd jump_;
  std::vector<StateEstimate> states_;
  Eigen::VectorXd mu_;
};

}  // namespace viewline::estimation
