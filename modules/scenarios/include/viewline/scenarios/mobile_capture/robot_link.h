#pragma once
// The mobile-capture loop's link to its robot (base and head) under robot faults
// (runtime::FaultPlan's robot_silent, robot_limit_error). Every control period's base command and
// head set point pass the robot's injection point; a failed command is not taken as sent:
//
//  - robot_silent: nothing reaches the robot. Its own controllers go on with what they last
//    accepted: the wheel PID with the last (v, ω) until the base's command watchdog
//    (base.command_timeout, DifferentialDriveParams::command_timeout) brakes it to rest, and the
//    head's servo towards its last set point. Counted: robot_commands_failed, and
//    base_watchdog_stops once per silence that outlasts the watchdog.
//  - robot_limit_error: the robot refuses the command and the loop stops the base (a zero
//    command, which a base accepts whatever its limits); the head holds. Counted:
//    robot_commands_failed, robot_halts.
//  - The first command accepted after a failure resumes the loop's laws (robot_resumed). They
//    act on the measured pose and the track, not on what they commanded, so nothing of the
//    failed commands enters them.
//
// The commands themselves are within the robot's limits by construction (goToPoint and the
// search clamp them, DifferentialDrive::setCommand clamps again, the head set point is clamped
// to its joint limits and rate): a fault can only stop or hold the robot, never push it further.
// Without robot faults every command goes straight through, in the order the loop had before.

#include "viewline/control/mobile_capture_control.h"
#include "viewline/runtime/faults.h"
#include "viewline/scenarios/mobile_capture/world.h"

namespace viewline::scenarios::mobile_capture {

/// Sends the loop's commands to the simulated robot through the fault plan (header comment).
class RobotLink {
public:
  /// Links `robot` and `faults` (both must outlive the link; counts go to `faults`).
  RobotLink(RobotSim& robot, runtime::FaultPlan& faults) : robot_(robot), faults_(faults), head_(robot.q) {}
  /// One control period's commands at time t (s): the base's (v, ω) and the head's joint set
  /// point (rad). Steps the head servo (towards this set point, or the last accepted one when
  /// the command failed); the caller steps the base. Returns true when the robot accepted them.
  bool send(double t, const control::BaseCommand& cmd, const robots::PanTiltJoints& head_target);

private:
  RobotSim& robot_;
  runtime::FaultPlan& faults_;
  robots::PanTiltJoints head_;  // the head set point the robot last accepted
  bool down_ = false;           // the last command failed
  bool watchdog_noted_ = false;  // this silence's watchdog stop is counted
};

}  // namespace viewline::scenarios::mobile_capture
