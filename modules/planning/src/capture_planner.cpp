#include "viewline/planning/capture_planner.h"

#include <algorithm>
#include <cmath>
#include <limits>

#include "viewline/core/checks.h"
#include "viewline/core/error.h"

namespace viewline::planning {

void CapturePlannerParams::validate() const {
  core::requirePositive(period, "CapturePlannerParams.period");
  core::requirePositive(robot_speed, "CapturePlannerParams.robot_speed");
  core::requireFinite(reach, "CapturePlannerParams.reach");
  if (reach < 0.0) throw core::InvalidInput("CapturePlannerParams.reach: expected >= 0");
  core::requireFinite(turn_rate, "CapturePlannerParams.turn_rate");
  if (turn_rate < 0.0) throw core::InvalidInput("CapturePlannerParams.turn_rate: expected >= 0");
}

double timeToReach(const PlannerRobot& robot, const Eigen::Vector2d& point, const CapturePlannerParams& params) {
  const Eigen::Vector2d d = point - robot.position;
  const double dist = d.norm();
  double turn = 0.0;
  if (params.turn_rate > 0.0 && dist > params.reach) {
    const double err = std::remainder(std::atan2(d.y(), d.x()) - robot.heading, 2.0 * M_PI);
    turn = std::abs(err) / params.turn_rate;
  }
  return turn + std::max(0.0, dist - params.reach) / params.robot_speed;
}

CapturePlan planCapture(const std::vector<Eigen::Vector2d>& predicted, const PlannerRobot& robot,
                        const CapturePlannerParams& params) {
  params.validate();
  if (predicted.empty()) throw core::InvalidInput("planCapture: empty prediction (expected M >= 1 positions)");
  core::requireFinite(robot.position, "planCapture: robot position");
  core::requireFinite(robot.heading, "planCapture: robot heading");
  CapturePlan best;
  double best_shortfall = std::numeric_limits<double>::infinity();
  for (std::size_t i = 0; i < predicted.size(); ++i) {
    core::requireFinite(predicted[i], "planCapture: predicted position");
    const int m = static_cast<int>(i) + 1;
    const double t_obj = m * params.period;
    const double t_robot = timeToReach(robot, predicted[i], params);
    const double shortfall = t_robot - t_obj;
    if (shortfall <= 0.0) {
      return {true, m, t_obj, predicted[i], t_robot};
    }
    if (shortfall < best_shortfall) {
      best_shortfall = shortfall;
      best = {false, m, t_obj, predicted[i], t_robot};
    }
  }
  return best;
}

}  // namespace viewline::planning
