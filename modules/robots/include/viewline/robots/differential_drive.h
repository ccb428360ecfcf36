#pragma once
// Differential-drive base of [K]'s mobile robot (SPEC §4): a unicycle driven by two wheels whose
// speeds are PID-controlled every control period (10 ms), with a speed limit of 30 cm/s.
//
// Kinematics (robot frame r as in mobile_pan_tilt.h: x forward, z up, origin under the axle
// centre). Wheel rim speeds w_l, w_r [m/s], track b:
//     v = (w_r + w_l) / 2,   ω = (w_r - w_l) / b,
//     ẋ = v cos θ,  ẏ = v sin θ,  θ̇ = ω          (ViSP's vpUnicycle / vpSimulatorPioneerPan model;
//                                                  the test checks ours against vpSimulatorPioneerPan)
// integrated exactly (circular arcs) on sub-steps of the control period.
//
// Wheel drive: each motor follows its command u with a first-order lag,
//     ẇ = (u - w) / τ,   |u| <= wheel_speed_max,
// integrated exactly over the control period with u held (zero-order hold). The wheel speed
// controller runs every control period:
//     e = w_ref - w_meas,  u = w_ref + kp e + ki ∫e dt + kd ė      (feed-forward + PID)
// with conditional integration (anti-windup: the integrator freezes while u saturates). The
// encoder measurement w_meas is the true wheel speed plus optional noise.
//
// Commands: setCommand(v, ω) clamps |v| <= max_speed and |ω| <= max_turn_rate; when a wheel
// would exceed wheel_speed_max the turn rate is kept and |v| reduced (turning has priority).

#include <Eigen/Core>

#include "viewline/core/random.h"

namespace viewline::robots {

/// Pose of the mobile base on the floor: position and heading θ from the world x axis.
struct BasePose {
  double x = 0.0,      ///< position x, world frame, m
         y = 0.0,      ///< position y, world frame, m
         theta = 0.0;  ///< heading from the world x axis (counter-clockwise), rad
};

/// Exact unicycle motion over dt with constant (v, ω) (circular arc).
BasePose integrateUnicycle(const BasePose& p, double v, double omega, double dt);

/// Parameters of the differential-drive base: geometry, limits, motor lag and wheel PID ([K]).
struct DifferentialDriveParams {
  double track = 0.30;             ///< b, distance between the wheels, m
  double max_speed = 0.30;         ///< |v| limit, m/s ([K]: 30 cm/s)
  double max_turn_rate = 2.0;      ///< |ω| limit, rad/s
  double wheel_speed_max = 0.45;   ///< rim speed limit of each wheel, m/s
  double motor_time_constant = 0.08;  ///< τ, s
  double control_period = 0.01;    ///< wheel PID period, s ([K]: 10 ms)
  int substeps = 5;                ///< pose integration sub-steps per control period
  double kp = 2.0,                 ///< wheel speed PID proportional gain (on rim speed), 1
         ki = 4.0,                 ///< integral gain, 1/s
         kd = 0.0;                 ///< derivative gain, s
  double encoder_noise = 0.0;      ///< std of the measured wheel speed, m/s
  /// The base's command watchdog: when no setCommand() came for this long, the wheel references
  /// drop to zero and the base brakes by itself, as ROS's diff_drive_controller does after its
  /// cmd_vel_timeout (0.5 s by default there), s; 0: no watchdog (the last command holds).
  double command_timeout = 0.0;

  /// Throws core::InvalidInput naming the field.
  void validate() const;
};

/// Simulated differential-drive base: wheel PID, first-order motors and exact unicycle integration.
class DifferentialDrive {
public:
  /// Base at `start` at rest, time 0 (validates params; throws core::InvalidInput).
  DifferentialDrive(const DifferentialDriveParams& params, const BasePose& start);

  /// Desired body velocities; see the header comment for limits. Feeds the command watchdog.
  void setCommand(double v, double omega);
  /// True when the command watchdog has stopped the base (no command for command_timeout).
  bool watchdogStopped() const { return params_.command_timeout > 0.0 && t_ - last_command_t_ >= params_.command_timeout; }
  /// One control period: PID on both wheels, motors and pose integrated over control_period.
  /// `rng` is used only when encoder_noise > 0.
  void step(core::Rng& rng);

  /// Current true pose on the floor (world frame).
  const BasePose& pose() const { return pose_; }
  /// Current body velocities from the true wheel speeds.
  double speed() const { return 0.5 * (wheel_.x() + wheel_.y()); }
  /// Current turn rate from the true wheel speeds, rad/s.
  double turnRate() const { return (wheel_.y() - wheel_.x()) / params_.track; }
  /// Wheel rim speeds (left, right) and their references.
  const Eigen::Vector2d& wheelSpeeds() const { return wheel_; }
  /// Wheel speed references (left, right) of the PID, m/s.
  const Eigen::Vector2d& wheelReferences() const { return ref_; }
  /// Simulated time, s.
  double time() const { return t_; }
  /// The parameters in use.
  const DifferentialDriveParams& params() const { return params_; }

private:
  DifferentialDriveParams params_;
  BasePose pose_;
  double t_ = 0.0;
  Eigen::Vector2d wheel_ = Eigen::Vector2d::Zero();  ///< true rim speeds (l, r)
  Eigen::Vector2d ref_ = Eigen::Vector2d::Zero();
  Eigen::Vector2d integral_ = Eigen::Vector2d::Zero();
  Eigen::Vector2d last_error_ = Eigen::Vector2d::Zero();
  double last_command_t_ = 0.0;  ///< time of the last setCommand(), s (the watchdog's)
};

/// Rate-limited position servo of the pan/tilt joints (the head's own drive): each control
/// period every joint moves towards its set point by at most rate_max · dt.
struct JointRateLimiter {
  /// Joint position after one period of dt: moves from current towards target by at most rate_max · dt (rad, rad/s, s).
  static double step(double current, double target, double rate_max, double dt);
};

}  // namespace viewline::robots
