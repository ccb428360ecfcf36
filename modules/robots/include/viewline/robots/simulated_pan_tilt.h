#pragma once
// Simulated velocity-controlled pan-tilt unit (default: FLIR PTU-D46-17.5).
//
// Model, per axis, integrated on a fixed sub-step (default 1 ms):
//   * a command c issued at t takes effect at t + latency (pure delay);
//   * the axis velocity v follows the active command with |v̇| <= qddot_max
//     (the drive's acceleration ramp): v ← v + clamp(c − v, −a h, a h);
//   * q ← q + (v_old + v_new) h / 2 (exact for the ramp within a sub-step);
//   * |c| above qdot_max is clipped (and counted as a rate violation);
//   * hard stops: q never leaves [q_min, q_max]; reaching a stop while moving
//     towards it zeroes the velocity and counts a limit hit.
// A well-behaved controller (limitVelocityCommand) produces no rate violation
// and no limit hit; the tests assert both counters stay zero.
//
// The recent state history (history_seconds) is kept so that read(t) for a
// past t (an image's capture time) interpolates it linearly.

#include <deque>
#include <vector>

#include "viewline/robots/pan_tilt_unit.h"

namespace viewline::robots {

/// Parameters of the simulated pan-tilt unit: limits, latency, integration sub-step, history and initial joints.
struct SimulatedPanTiltParams {
  /// Joint, rate and acceleration limits (default: FLIR PTU-D46-17.5)
  PanTiltLimits limits = PanTiltLimits::flirPtuD46();
  double latency = 0.03;          ///< s, command issue -> effect
  double substep = 1e-3;          ///< s
  double history_seconds = 2.0;   ///< s of state kept for read(t) in the past
  Eigen::Vector2d q0 = Eigen::Vector2d::Zero();  ///< initial joints (inside the limits)

  void validate() const;  ///< throws core::InvalidInput naming the field
};

/// Simulated pan-tilt unit: delayed commands, acceleration-limited velocity, hard stops, counted violations.
class SimulatedPanTiltUnit : public PanTiltUnit {
public:
  /// Unit at q0 at rest at time t0 (validates params; throws core::InvalidInput).
  explicit SimulatedPanTiltUnit(const SimulatedPanTiltParams& params = {}, core::Timestamp t0 = 0.0);

  std::string name() const override { return "simulated FLIR PTU-D46-17.5"; }
  const PanTiltLimits& limits() const override { return params_.limits; }
  double commandLatency() const override { return params_.latency; }
  void commandVelocity(core::Timestamp t, const Eigen::Vector2d& qdot) override;
  /// State at t: t <= now interpolates the history (clamped to its oldest entry); t > now
  /// advances the simulation to t first.
  JointState read(core::Timestamp t) override;

  /// Advances the simulation to t (>= now).
  void advanceTo(core::Timestamp t);
  /// Current simulated state (at the simulated time).
  const JointState& now() const { return state_; }

  /// Commands above qdot_max (clipped; tests assert 0).
  std::size_t rateViolations() const { return rate_violations_; }
  /// Times a joint reached a hard stop while moving towards it (tests assert 0).
  std::size_t limitHits() const { return limit_hits_; }
  /// Every command received, with its issue time.
  const std::vector<IssuedCommand>& commands() const { return log_; }
  /// The parameters in use.
  const SimulatedPanTiltParams& params() const { return params_; }

private:
  void step(double h);  // h never crosses a command effect time
  SimulatedPanTiltParams params_;
  JointState state_;
  Eigen::Vector2d active_ = Eigen::Vector2d::Zero();            ///< command in effect
  std::deque<IssuedCommand> pending_;                             ///< (effect time, command)
  std::deque<JointState> history_;
  std::vector<IssuedCommand> log_;
  core::Timestamp last_command_t_ = -1e300;
  std::size_t rate_violations_ = 0, limit_hits_ = 0;
};

}  // namespace viewline::robots
