#include "viewline/scenarios/table_ball/wrist_link.h"

#include <algorithm>
#include <cmath>
#include <limits>

namespace viewline::scenarios {

WristLink::WristLink(robots::TableTilt& wrist, runtime::FaultPlan& faults, const Eigen::Vector2d& initial_tilt)
    : wrist_(wrist), faults_(faults), held_(initial_tilt), last_cmd_(initial_tilt),
      last_t_(std::numeric_limits<double>::quiet_NaN()) {}

bool WristLink::send(double t, const Eigen::Vector2d& tilt) {
  const double dt = std::isfinite(last_t_) ? std::max(t - last_t_, 0.0) : 0.0;
  last_t_ = t;
  last_cmd_ = tilt;
  try {
    faults_.beforeCommand(t);
  } catch (const runtime::InjectedFault& e) {
    faults_.note("robot_commands_failed");
    if (e.kind() == runtime::FaultKind::RobotLimitError) faults_.note("robot_halts");  // it halts where it is
    down_ = true;
    return false;
  }
  if (down_) {
    faults_.note("robot_resumed");
    down_ = false;
    resuming_ = true;
  }
  if (resuming_) {
    // Back from an outage: the wrist's set point has been held_ up to the previous command, so
    // the step to this one is taken from there and checked with the wrist's own limits (the
    // relative tolerance of the loop's limit check).
    const robots::TableTiltLimits& lim = wrist_.limits();
    const double max_step = lim.max_rate * dt;
    const Eigen::Vector2d step = tilt - held_;
    if (step.cwiseAbs().maxCoeff() > max_step * (1.0 + 1e-9) + 1e-12 || !lim.withinAngle(tilt)) {
      last_cmd_ = lim.clampAngle(held_ + step.cwiseMax(-max_step).cwiseMin(max_step));
      faults_.note("robot_commands_ramped");
    } else {
      resuming_ = false;
    }
  }
  wrist_.command(t, last_cmd_);
  held_ = last_cmd_;
  return true;
}

}  // namespace viewline::scenarios
