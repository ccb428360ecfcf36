#pragma once
// The ball-catching loop's link to its robot under robot faults (runtime::FaultPlan's
// robot_silent, robot_limit_error): every set point passes the robot injection point; a failed
// command is not taken as sent. While the robot does not answer (or refuses with a limit error)
// it holds its last accepted set point, since a streamed-set-point robot stops where its stream
// stops. When it answers again, the planner's set point is sent only if going there from the
// held set point stays within the robot's limits (mean speed |Δp| / Δt and acceleration
// |Δv| / Δt over the gap, as the robot checks consecutive set points); otherwise the robot is
// halted for the rest of the throw: the planner's profile assumed a robot that followed it, and
// resuming it would command a jump. Without robot faults every set point goes straight through.

#include "viewline/robots/cartesian_robot.h"
#include "viewline/runtime/faults.h"

namespace viewline::scenarios {

/// Streams set points to the robot through the fault plan's robot injection point (header comment).
class RobotGuard {
public:
  /// Guards `robot` (which must outlive it) with `faults` (counts go there).
  RobotGuard(robots::CartesianRobot& robot, runtime::FaultPlan& faults) : robot_(robot), faults_(faults) {}
  /// The set point the robot last accepted (world frame, m and m/s, stamped), e.g. home at the start.
  void reset(const robots::CartesianState& accepted) { last_ = accepted; }
  /// Sends `sp` (world frame, stamped with its issue time), or holds or halts (header comment).
  /// Returns true when the robot received it.
  bool send(const robots::CartesianState& sp);
  /// True once the robot was halted for the rest of the throw.
  bool halted() const { return halted_; }

private:
  robots::CartesianRobot& robot_;
  runtime::FaultPlan& faults_;
  robots::CartesianState last_;  // the last set point the robot accepted
  bool down_ = false;            // the last command failed
  bool halted_ = false;
};

}  // namespace viewline::scenarios
