#pragma once
// The rolling-ball track of [M] (Andersen, "Ball on a tilting table", the table-ball observer's
// filter): a ball rolling on a tilting table, seen as its position on the table (table frame,
// metres), driven by the in-plane acceleration measured from the table's tilt.
//
// Per step (time t, measured a_xy = (5/7)[table_R_world g_w]_xy, optional position y):
//  - the model (estimation::RollingBallModel) is rediscretised for the actual interval and a_xy
//    (Φ, Γ, Q by Van Loan), the time update clamps the ball at the borders;
//  - the measurement y goes through the shared track life cycle (tracking::TrackGate): the first
//    one starts the track, later ones are tested on the update's own NIS
//    d = y − C x̂(t|t−), S = C P(t|t−) Cᵀ + σv² I, NIS = dᵀ S⁻¹ d (2 degrees of freedom) and
//    fused when accepted; a restart re-initialises the track from y. The shipped config turns the
//    test off (probability 1: every finite NIS is accepted), as [M]'s filter has no gate;
//  - pushes (ours, beyond [M]): a knock on the ball changes its velocity within one tick, a jump
//    no white acceleration noise of the size that fits the rolling between pushes covers (the
//    filter would lag for half a second, and its NEES explode). The model adds rare velocity
//    jumps Δv ~ N(0, impulse_std² I): when the update's NIS exceeds `impulse_nis` (far in the
//    chi-square tail: a one-frame measurement glitch must not pass for a push), the jump is
//    assumed at a uniform time in the interval, the a-priori covariance grows accordingly
//    (var v += q, cov(p, v) += q dt/2, var p += q dt²/3, q = impulse_std²) and the update is
//    redone (its own NIS is the one reported). impulse_nis = 0 turns it off ([M]);
//  - coloured measurement error (ours): the ball's measured position inherits the table pose's
//    error, which is correlated from frame to frame (about 0.3-0.5 at one frame, gone by five);
//    treated as white it makes the filter average less than it believes (position NEES about
//    1.75 per axis where 1 is expected). With coloured_sigma > 0 the error is modelled as
//    y = p + e + v, e an AR(1) of std coloured_sigma and correlation coloured_correlation per
//    frame (two more states), v white of std σv (Bryson and Johansen, "Linear filtering for
//    time-varying systems using measurements containing colored noise", IEEE TAC 1965: state
//    augmentation). x() and P() stay the ball's six states;
//  - the input over the interval before a frame (input_hold): End holds that frame's measured
//    a_xy over the whole interval (zero-order hold, as [M]); Ramp lets it ramp linearly from the
//    previous frame's a_xy to this frame's (first-order hold, estimation::discretizeFirstOrderHold),
//    which is how a wrist that moves between frames turns the table; predictions then hold the
//    newest a_xy;
//  - or, with `stationary_gain`, the DARE's constant gain for the nominal period ([M]'s option;
//    P(t|t−) is then the DARE's a-priori covariance);
//  - the next N positions are predicted from the filtered state (clamped at the borders).

#include <Eigen/Core>
#include <optional>
#include <cstddef>
#include <vector>

#include "viewline/estimation/kalman_filter.h"
#include "viewline/estimation/models/rolling_ball.h"
#include "viewline/estimation/state.h"
#include "viewline/tracking/track_gate.h"

namespace viewline::tracking {

/// How the measured in-plane acceleration drives the interval before a frame (see the header).
enum class InputHold {
  End,   ///< the frame's own a_xy over the whole interval (zero-order hold)
  Ramp,  ///< a linear ramp from the previous frame's a_xy to this frame's (first-order hold)
};

/// Settings of RollingBallTracker.
struct RollingBallTrackerConfig {
  estimation::RollingBallModel model;  ///< σw, β, σv, table side L, ball radius r, predicted steps N
  bool stationary_gain = false;        ///< use the DARE gain for the nominal frame period
  double nominal_period = 0.02;        ///< s, for the stationary gain
  double initial_velocity_std = 0.5;   ///< m/s, prior on the velocity at the first detection
  /// NIS above which a velocity jump (a push) is assumed and the update redone; 0: never.
  double impulse_nis = 0.0;
  /// m/s, std per axis of an assumed velocity jump (see impulse_nis).
  double impulse_std = 0.2;
  /// m, std σe of a coloured (AR(1)) part of the measurement error, estimated as two extra
  /// states; model.sigma_v is then the white part. 0: white measurement noise only ([M]).
  double coloured_sigma = 0.0;
  /// Correlation φ of that coloured error from one nominal period to the next, in [0, 1).
  double coloured_correlation = 0.5;
  /// The input over each interval: held end value (as [M]) or a ramp between the frames' values.
  InputHold input_hold = InputHold::End;
  /// The measurement gate and restart rule; probability 1 (the default) accepts every finite NIS.
  TrackGateConfig gate{1.0, 3};
  /// Throws core::InvalidInput naming the first bad value.
  void validate() const;
};

/// What one step did with its measurement: the gate's decision and the update's own innovation
/// report (for Start, no innovation: rows = 2, empty innovation).
struct BallUpdate {
  GateDecision decision = GateDecision::Accept;  ///< Start, Accept, Reject or Restart
  estimation::UpdateReport report;               ///< d, S and NIS of the update (2 rows)
};

/// The filter part of the table-ball observer: ball position and velocity on the table.
class RollingBallTracker {
public:
  /// Throws core::InvalidInput when the config is invalid.
  explicit RollingBallTracker(const RollingBallTrackerConfig& config);

