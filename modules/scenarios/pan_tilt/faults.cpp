#include "viewline/scenarios/pan_tilt/faults.h"

namespace viewline::scenarios::pan_tilt {

std::optional<Eigen::Vector2d> commandThroughFaults(robots::PanTiltUnit& unit, runtime::FaultPlan& faults,
                                                    core::Timestamp t, const Eigen::Vector2d& qdot) {
  try {
    faults.beforeCommand(t);
  } catch (const runtime::InjectedFault& e) {
    faults.note("robot_commands_failed");
    if (e.kind() != runtime::FaultKind::RobotLimitError) return std::nullopt;  // silent: nothing reaches it
    unit.stop(t);
    faults.note("robot_halts");
    return Eigen::Vector2d::Zero();
  }
  unit.commandVelocity(t, qdot);
  return qdot;
}

}  // namespace viewline::scenarios::pan_tilt
