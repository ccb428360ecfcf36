#pragma once
// A velocity-controlled pan-tilt unit (PTU): one interface for the simulated
// back end (simulated_pan_tilt.h) and the hardware back ends
// (pan_tilt_hardware.h, compiled only where ViSP has the drivers).
//
// Joints q = (pan, tilt) in rad, joint velocities q̇ in rad/s. Conventions are
// those of ViSP's vpPtu46 (see pan_tilt_kinematics.h): base frame f with x
// forward, y left, z up; positive pan turns the optical axis towards +y_f
// (left), positive tilt turns it up.
//
// Commands are joint velocities stamped with their issue time t; a real unit
// applies them after a command latency (serial link + drive). Commands must
// respect the joint and rate limits: limitVelocityCommand() below makes any
// desired velocity safe, and the simulated unit counts every command that is
// not (the tests assert that none is).

#include <Eigen/Core>
#include <string>
#include <vector>

#include "viewline/core/time.h"

namespace viewline::robots {

/// Joint and rate limits of a pan-tilt unit (rad, rad/s, rad/s²).
struct PanTiltLimits {
  Eigen::Vector2d q_min = Eigen::Vector2d::Zero();  ///< lower joint limits (pan, tilt), rad
  Eigen::Vector2d q_max = Eigen::Vector2d::Zero();  ///< upper joint limits (pan, tilt), rad
  Eigen::Vector2d qdot_max = Eigen::Vector2d::Zero();   ///< |q̇| per axis
  Eigen::Vector2d qddot_max = Eigen::Vector2d::Zero();  ///< |q̈| per axis (the drive's acceleration)

  /// FLIR PTU-D46-17.5: pan ±150°, tilt −47°..+31°, 300°/s on both axes; the acceleration is
  /// configurable on the drive, we default to 1200°/s² (an assumption, set it in the config).
  static PanTiltLimits flirPtuD46();
  /// Throws core::InvalidInput naming the field (q_min < q_max, positive rates, finite).
  void validate() const;
};

/// Joint positions and velocities at time t.
struct JointState {
  core::Timestamp t = 0.0;  ///< time of the state, s
  Eigen::Vector2d q = Eigen::Vector2d::Zero();  ///< joint positions (pan, tilt), rad
  Eigen::Vector2d qdot = Eigen::Vector2d::Zero();  ///< joint velocities (pan, tilt), rad/s
};

/// A velocity-controlled pan-tilt unit (simulated or hardware); joints q = (pan, tilt), vpPtu46 conventions.
class PanTiltUnit {
public:
  virtual ~PanTiltUnit() = default;
  /// Short name for logs and summaries.
  virtual std::string name() const = 0;
  /// The unit's joint and rate limits (controllers ask the unit, their owner).
  virtual const PanTiltLimits& limits() const = 0;
  /// Nominal delay between a command's issue and its effect (s).
  virtual double commandLatency() const = 0;
  /// Joint velocity command (rad/s) issued at time t (s). Throws core::InvalidInput for NaN or
  /// a time before the previous command.
  virtual void commandVelocity(core::Timestamp t, const Eigen::Vector2d& qdot) = 0;
  /// Joint state at time t (simulation: any t up to the simulated time; hardware: now).
  virtual JointState read(core::Timestamp t) = 0;
  /// Zero velocity.
  virtual void stop(core::Timestamp t) { commandVelocity(t, Eigen::Vector2d::Zero()); }
};

/// A velocity command as issued (issue time t, before the latency).
struct IssuedCommand {
  core::Timestamp t = 0.0;  ///< issue time, s
  Eigen::Vector2d qdot = Eigen::Vector2d::Zero();  ///< commanded joint velocities (pan, tilt), rad/s
};

/// Predicts the joint state at time t (>= now.t) from the state `now`, the commands issued
/// recently (any order is not allowed: increasing issue times) and the command latency, with the
/// drive model of the simulated unit: the command issued at t_i acts from t_i + latency on, the
/// velocity ramps towards the active command at qddot_max, positions are clamped to the limits.
/// The command active at now.t is the last one with t_i + latency <= now.t (if none, the current
/// velocity is assumed to be commanded). Integrates on `substep` (s) and at command switches.
JointState predictJointState(const PanTiltLimits& limits, const JointState& now,
                             const std::vector<IssuedCommand>& recent, double latency, core::Timestamp t,
                             double substep = 1e-3);

/// Makes a desired joint velocity safe to command, axis by axis:
///  1. |q̇| <= qdot_max;
///  2. joint limits with braking. From the predicted state at the command's effect time
///     (position q_e, velocity v_e: where the joints will be when it takes effect), the axis
///     ramps at qddot_max from v_e to the command v, holds it until `hold` seconds have passed,
///     then brakes to rest at qddot_max. The whole excursion of that velocity profile must stay
///     within [q_min + margin, q_max − margin]. The excursion grows monotonically with v, so the
///     largest admissible v towards a limit is found by bisection.
///     Moving away from a limit is always allowed; when even braking at once cannot avoid the
///     margin (v_e already too large), the command towards that limit becomes 0.
/// Returns the limited velocity (never larger in magnitude than the input, same sign or 0).
Eigen::Vector2d limitVelocityCommand(const PanTiltLimits& limits, const Eigen::Vector2d& q_e,
                                     const Eigen::Vector2d& v_e, const Eigen::Vector2d& qdot_desired,
                                     double hold, double margin);

/// Extremes (min, max) of the displacement of one axis that starts at velocity v_e, ramps at
/// `a` to v, holds v until `hold` seconds have passed (the ramp counts), then brakes to rest.
Eigen::Vector2d excursion(double v_e, double v, double hold, double a);

/// True when a command respects the rate limit and the braking condition above (margin 0),
/// with tolerance `tol` (rad, rad/s).
bool isSafeCommand(const PanTiltLimits& limits, const Eigen::Vector2d& q_e, const Eigen::Vector2d& v_e,
                   const Eigen::Vector2d& qdot, double hold, double tol = 1e-9);

}  // namespace viewline::robots
