#include "viewline/scenarios/ball_catching/robot_guard.h"

namespace viewline::scenarios {

bool RobotGuard::send(const robots::CartesianState& sp) {
  if (halted_) return false;
  try {
    faults_.beforeCommand(sp.t);
  } catch (const runtime::InjectedFault&) {
    faults_.note("robot_commands_failed");
    down_ = true;
    return false;
  }
  if (down_) {
    down_ = false;
    // Back from an outage: the jump from the held set point to the plan's, checked with the
    // robot's own limits (relative tolerance as its set-point check).
    const double dt = sp.t - last_.t;
    const robots::CartesianLimits& lim = robot_.limits();
    const bool within = dt > 0.0 && lim.speedWithin((sp.p - last_.p) / dt, 1e-6) &&
                        lim.accelerationWithin((sp.v - last_.v) / dt, 1e-6) && lim.speedWithin(sp.v, 1e-6);
    if (!within) {
      halted_ = true;
      faults_.note("robot_halts");
      return false;
    }
    faults_.note("robot_resumed");
  }
  robot_.command(sp);
  last_ = sp;
  return true;
}

}  // namespace viewline::scenarios
