#include "viewline/planning/capture_planner.h"

#include <gtest/gtest.h>

#include <cmath>

#include "viewline/core/error.h"

namespace viewline::planning {
namespace {

std::vector<Eigen::Vector2d> straightLine(const Eigen::Vector2d& p0, const Eigen::Vector2d& v, double T, int M) {
  std::vector<Eigen::Vector2d> out;
  for (int m = 1; m <= M; ++m) out.push_back(p0 + v * (m * T));
  return out;
}

TEST(CapturePlanner, HeadOnObjectIsMetHalfWay) {
  // Object 3 m ahead coming at 0.3 m/s, robot 0.3 m/s, no reach: they meet after 5 s at 1.5 m.
  CapturePlannerParams p;
  p.reach = 0.0;
  const auto pred = straightLine({3.0, 0.0}, {-0.3, 0.0}, p.period, 200);
  const CapturePlan plan = planCapture(pred, {}, p);
  ASSERT_TRUE(plan.reachable);
  EXPECT_EQ(plan.steps, 50);
  EXPECT_NEAR(plan.point.x(), 1.5, 1e-9);
  EXPECT_LE(plan.robot_time, plan.time + 1e-12);
}

TEST(CapturePlanner, EarliestReachableStepIsChosen) {
  // Brute force: no earlier step is reachable, and the chosen one is.
  CapturePlannerParams p;
  p.reach = 0.15;
  p.turn_rate = 1.5;
  std::vector<Eigen::Vector2d> pred;
  for (int m = 1; m <= 300; ++m) {
    const double t = m * p.period;
    pred.emplace_back(2.0 + 0.8 * std::cos(0.5 * t), 1.0 + 0.8 * std::sin(0.5 * t));
  }
  const PlannerRobot robot{{-0.5, -0.5}, 2.0};
  const CapturePlan plan = planCapture(pred, robot, p);
  ASSERT_TRUE(plan.reachable);
  for (int m = 1; m < plan.steps; ++m) EXPECT_GT(timeToReach(robot, pred[m - 1], p), m * p.period);
  EXPECT_LE(timeToReach(robot, plan.point, p), plan.time);
}

TEST(CapturePlanner, FasterObjectRunningAwayIsUnreachable) {
  CapturePlannerParams p;
  const auto pred = straightLine({1.0, 0.0}, {0.6, 0.0}, p.period, 100);
  const CapturePlan plan = planCapture(pred, {}, p);
  EXPECT_FALSE(plan.reachable);
  EXPECT_EQ(plan.steps, 1);  // least late where the gap is smallest: now
}

TEST(CapturePlanner, ObjectAlreadyWithinReach) {
  CapturePlannerParams p;
  const CapturePlan plan = planCapture({{0.1, 0.05}}, {}, p);
  EXPECT_TRUE(plan.reachable);
  EXPECT_EQ(plan.steps, 1);
}

TEST(CapturePlanner, RejectsBadInput) {
  CapturePlannerParams p;
  EXPECT_THROW(planCapture({}, {}, p), core::InvalidInput);
  EXPECT_THROW(planCapture({{NAN, 0.0}}, {}, p), core::InvalidInput);
  p.robot_speed = 0.0;
  EXPECT_THROW(planCapture({{1.0, 0.0}}, {}, p), core::InvalidInput);
}

}  // namespace
}  // namespace viewline::planning
