#pragma once
// The table-ball loop's link to the wrist that tilts the table, under robot faults
// (runtime::FaultPlan's robot_silent, robot_limit_error). Every physics tick's interpolated
// position command passes the robot's injection point; a failed command is not taken as sent:
//
//  - robot_silent: nothing reaches the wrist; its servo holds the last set point it accepted.
//  - robot_limit_error: the wrist refuses the command and halts, holding its current tilt. The
//    wrist's delay is a transport delay before its servo (robots::TableTilt), so it meets the
//    refused command at t + D, when the last accepted set point (one tick earlier, within the
//    rate limit of it) is where it is: the halt holds that set point too. Counted: robot_halts,
//    one per refused command (as mobile capture counts them).
//  - Both count robot_commands_failed. The loop learns of the failure at once, holds its own
//    command at held() (the wrist's set point), and tells the controller
//    (control::TableBalancer::hold) so that its tilt model, and the table pose the observer
//    predicts from it, follow what the wrist holds.
//  - The first command accepted after a failure is counted robot_resumed. From then until a
//    command passes unchanged, a command farther from the held set point than the wrist's rate
//    limit allows since the previous command (or outside its angle limit) is replaced by the
//    step towards it at the rate limit, counted robot_commands_ramped: the wrist is never
//    commanded outside its limits on resuming, whatever the loop asks (the table-ball loop
//    itself resumes from the held tilt, so it needs none).
//
// Without robot faults every command goes straight to the wrist, unchanged.

#include <Eigen/Core>

#include "viewline/robots/table_tilt.h"
#include "viewline/runtime/faults.h"

namespace viewline::scenarios {

/// Sends the loop's position commands to the wrist through the fault plan (header comment).
class WristLink {
public:
  /// Links `wrist` and `faults` (both must outlive the link; counts go to `faults`). The wrist
  /// is taken to hold `initial_tilt` (θx, θy), rad, until the first accepted command.
  WristLink(robots::TableTilt& wrist, runtime::FaultPlan& faults,
            const Eigen::Vector2d& initial_tilt = Eigen::Vector2d::Zero());
  /// One position command (θx, θy), rad, at time t, s (non-decreasing). Returns true when the
  /// wrist took it; false when it failed (the wrist holds held()).
  bool send(double t, const Eigen::Vector2d& tilt);
  /// The set point the wrist holds: the last command it accepted (θx, θy), rad.
  const Eigen::Vector2d& held() const { return held_; }
  /// The command of the last send() as it went out (a resuming ramp's step, if one replaced
  /// it), accepted or not, rad: what the loop's limit check sees.
  const Eigen::Vector2d& lastCommand() const { return last_cmd_; }
  /// True while the last command failed (the wrist does not take commands).
  bool down() const { return down_; }

private:
  robots::TableTilt& wrist_;
  runtime::FaultPlan& faults_;
  Eigen::Vector2d held_;      // the last accepted set point, rad
  Eigen::Vector2d last_cmd_;  // the last command sent (accepted or not), rad
  double last_t_;             // time of the last send(), s
  bool down_ = false;         // the last command failed
  bool resuming_ = false;     // accepted after a failure, no command passed unchanged since
};

}  // namespace viewline::scenarios
