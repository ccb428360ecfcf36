#pragma once
// The pan-tilt loop's command link under robot faults (runtime::FaultPlan's robot_silent,
// robot_limit_error). A command that fails did not reach the unit, so it must not enter the
// commands the law accounts for (the law predicts the joints at the effect time from the commands
// in flight; counting a lost one would mispredict them). A unit that stops answering gets
// nothing: it keeps its last command, which the law already accounted for, and the drive's own
// limits stop it at worst. A unit that refuses a command with a limit error is halted (zero
// velocity, the one command a PTU always takes: FLIR's H), so it no longer moves on an old
// velocity towards a limit.

#include <Eigen/Core>
#include <optional>

#include "viewline/robots/pan_tilt_unit.h"
#include "viewline/runtime/faults.h"

namespace viewline::scenarios::pan_tilt {

/// Sends the joint velocity `qdot` (rad/s) issued at `t` (s) through the robot injection point
/// (header comment). Returns the command the unit received (qdot, or zero after a limit error),
/// nothing when it received none.
std::optional<Eigen::Vector2d> commandThroughFaults(robots::PanTiltUnit& unit, runtime::FaultPlan& faults,
                                                    core::Timestamp t, const Eigen::Vector2d& qdot);

}  // namespace viewline::scenarios::pan_tilt
