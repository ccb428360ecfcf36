#include "viewline/scenarios/mobile_capture/robot_link.h"

namespace viewline::scenarios::mobile_capture {

bool RobotLink::send(double t, const control::BaseCommand& cmd, const robots::PanTiltJoints& head_target) {
  try {
    faults_.beforeCommand(t);
  } catch (const runtime::InjectedFault& e) {
    faults_.note("robot_commands_failed");
    down_ = true;
    if (e.kind() == runtime::FaultKind::RobotLimitError) {
      robot_.base.setCommand(0.0, 0.0);  // refused: stop the base (a zero command is within every limit)
      faults_.note("robot_halts");
    } else if (!watchdog_noted_ && robot_.base.watchdogStopped()) {
      faults_.note("base_watchdog_stops");  // silent past base.command_timeout: the base brakes by itself
      watchdog_noted_ = true;
    }
    robot_.stepHead(head_);  // the head's servo goes on towards what it last accepted
    return false;
  }
  if (down_) {
    faults_.note("robot_resumed");
    down_ = false;
    watchdog_noted_ = false;
  }
  robot_.stepHead(head_target);
  robot_.base.setCommand(cmd.v, cmd.omega);
  head_ = head_target;
  return true;
}

}  // namespace viewline::scenarios::mobile_capture