  /// Advances to time t (s, increasing) with the measured in-plane acceleration a_xy (m/s², table
  /// frame), fusing the ball position y (table frame, m) when present and accepted by the gate.
  /// Before the first measurement nothing is estimated.
  void step(double t, const Eigen::Vector2d& a_xy, const std::optional<Eigen::Vector2d>& y);

  /// True once a measurement has started the track.
  bool initialized() const { return initialized_; }
  /// State (p_x, v_x, p_y, v_y, w2_x, w2_y) at the last step (m, m/s, m/s²; table frame).
  const Eigen::VectorXd& x() const { return x_; }
  /// Ball position on the table (m, table frame) at the last step.
  Eigen::Vector2d position() const { return {x_[0], x_[2]}; }
  /// Ball velocity on the table (m/s, table frame) at the last step.
  Eigen::Vector2d velocity() const { return {x_[1], x_[3]}; }
  /// Covariance (time-varying filter) or the stationary filtered covariance.
  Eigen::MatrixXd P() const;
  /// The N predicted positions after the last step (one frame interval apart; m, table frame).
  const std::vector<Eigen::Vector2d>& predictions() const { return predictions_; }
  /// NIS of the last fused measurement (0 before any).
  double lastNis() const { return nis_; }
  /// The last step's gate decision and update; empty when that step had no measurement.
  const std::optional<BallUpdate>& lastUpdate() const { return last_update_; }
  /// Updates in which a velocity jump (push) was assumed (see impulse_nis).
  int impulses() const { return impulses_; }
  /// Steps in a row without a fused measurement.
  int missedStreak() const { return missed_; }
  /// The gate's decision counts (starts, accepted, rejected, restarts).
  const GateCounts& gateCounts() const { return gate_.counts(); }
  /// The config the tracker was built with.
  const RollingBallTrackerConfig& config() const { return config_; }

private:
  // Φ, Γ, Q (and the augmented step) for one interval, without its input. Frame stamps k·T in
  // floating point give about a dozen distinct intervals (and their multiples after dropped
  // frames), so each is discretised once: the matrix exponentials were most of a step's cost.
  // Looked up by exact dt, so the numbers are those of discretising every step.
  struct Discretised {
    double dt = 0.0;
    estimation::LinearTransition tr, augmented;
  };
  static constexpr std::size_t kDiscretisedIntervals = 32;
  const Discretised& discretised(double dt);
  void start(double t, const Eigen::Vector2d& a_xy, const Eigen::Vector2d& y, GateDecision why);
  Eigen::Index stateDim() const;  // 6, or 8 with the coloured measurement error
  estimation::LinearTransition augmented(const estimation::LinearTransition& tr) const;
  estimation::LinearMeasurement measurement(const Eigen::Vector2d& y) const;
  void clampState(estimation::StateEstimate& s) const;
  estimation::UpdateReport stationaryInnovation(const estimation::LinearTransition& tr, const Eigen::Vector2d& y) const;
  RollingBallTrackerConfig config_;
  TrackGate gate_;
  bool initialized_ = false;
  double t_ = 0.0;
  double last_dt_ = 0.02;
  Eigen::Vector2d a_prev_ = Eigen::Vector2d::Zero();  // the last step's a_xy (m/s², for the ramp)
  std::vector<Discretised> discretised_;  // by interval, at most kDiscretisedIntervals
  std::size_t next_slot_ = 0;             // the entry replaced next once full
  Eigen::VectorXd x_ = Eigen::VectorXd::Zero(6);
  estimation::StateEstimate state_;
  std::optional<estimation::StationaryFilter> stationary_;
  std::vector<Eigen::Vector2d> predictions_;
  double nis_ = 0.0;
  int missed_ = 0;
  int impulses_ = 0;
  std::optional<BallUpdate> last_update_;
};

}  // namespace viewline::tracking
