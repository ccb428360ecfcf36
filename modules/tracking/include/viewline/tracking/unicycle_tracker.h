#pragma once
// A gated track of a curvilinear ground target: the EKF on estimation::UnicycleModel
// (x, y, θ, v, ω; [K] eqs 16-20) measured by floor positions (x, y), started from two points,
// gated and restarted by tracking::TrackGate, with the speed history the least-squares path
// predictor needs ([K] eqs 27-29, estimation::UnicycleTrajectoryPredictor).
//
// Life cycle of one measurement z = (x, y) with covariance R at time t:
//   no track:   the first point is kept; a second one within `start_window_s` after it starts the
//               track (gate decision Start): position z, heading and speed from the two points,
//               covariances from R and the time between them (below), ω = 0.
//   live track: predicted to t, the update is computed and its own report (innovation d,
//               S = R + H P Hᵀ, NIS = dᵀ S⁻¹ d, 2 dof) goes to the gate: Accept fuses it,
//               Reject coasts, Restart (the gate's restart_after-th rejection in a row: the track,
//               not the measurements, is wrong) drops the track and keeps z as the first point
//               of the next two-point start.
//
// Two-point start, d = z₂ − z₁ over Δt: x = (z₂, atan2(d), |d| / Δt, 0) with
//   P_pos = R,  σ_θ = min(π, √(2 σ²) / max(|d|, 1 mm) + 0.2),  σ_v = √(2 σ²) / Δt + σ_v0 / 2,
//   σ_ω = σ_ω0,  σ² = tr(R) / 2,
// the first-order spread of the direction and length of a difference of two points with
// per-axis variance σ², widened by a fixed 0.2 rad and half the prior speed spread.
//
// (θ, v) and (θ + π, −v) describe the same motion; when the object nearly stops the EKF can slide
// to the negative-speed twin, so after each fused update it is mapped back (θ shifted by π, the
// covariance by J = diag(1, 1, 1, −1, 1)): θ stays the heading of the object.

#include <Eigen/Core>
#include <optional>

#include "viewline/estimation/kalman_filter.h"
#include "viewline/estimation/models/unicycle.h"
#include "viewline/estimation/models/unicycle_predictor.h"
#include "viewline/estimation/state.h"
#include "viewline/tracking/track_gate.h"

namespace viewline::tracking {

/// Configuration of the unicycle ground tracker: model noise, two-point start, gate and predictor window.
struct UnicycleTrackerConfig {
  estimation::UnicycleModel model{0.01, 0.5};  ///< random-walk intensities q_v (m²/s³), q_w (rad²/s³)
  double init_speed_sigma = 0.3;               ///< m/s, prior speed spread of a two-point start
  double init_turn_sigma = 1.0;                ///< rad/s, turn-rate spread of a two-point start
  TrackGateConfig gate{0.999, 5};              ///< χ²₂ gate; restart after 5 rejections in a row
  double start_window_s = 0.5;                 ///< s, the two points of a start at most this far apart
  int predictor_window = 10;                   ///< (t, v, ω) samples kept for the LS predictor, >= 2
  /// Throws core::InvalidInput naming the field (prefixed with `what`).
  void validate(const char* what = "tracker") const;
};

/// What one measurement did to the track.
struct UnicycleUpdate {
  /// The gate's decision; nullopt when there was no track and the measurement was kept as the
  /// first point of a two-point start (no decision to take).
  std::optional<GateDecision> decision;
  bool fused = false;  ///< the track now includes z (Start or Accept)
  /// The update's own report for a live track (Accept, Reject, Restart): innovation, S, NIS.
  /// Empty (rows 0, NaN NIS) for Start and for a kept first point.
  estimation::UpdateReport report;
};

/// Unicycle ground tracker on the floor: EKF with two-point starts, TrackGate life cycle and a least-squares
/// trajectory predictor.
class UnicycleTracker {
public:
  /// Throws core::InvalidInput for an invalid config.
  explicit UnicycleTracker(const UnicycleTrackerConfig& config);

  /// A track exists (started and not restarted since).
  bool valid() const { return valid_; }
  /// The estimate x = (x, y, θ, v, ω) on the floor (world frame; m, rad, m/s, rad/s).
  const estimation::StateEstimate& state() const { return est_; }
  /// The trajectory predictor fed with the track's (t, v, ω).
  const estimation::UnicycleTrajectoryPredictor& predictor() const { return predictor_; }
  /// The track's gate (decisions, counts, life cycle).
  const TrackGate& gate() const { return gate_; }
  /// The configuration in use.
  const UnicycleTrackerConfig& config() const { return config_; }

  /// Time update to t (no-op without a track or when t is not after the state's time).
  void predictTo(double t);

  /// Measurement z (floor x, y; m) with covariance R at time t (s).
  UnicycleUpdate update(double t, const Eigen::Vector2d& z, const Eigen::Matrix2d& R);

  /// The mean propagated to time t without touching the track (e.g. to aim a camera between
  /// frames); the state's time or earlier returns the current position.
  Eigen::Vector2d positionAt(double t) const;

private:
  void start(double t, const Eigen::Vector2d& z, const Eigen::Matrix2d& R);
  void keepSpeedPositive();

  UnicycleTrackerConfig config_;
  TrackGate gate_;
  estimation::UnicycleTrajectoryPredictor predictor_;
  estimation::StateEstimate est_;
  bool valid_ = false;
  std::optional<Eigen::Vector2d> first_;
  double first_t_ = -1.0;
};

}  // namespace viewline::tracking
