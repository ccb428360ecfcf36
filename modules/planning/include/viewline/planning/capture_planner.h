#pragma once
// Shortest-time capture point of a moving ground object by a mobile robot, [K] eq 30 (SPEC §4).
//
// Input: the object's predicted positions p(k+m), m = 1..M, one every period T (from the
// least-squares trajectory predictor, estimation/models/unicycle_predictor.h, or the true future
// path for the oracle), and the robot's pose. For each m the robot is assumed to head straight
// for p(k+m) at full speed v_max; it gets there (object within the gripper reach `reach`,
// measured from the axle centre) after
//     τ(m) = τ_turn + max(0, |p(k+m) - p_r| - reach) / v_max,
//     τ_turn = |heading error| / turn_rate   (0 when turn_rate = 0, as in [K])
// The capture point is p(k+m*) with the earliest m* such that τ(m*) <= m* T: the first predicted
// position the robot can reach no later than the object (shortest-time capture). Replanned every
// cycle. When no m <= M works, the plan is the m with the smallest shortfall τ(m) - mT (the
// robot then heads where it is least late) and `reachable` is false.

#include <Eigen/Core>
#include <vector>

namespace viewline::planning {

/// Parameters of the shortest-time capture planner ([K] eq 30).
struct CapturePlannerParams {
  double period = 0.1;      ///< T, s between predictions
  double robot_speed = 0.3; ///< v_max, m/s
  double reach = 0.2;       ///< gripper reach from the axle centre, m
  double turn_rate = 0.0;   ///< rad/s used to charge the initial turn (0: none, [K])

  /// Throws core::InvalidInput naming the field.
  void validate() const;
};

/// Result of planCapture(): where and when the robot meets the object.
struct CapturePlan {
  bool reachable = false;  ///< true when the robot reaches p(k+m*) no later than the object (else the least-late point)
  int steps = 0;                          ///< m* (1-based)
  double time = 0.0;                      ///< m* T, s from now
  Eigen::Vector2d point = Eigen::Vector2d::Zero();  ///< capture point p(k+m*)
  double robot_time = 0.0;                ///< τ(m*)
};

/// Robot pose on the floor for planning: position (m) and heading (rad).
struct PlannerRobot {
  Eigen::Vector2d position = Eigen::Vector2d::Zero();  ///< axle-centre position on the floor (world frame), m
  double heading = 0.0;  ///< heading in the floor plane from the world x axis, rad
};

/// Time the robot needs to get the point within reach (τ above).
double timeToReach(const PlannerRobot& robot, const Eigen::Vector2d& point, const CapturePlannerParams& params);

/// [K] eq 30 over predicted[0..M-1] = p(k+1..k+M). Throws for an empty prediction or NaN input.
CapturePlan planCapture(const std::vector<Eigen::Vector2d>& predicted, const PlannerRobot& robot,
                        const CapturePlannerParams& params);

}  // namespace viewline::planning
