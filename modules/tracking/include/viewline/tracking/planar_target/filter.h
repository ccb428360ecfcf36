#pragma once
// The planar target filter: a target moving on a known plane, estimated in plane coordinates (m).
//
// Kalman filter of a target moving on a plane, state (p, v[, a]) in plane coordinates (m),
// models built as continuous-time systems and discretised exactly (estimation::discretize,
// Van Loan) for the actual interval of every step:
//   CV:     ṗ = v, v̇ = w,                 w ~ q I₂
//   CA:     ṗ = v, v̇ = a, ȧ = w,          w ~ q I₂
//   Singer: ṗ = v, v̇ = a, ȧ = −a/τ + w,   w ~ (2 σm² / τ) I₂
//   CT:     state (p, v, ω), coordinated turn (estimation/models/coordinated_turn.h), EKF
//   IMM:    state (p, v, ω), three modes (estimation/imm.h): "cv" = CV with density q (ω kept,
//           random walk ct_q_omega), "ct" = CT (ct_q_accel, ct_q_omega), "maneuver" = CV with
//           density maneuver_q; mean sojourn times imm_sojourn, jumps uniform to the other modes.
//           (CT alone is the one-mode IMM, i.e. a plain EKF.)
// Measurement: the position, y = [I 0] x + e, cov e = R.
// Gate (tracking::TrackGate, 2 dof): a measurement whose NIS exceeds χ²₂(gate_probability) is not
// fused; reinit_after of them in a row re-initialise the filter at the last one. update() reports the
// decision with the NIS it was taken on.
// The parts, each in its own header:
//   corner_detector.h  jump detection (a corner of a polyline), the soft jump mixture, "auto" corner settings;
//   speed_legs.h       constant-speed legs after each corner, the learnt speed and turn angles;
//   waypoint_region.h  the box the waypoints lie in (direction prior, turn odds, coasting stops at its edge);
//   waypoint_particles.h  the Bayes reference of the random path (model waypoint_particles, below).
// Waypoint particles (model waypoint_particles; needs the region): instead of a Kalman filter, the
// waypoint particle filter (waypoint_particles.h), the posterior of the random path's own
// generator (waypoints uniform in the region, one speed). state() and estimate() are its posterior
// moments of (p, v) at the last measurement, at() its moments run ahead; its outlier term replaces
// the gate (every measurement is accepted; NIS against the predicted moments), and a reset() draws
// a fresh cloud from the next stream. The Kalman keys (q, jumps, legs, turns) are not used. It is
// the Bayes reference of the replays put in the loop, for targets whose generator is known.
// Mixture (model mixture): the target either runs straight constant-speed legs between corners or
// turns at a steady rate, and the user need not say which: two filters run side by side on every
// measurement, the cv filter with all its corner keys (jumps, legs, turns, region) and the ct filter
// (ct_q_accel, ct_q_omega, init_omega_sigma; no corner keys), and their probabilities are the posterior
// of a two-state Markov chain (switch rate mixture_switch_rate) given each one's predictive likelihood
// N(z; p̂ᵢ, Pᵢ + R) (Bar-Shalom, Li, Kirubarajan 2001, §11.6, the multiple-model estimator without
// interaction: the cv filter's corner history cannot be mixed). The output (at(), estimate()) is the
// Gaussian mixture's mean and covariance (spread of the means included); the NIS that update() reports
// is the measurement's against that mixture's prediction, and the mixture's gate (gate_probability,
// reinit_after) decides on it for every part: a measurement it rejects is fused by no part (the cv part
// keeps it in its corner history, as a cv filter keeps its gated-out measurements) and leaves the
// probabilities at the chain's prediction; a restart re-initialises every part and keeps the
// probabilities. Corner diagnostics (jumps, speed, turns, region) are the cv part's.

#include <Eigen/Core>
#include <array>
#include <cstdint>
#include <memory>
#include <optional>
#include <utility>
#include <vector>

