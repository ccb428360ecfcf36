#include "viewline/robots/table_tilt.h"

#include <gtest/gtest.h>

#include "viewline/core/error.h"

using viewline::robots::SimulatedTableTilt;
using viewline::robots::TableTiltLimits;

namespace {
TableTiltLimits limits(double angle, double rate, double delay) {
  TableTiltLimits l;
  l.max_angle = angle;
  l.max_rate = rate;
  l.delay = delay;
  return l;
}
}  // namespace

TEST(TableTilt, DelayThenSlewAtRateLimit) {
  SimulatedTableTilt wrist(limits(0.3, 1.0, 0.05));
  wrist.command(0.0, Eigen::Vector2d(0.1, -0.02));
  // Nothing moves during the delay.
  EXPECT_NEAR(wrist.actual(0.049).norm(), 0.0, 1e-15);
  // Then each axis slews at 1 rad/s until it reaches its target.
  const Eigen::Vector2d a = wrist.actual(0.06);
  EXPECT_NEAR(a.x(), 0.01, 1e-12);
  EXPECT_NEAR(a.y(), -0.01, 1e-12);
  const Eigen::Vector2d b = wrist.actual(0.08);
  EXPECT_NEAR(b.x(), 0.03, 1e-12);
  EXPECT_NEAR(b.y(), -0.02, 1e-12);  // reached, stays
  EXPECT_NEAR(wrist.actual(1.0).x(), 0.1, 1e-12);
}

TEST(TableTilt, AngleLimitClampsTargets) {
  SimulatedTableTilt wrist(limits(0.2, 10.0, 0.0));
  wrist.command(0.0, Eigen::Vector2d(1.0, -5.0));
  const Eigen::Vector2d a = wrist.actual(2.0);
  EXPECT_NEAR(a.x(), 0.2, 1e-12);
  EXPECT_NEAR(a.y(), -0.2, 1e-12);
  EXPECT_TRUE(wrist.limits().withinAngle(a));
}

TEST(TableTilt, CommandsActInOrderAtTheirActivationTime) {
  SimulatedTableTilt wrist(limits(0.3, 1.0, 0.02));
  wrist.command(0.0, Eigen::Vector2d(0.1, 0.0));
  wrist.command(0.03, Eigen::Vector2d(0.0, 0.0));  // acts at 0.05
  EXPECT_NEAR(wrist.actual(0.05).x(), 0.03, 1e-12);  // slewed 0.02..0.05
  EXPECT_NEAR(wrist.actual(0.06).x(), 0.02, 1e-12);  // now back down
  EXPECT_NEAR(wrist.actual(0.2).x(), 0.0, 1e-12);
}

TEST(TableTilt, RejectsCommandsThatWouldChangeThePast) {
  SimulatedTableTilt wrist(limits(0.3, 1.0, 0.02));
  wrist.actual(0.5);
  EXPECT_THROW(wrist.command(0.4, Eigen::Vector2d(0.1, 0.0)), viewline::core::InvalidInput);
  EXPECT_NO_THROW(wrist.command(0.49, Eigen::Vector2d(0.1, 0.0)));
  EXPECT_THROW(wrist.command(0.485, Eigen::Vector2d(0.1, 0.0)), viewline::core::InvalidInput);  // backwards
  EXPECT_THROW(wrist.actual(0.4), viewline::core::InvalidInput);
}

TEST(TableTilt, RejectsBadLimits) {
  EXPECT_THROW(SimulatedTableTilt(limits(0.0, 1.0, 0.0)), viewline::core::InvalidInput);
  EXPECT_THROW(SimulatedTableTilt(limits(0.3, -1.0, 0.0)), viewline::core::InvalidInput);
  EXPECT_THROW(SimulatedTableTilt(limits(0.3, 1.0, -0.1)), viewline::core::InvalidInput);
  EXPECT_THROW(SimulatedTableTilt(limits(0.3, 1.0, 0.0), Eigen::Vector2d(0.5, 0.0)), viewline::core::InvalidInput);
}
