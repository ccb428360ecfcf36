#include "viewline/control/mobile_capture_control.h"

#include <gtest/gtest.h>

#include <cmath>

#include "viewline/core/random.h"

namespace viewline::control {
namespace {

TEST(GoToPoint, ReachesAStaticGoalWithTheDriveInTheLoop) {
  robots::DifferentialDrive base({}, {0.0, 0.0, M_PI});  // goal behind: turns first
  core::Rng rng = core::makeRng(1);
  const Eigen::Vector2d goal(2.0, 1.0);
  GoToPointParams p;
  double t_reach = -1.0;
  for (int i = 0; i < 3000 && t_reach < 0; ++i) {
    const BaseCommand c = goToPoint(base.pose(), goal, p);
    base.setCommand(c.v, c.omega);
    base.step(rng);
    if ((Eigen::Vector2d(base.pose().x, base.pose().y) - goal).norm() < p.stop_distance + 0.02) t_reach = base.time();
  }
  ASSERT_GT(t_reach, 0.0);
  // Straight-line time at 0.3 m/s is 7.45 s plus the half turn; well under 12 s.
  EXPECT_LT(t_reach, 12.0);
}

TEST(GoToPoint, TurnsOnTheSpotWhenTheGoalIsBehind) {
  const BaseCommand c = goToPoint({0, 0, 0}, {-1.0, 0.1}, {});
  EXPECT_NEAR(c.v, 0.0, 1e-12);
  EXPECT_GT(std::abs(c.omega), 1.0);
}

TEST(HeadSetPoint, CentresAGroundTargetAheadOfAMovedBase) {
  const robots::MobilePanTilt head;
  const robots::BasePose pose{1.0, 2.0, 0.8};
  const Eigen::Vector3d target(2.0, 3.5, 0.025);
  double err = -1.0;
  const auto q = headSetPoint(head, pose, target, &err);
  EXPECT_NEAR(err, 0.0, 1e-12);
  const Eigen::Isometry3d c_M_w = robots::headCamera_c_M_w(head, q, pose.x, pose.y, pose.theta);
  const Eigen::Vector3d p_c = c_M_w * target;
  EXPECT_LT(std::hypot(p_c.x(), p_c.y()) / p_c.z(), 1e-9);
}

TEST(SearchPattern, ModesAndSweepStayWithinLimits) {
  const SearchPattern s;
  EXPECT_EQ(s.mode(1.0, 0.9), SearchMode::Tracking);
  EXPECT_EQ(s.mode(1.0, 0.5), SearchMode::Lost);
  EXPECT_EQ(s.mode(5.0, 0.5), SearchMode::Sweeping);
  EXPECT_EQ(s.mode(0.0, -1.0), SearchMode::Sweeping);
  const robots::MobilePanTilt head;
  double lo = 1e9, hi = -1e9;
  for (double t = 0; t < 3.0; t += 0.05) {
    const auto q = s.sweep(head, t, 0.0, 0.2);
    EXPECT_TRUE(head.withinLimits(q));
    lo = std::min(lo, q.pan);
    hi = std::max(hi, q.pan);
  }
  EXPECT_GT(hi - lo, 0.8);  // the sweep covers about twice its amplitude
  EXPECT_GT(s.baseWhileSearching(1.0, true).omega, 0.0);
  EXPECT_LT(s.baseWhileSearching(-1.0, true).omega, 0.0);
}

}  // namespace
}  // namespace viewline::control