#include "viewline/core/time.h"
#include "viewline/estimation/discretization.h"
#include "viewline/estimation/imm.h"
#include "viewline/estimation/state.h"
#include "viewline/tracking/planar_target/config.h"
#include "viewline/tracking/planar_target/corner_detector.h"
#include "viewline/tracking/planar_target/history.h"
#include "viewline/tracking/planar_target/speed_legs.h"
#include "viewline/tracking/planar_target/waypoint_particles.h"
#include "viewline/tracking/planar_target/waypoint_region.h"
#include "viewline/tracking/track_gate.h"

namespace viewline::tracking {

/// Kalman (or IMM / particle) filter of a target moving on a known plane, plane coordinates in m, with a chi-
/// square gate and jump handling.
class PlanarTargetFilter {
public:
  /// Filter with this configuration (validated; throws core::InvalidInput).
  explicit PlanarTargetFilter(const TargetFilterConfig& config = {});

  /// What one update did.
  struct Update {
    bool accepted = false;  ///< the measurement was fused
    bool reinitialized = false;  ///< the filter was (re)initialised at the measurement
    bool jump = false;  ///< a velocity jump was detected and the recent measurements processed again
    double nis = 0.0;   ///< of the innovation the gate tested (0 when the measurement started the track)
    std::optional<GateDecision> decision;  ///< the gate's decision (nullopt: no measurement)
  };
  /// True once the first measurement initialised the filter.
  bool initialized() const { return initialized_; }
  /// (Re)initialises at the measurement: the gate's Start.
  void reset(core::Timestamp t, const Eigen::Vector2d& z, const Eigen::Matrix2d& R);
  /// Predicts to t (>= the state's time) and fuses z (gated). Initialises on the first call.
  Update update(core::Timestamp t, const Eigen::Vector2d& z, const Eigen::Matrix2d& R);

