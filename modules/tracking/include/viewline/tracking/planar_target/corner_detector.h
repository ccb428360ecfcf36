#pragma once
// Corners of the planar target's path: the likelihood-ratio test for a velocity jump over the filter's
// recent history, the soft jump mixture's posterior odds, and the noise-scaled corner settings.
//
// Jump detection (jump_window > 0, any model): a generalised likelihood-ratio test for a step in
// velocity at one of the measurement times of the last jump_window seconds (a corner of a
// polyline at constant speed); on detection the filter restarts from its estimate at that time
// with the velocity prior re-opened and processes the later measurements again (PlanarTargetFilter).
// Soft jump mixture (jump_rate > 0; cv, ca, singer): between detected jumps the output is not the
// filter's x(k|k) alone but the posterior mixture of "no jump in the window" and "a jump at t_j"
// for the window's measurement times, with prior probability jump_rate × (t_j − t_{j−1}) and Bayes
// factor from the same fits as the test, the jump having the prior Δv ~ N(0, jump_prior_sigma² I);
// so the estimate starts to turn before the test is sure of a corner (estimate(), at()).
// With jump_evidence "legs" (constant-speed legs, once ŝ is known) the Bayes factor of "a jump at t_j"
// is instead the evidence of the measurements after t_j under a constant-speed leg from x(j|j) (θ with
// its learnt-turn prior) over their evidence under "straight on from x(j|j)" (both linear-Gaussian,
// closed form): a specific alternative (this speed, these turns), so the mixture turns sooner.
// Jump decision "posterior" (soft mixture on): a jump is declared, at the most probable t_j, once the
// mixture's hypotheses "a jump at t_j" that have jump_min_samples measurements after t_j hold more than
// jump_posterior of its posterior mass, instead of when the test statistic passes jump_threshold; the
// prior odds then count, and jump_threshold is not used.
// Noise-scaled corner settings (jump_min_samples and/or jump_corner_sigma "auto", nullopt): with
// σ = √(tr R / 2) the measurement noise (its latest R, per-axis RMS), Δt the median of the last 16
// measurement intervals, ŝ the learnt speed (before the first leg has ended: |v̂| of the state once
// it exceeds its own std; until then jump_min_samples is kAutoJumpSamplesMax) and ρ = σ / (ŝ Δt),
// the noise in units of the target's step between measurements,
//   jump_min_samples = clamp(round(kAutoJumpSamplesScale ρ^(2/3)), 2, kAutoJumpSamplesMax),
//   jump_corner_sigma = kAutoCornerSigmaPerNoise σ.
// Why ρ^(2/3): n measurements after a turn that changes the velocity by Δv (∝ ŝ at constant speed)
// depart from straight on by Δv Δt k, k = 1..n, a log-likelihood ratio of about Δv² Δt² n³ / (3 σ²);
// the same evidence for every setting needs n ∝ ρ^(2/3). The two factors are the values tuned for [T]'s
// random path at 10 % noise (ρ = 5.9: 8 and 0.01 m), checked by grid search at 5-20 % noise, at
// 0.3 m/s and at 60 fps: "auto" is within 1.5 % of the best fixed pair of each setting, where the
// 10 %-tuned pair loses up to 12 % (docs/results.md, pan-tilt).

#include <Eigen/Core>
#include <functional>
#include <limits>
#include <optional>
#include <utility>
#include <vector>

#include "viewline/core/time.h"
#include "viewline/tracking/planar_target/history.h"

namespace viewline::tracking {

/// The settings of one scan (from TargetFilterConfig, with the corner settings in force).
struct JumpScanSettings {
  int min_samples = 4;            ///< measurements on each side of a tested t_j (after it: soft mixture)
  double threshold = 20.0;        ///< jump_threshold
  bool soft = false;              ///< the soft jump mixture (jump_rate > 0)
  double jump_rate = 0.0;         ///< 1/s
  double prior_sigma = 0.15;      ///< jump_prior_sigma (m/s)
  bool posterior_decision = false;  ///< jump_decision "posterior"
  double posterior_mass = 0.99;   ///< jump_posterior
};

/// Result of a jump scan: the declared jump (if any) and the soft mixture's log odds per tested time.
struct JumpScan {
  int jump = -1;  ///< index into the history of the declared jump; -1: none
  /// Soft mixture: log(π_j BF_j) of "a jump at history[j]", for every tested j.
  std::vector<std::pair<double, int>> log_odds;
};

/// Scans the history for a velocity jump. leg_bayes_factor (soft mixture, jump_evidence "legs"; empty:
/// the kink fits' Bayes factors) gives log BF_j; region_odds (empty: jump_rate × interval) the log prior
/// odds of a jump at each j (WaypointRegion::jumpOdds).
JumpScan scanForJump(const PlanarHistory& history, const JumpScanSettings& settings,
                     const std::function<double(int)>& leg_bayes_factor, const std::vector<double>& region_odds);

/// The corner settings in force: the configured jump_min_samples / jump_corner_sigma, or the "auto" ones
/// from the measurement noise and cadence (above).
class CornerSettings {
public:
  /// The configured jump_min_samples / jump_corner_sigma; nullopt selects the noise-scaled "auto" value.
  CornerSettings(std::optional<int> min_samples, std::optional<double> corner_sigma)
      : min_samples_(min_samples), corner_sigma_(corner_sigma) {}
  /// A measurement at t with covariance R (keeps the latest R and the last 16 intervals).
  void note(core::Timestamp t, const Eigen::Matrix2d& R);
  /// `speed`: the target's speed (ŝ, or |v̂| once it exceeds its std), <= 0 when unknown.
  int minSamples(double speed) const;
  /// σ_c added to a new leg's corner position std, m (configured or "auto").
  double cornerSigma() const;
  /// √(tr R / 2) of the latest measurement: the per-axis RMS noise (m).
  double noiseSigma() const;

private:
  std::optional<int> min_samples_;
  std::optional<double> corner_sigma_;
  Eigen::Matrix2d last_R_ = Eigen::Matrix2d::Zero();
  core::Timestamp last_t_ = std::numeric_limits<double>::quiet_NaN();
  std::vector<double> intervals_;  ///< the last 16 measurement intervals (s)
};

}  // namespace viewline::tracking
