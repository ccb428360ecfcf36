#pragma once
// The arm-held table of the table-ball scenario ([M], SPEC §3) as an actuated two-angle tilt.
//
// Tilt angles (rad): tilt = (θx, θy), the table frame being w_M_table = w_M_base · Rx(θx) · Ry(θy)
// (the same convention as sim::TiltTable). The arm's wrist realises a commanded tilt with
//   * a pure delay D: a command issued at t starts acting at t + D;
//   * a rate limit: each angle moves towards its active target at most at `max_rate` (rad/s);
//   * an angle limit: targets are clamped to |θ| <= max_angle.
// So with targets c(t) (the last command issued before t - D, clamped), the actual tilt obeys
//   θ̇_i = clamp((c_i - θ_i) / 0⁺, -max_rate, max_rate)   per axis,
// i.e. it slews at the rate limit until it reaches the target and then stays on it. The
// simulated back end integrates this exactly (piecewise-linear motion between command
// activations), so querying the tilt at any time is exact and costs nothing.
//
// Interface: command(t, tilt) at non-decreasing times; actual(t) at non-decreasing times. A
// command may not change the past: t + D must not precede the latest time already queried
// (throws core::InvalidInput), which keeps a closed loop causal.

#include <Eigen/Core>
#include <deque>
#include <utility>

namespace viewline::robots {

/// Limits of the table's wrist: angle, rate and actuator delay.
struct TableTiltLimits {
  double max_angle = 0.35;  ///< |θ| limit per axis, rad (> 0)
  double max_rate = 1.5;    ///< |θ̇| limit per axis, rad/s (> 0)
  double delay = 0.02;      ///< actuator delay between a command and the start of motion, s (>= 0)

  /// Throws core::InvalidInput naming the field.
  void validate() const;
  /// The tilt clamped to ±max_angle per axis.
  Eigen::Vector2d clampAngle(const Eigen::Vector2d& tilt) const;
  /// True when |θ_i| <= max_angle (+ tol) on both axes.
  bool withinAngle(const Eigen::Vector2d& tilt, double tol = 1e-12) const;
};

/// A two-angle tilting table, whatever drives it (simulated wrist or a real arm).
class TableTilt {
public:
  virtual ~TableTilt() = default;
  /// Commands the tilt (rad) at time t (s); t must not decrease between calls.
  virtual void command(double t, const Eigen::Vector2d& tilt) = 0;
  /// The actual tilt at time t (s); t must not decrease between calls.
  virtual Eigen::Vector2d actual(double t) = 0;
  /// The wrist's limits (controllers ask the table, their owner).
  virtual const TableTiltLimits& limits() const = 0;
};

/// Exact simulation of the delayed, rate- and angle-limited wrist.
class SimulatedTableTilt : public TableTilt {
public:
  /// Throws core::InvalidInput for bad limits or a non-finite / out-of-limit initial tilt.
  explicit SimulatedTableTilt(const TableTiltLimits& limits, const Eigen::Vector2d& initial_tilt = Eigen::Vector2d::Zero(),
                              double t0 = 0.0);

  void command(double t, const Eigen::Vector2d& tilt) override;
  Eigen::Vector2d actual(double t) override;
  const TableTiltLimits& limits() const override { return limits_; }

  /// The target the wrist is currently slewing to (clamped), as of the last actual() query.
  const Eigen::Vector2d& activeTarget() const { return target_; }
  /// Time of the last actual() query.
  double time() const { return t_; }

private:
  void slew(double t);  ///< move from t_ to t towards target_ at the rate limit
  TableTiltLimits limits_;
  Eigen::Vector2d tilt_;
  Eigen::Vector2d target_;
  double t_;
  double last_command_t_;
  std::deque<std::pair<double, Eigen::Vector2d>> pending_;  ///< (activation time, clamped target)
};

}  // namespace viewline::robots