  /// Position, velocity, acceleration (plane coordinates; m, m/s, m/s²) and position covariance at one time.
  struct Kinematics {
    Eigen::Vector2d p = Eigen::Vector2d::Zero(),  ///< position, m
                    v = Eigen::Vector2d::Zero(),  ///< velocity, m/s
                    a = Eigen::Vector2d::Zero();  ///< acceleration, m/s² (zero for models without it)
    Eigen::Matrix2d P_pos = Eigen::Matrix2d::Zero();  ///< position covariance, m²
  };
  /// The state extrapolated to t (no change to the filter); t may be before the state's time
  /// only by rounding (it is then evaluated at the state's time). With an active waypoint region, an
  /// extrapolation that would leave the box stops on its boundary with v = a = 0 (the model's target
  /// never leaves it; it turns there, direction unknown): what coasting through an occlusion follows.
  Kinematics at(core::Timestamp t) const;
  /// The filter state (mean and covariance in the model's layout, time of the last update).
  const estimation::StateEstimate& state() const { return state_; }
  /// The output estimate at the last measurement: the soft jump mixture when it applies, else state().
  const estimation::StateEstimate& estimate() const { return output_ ? *output_ : state_; }
  /// The configuration in use.
  const TargetFilterConfig& config() const { return config_; }
  /// Dimension of the model's state (e.g. 4 for CV on the plane).
  int stateDim() const;
  /// IMM mode probabilities (cv, ct, maneuver); mixture: (cv legs, ct); empty for the other models.
  Eigen::VectorXd modeProbabilities() const;
  /// Velocity jumps detected since construction.
  std::size_t jumps() const { return parts_.empty() ? jumps_ : parts_.front().jumps(); }
  /// The gate's decisions reported by update() and reset() since construction (the measurements a
  /// detected jump processes again are not counted twice).
  const GateCounts& gateCounts() const { return counts_; }
  /// The NIS threshold χ²₂(gate_probability).
  double gateThreshold() const { return gate_.threshold(); }
  /// Starts a constant-speed leg at t_c (>= the last measurement time) from the estimate there: a
  /// jump known from outside (e.g. the corner times of a known path, for a bound). Needs constant_speed
  /// and a known speed.
  void startLeg(core::Timestamp t_c);
  /// Sets ŝ and its variance (instead of learning them from the legs).
  void setSpeed(double speed, double variance);
  /// The corner settings in force now: the configured values, or the "auto" ones (corner_detector.h).
  int minSamples() const;
  /// σ_c in force now, m.
  double cornerSigma() const;
  /// The learnt speed ŝ (m/s) and its variance; 0 / 1e300 before the first segment has ended.
  double speedEstimate() const { return parts_.empty() ? speed_.estimate() : parts_.front().speedEstimate(); }
  /// Variance of the learnt speed ŝ, m²/s² (1e300 before the first segment has ended).
  double speedVariance() const { return parts_.empty() ? speed_.variance() : parts_.front().speedVariance(); }
  /// The configured waypoint region was dropped because the measurements left it (waypoint_region.h).
  bool regionDropped() const { return parts_.empty() ? region_.dropped() : parts_.front().regionDropped(); }
  /// The turn angles (rad, in [−π, π], oldest first) learnt at the last corners (turn_prior_weight > 0).
  const std::vector<double>& learntTurns() const {
    return parts_.empty() ? turns_.turns() : parts_.front().learntTurns();
  }

private:
  using Snapshot = PlanarSnapshot;
  /// The old state is dropped: x = (z, 0...), P = diag(R, the motion prior), the gate started at t.
  void start(core::Timestamp t, const Eigen::Vector2d& z, const Eigen::Matrix2d& R);
  /// update() under the gate's decision `decided` (a mixture part: the mixture's), or its own gate's (nullopt).
  Update updateUnder(core::Timestamp t, const Eigen::Vector2d& z, const Eigen::Matrix2d& R,
                     std::optional<GateDecision> decided);
  /// One predict-gate-fuse step; `decided` as in updateUnder.
  Update step(core::Timestamp t, const Eigen::Vector2d& z, const Eigen::Matrix2d& R,
              std::optional<GateDecision> decided = std::nullopt);
  /// The gate on out.nis (or the decision `decided`, if given): true to fuse. Otherwise the state becomes
  /// `coast` (if given) and a restart re-initialises at the measurement.
  bool admit(Update& out, core::Timestamp t, const Eigen::Vector2d& z, const Eigen::Matrix2d& R,
             const estimation::StateEstimate* coast = nullptr, std::optional<GateDecision> decided = std::nullopt);
  void count(const Update& u);
  /// The measurement and the state now, under a new serial.
  Snapshot snapshot(core::Timestamp t, const Eigen::Vector2d& z, const Eigen::Matrix2d& R);
  bool detectJump();
  void applyJump(int j);  ///< restart from history_[j] with the motion prior re-opened, re-process the rest
  void softMixture(std::vector<std::pair<double, int>>& log_odds);
  /// The constant-speed leg from the corner (t_c, c ~ N(c, P_c)) under the current speed, turn and
  /// region priors; from_direction: the direction (rad) of the leg that ended there (NaN: θ uniform);
  /// moments_table: with the logPrior table of moments()' first grid (false: logEvidence's only).
  ConstantSpeedLeg makeLeg(core::Timestamp t_c, const Eigen::Vector2d& c, const Eigen::Matrix2d& P_c,
                           double from_direction, bool moments_table = true) const;
  LegFactory legFactory() const;  ///< makeLeg with the priors at the time of the call (logEvidence's table only)
  /// A leg prior's normalisation and logPrior tables (ConstantSpeedLeg), keyed by the fields logPrior reads.
  struct LegPriorMemo {
    bool region = false;  ///< key: ConstantSpeedLeg::region
    Eigen::Vector2d region_c = Eigen::Vector2d::Zero(),   ///< key: ConstantSpeedLeg::region_c, m
                    region_lo = Eigen::Vector2d::Zero(),  ///< key: ConstantSpeedLeg::region_lo, m
                    region_hi = Eigen::Vector2d::Zero();  ///< key: ConstantSpeedLeg::region_hi, m
    double region_log_scale = 0.0;  ///< key: ConstantSpeedLeg::region_log_scale
    std::vector<double> prior_mu;   ///< key: ConstantSpeedLeg::prior_mu, rad
    double prior_weight = 0.0,      ///< key: ConstantSpeedLeg::prior_weight
           prior_sigma = 0.0;       ///< key: ConstantSpeedLeg::prior_sigma, rad
    double log_norm = 0.0;          ///< the normalisation for these fields
    std::shared_ptr<const std::vector<double>> evidence,  ///< logPrior on legBayesFactor's grid
                                               moments;   ///< logPrior on moments()' first grid (once asked for)
    std::uint64_t used = 0;         ///< last use (memo_clock_), for dropping the least recent
  };
  /// The memo entry of this leg's prior fields (made on a miss), with moments()' table if moments_table.
  const LegPriorMemo& legPriorMemo(const ConstantSpeedLeg& leg, bool moments_table) const;
  static constexpr std::size_t kLegPriorMemoSize = 256;  ///< entries kept (a scan asks for ~1 per measurement of the window)
  estimation::StateEstimate reopened(const Snapshot& sj) const;  ///< x(j|j) with the motion prior re-opened
  estimation::StateEstimate alternative(int j) const;            ///< the state now after a jump at history_[j]
  bool legEvidenceMixture() const;    ///< the soft mixture's Bayes factors from constant-speed legs
  /// log prior odds of a turn at each soft-mixture candidate from the waypoint region; empty if none.
  std::vector<double> regionJumpOdds() const;
  bool usesImm() const { return config_.model == TargetModel::CoordinatedTurn || config_.model == TargetModel::Imm; }
  void setParticleState();  ///< state_ from the particles' moments at their time
  /// update() of model mixture: both parts updated, their probabilities from the predictive likelihoods.
  Update updateMixture(core::Timestamp t, const Eigen::Vector2d& z, const Eigen::Matrix2d& R);
  Kinematics mixtureAt(core::Timestamp t) const;  ///< the parts' at(t) as one Gaussian
  /// The parts' predictions ks (cv legs, ct) as one Gaussian under the current part probabilities.
  Kinematics mixtureOf(const std::array<Kinematics, 2>& ks) const;
  void setMixtureState(core::Timestamp t);  ///< state_ = the parts' (p, v) estimates as one Gaussian

  TargetFilterConfig config_;
  TrackGate gate_;
  GateCounts counts_;
  CornerSettings corners_;
  LegSpeed speed_;
  LearntTurns turns_;
  WaypointRegion region_;
  std::shared_ptr<const ConstantSpeedLeg> leg_;  ///< the current leg (immutable: copies share it until it changes)
  mutable std::vector<LegPriorMemo> leg_prior_memo_;  ///< legPriorMemo's entries (a cache: no effect on values)
  mutable std::uint64_t memo_clock_ = 0;              ///< counts legPriorMemo calls
  mutable std::size_t memo_hint_ = 0;                 ///< where legPriorMemo's search starts (after the last hit)
  std::optional<estimation::StateEstimate> output_;  ///< the soft mixture, when it differs from state_
  PlanarHistory history_;  ///< measurements of the last jump_window s (since the last jump)
  std::uint64_t serial_ = 0;  ///< the last snapshot's serial
  LegBayesFactors leg_bayes_factors_;  ///< the scan's legBayesFactor, its sums kept between scans (a cache)
  std::size_t jumps_ = 0;
  std::optional<estimation::Imm> imm_;
  std::optional<WaypointParticleFilter> particles_;  ///< model waypoint_particles
  std::uint64_t particle_resets_ = 0;
  std::vector<PlanarTargetFilter> parts_;  ///< model mixture: the cv-legs filter, then the ct filter
  Eigen::Vector2d part_probability_ = Eigen::Vector2d::Constant(0.5);  ///< model mixture: P(cv legs), P(ct)
  estimation::ContinuousLinearModel model_;
  estimation::StateEstimate state_;
  bool initialized_ = false;
};

}  // namespace viewline::tracking
