// Cartesian robot back ends: stage and vpViper850 arm (IK + joint limits), set-point following
// with latency, limit and workspace accounting.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>

#include "viewline/core/error.h"
#include "viewline/robots/cartesian_robot.h"

using namespace viewline;
using robots::CartesianBackEnd;
using robots::SimulatedCartesianConfig;
using robots::SimulatedCartesianRobot;

namespace {

SimulatedCartesianConfig armConfig() {
  SimulatedCartesianConfig c;
  c.kind = CartesianBackEnd::Arm;
  c.w_M_base.translation() = Eigen::Vector3d(-0.8, 0.0, 0.8);
  // Box front normal (box z) along world +x, box x along world +y.
  c.w_R_box.col(2) = Eigen::Vector3d::UnitX();
  c.w_R_box.col(0) = Eigen::Vector3d::UnitY();
  c.w_R_box.col(1) = c.w_R_box.col(2).cross(c.w_R_box.col(0));
  c.tool_offset = Eigen::Vector3d(0, 0, 0.15);
  return c;
}

}  // namespace

TEST(CartesianRobot, ViperIkRoundTripAndJointLimits) {
  const auto c = armConfig();
  robots::ViperArmKinematics k(c.w_M_base, c.w_R_box, c.tool_offset);
  SimulatedCartesianRobot r(c);
  const auto q0 = r.joints();
  for (double y : {-0.4, 0.0, 0.4})
    for (double z : {0.9, 1.2, 1.5}) {
      const Eigen::Vector3d p(0.0, y, z);
      auto q = k.inverse(p, q0);
      ASSERT_TRUE(q) << y << " " << z;
      const Eigen::Isometry3d M = k.forward(*q);
      EXPECT_LT((M.translation() - p).norm(), 1e-9);
      EXPECT_LT((M.linear() - c.w_R_box).norm(), 1e-9);
      for (int i = 0; i < 6; ++i) {
        EXPECT_GE((*q)(i), k.jointMin()(i));
        EXPECT_LE((*q)(i), k.jointMax()(i));
      }
    }
  // Far outside the Viper850's reach (about 0.85 m from the shoulder): no solution.
  EXPECT_FALSE(k.inverse(Eigen::Vector3d(1.5, 0.0, 1.2), q0));
  EXPECT_FALSE(r.reachable(Eigen::Vector3d(0.0, 2.0, 1.2)));
  EXPECT_TRUE(r.reachable(Eigen::Vector3d(0.0, 0.3, 1.0)));
}

TEST(CartesianRobot, FollowsSetPointsWithLatency) {
  for (auto kind : {CartesianBackEnd::Stage, CartesianBackEnd::Arm}) {
    SimulatedCartesianConfig c = armConfig();
    c.kind = kind;
    c.latency = 0.01;
    SimulatedCartesianRobot r(c);
    r.reset(0.0);
    // A smooth (limit-respecting) sinusoid in y: A w <= 0.5, A w² <= 13.
    const double A = 0.1, w = 4.0;
    for (int k = 0; k <= 500; ++k) {
      const double t = k * 0.004;
      r.command({t, c.home + Eigen::Vector3d(0, A * std::sin(w * t), 0), Eigen::Vector3d(0, A * w * std::cos(w * t), 0)});
    }
    for (double t : {0.1, 0.5, 1.23, 1.9}) {
      const auto s = r.read(t);
      EXPECT_NEAR(s.p.y(), c.home.y() + A * std::sin(w * (t - c.latency)), 1e-6) << toString(kind);
      EXPECT_NEAR(s.v.y(), A * w * std::cos(w * (t - c.latency)), 1e-3) << toString(kind);
    }
    EXPECT_EQ(r.velocityViolations(), 0u);
    EXPECT_EQ(r.accelerationViolations(), 0u);
    EXPECT_EQ(r.refusedSetpoints(), 0u);
    // Before the first set point acts: at home.
    EXPECT_LT((r.read(0.0).p - c.home).norm(), 1e-12);
  }
}

// The same diagonal set-point stream (0.4 m/s on y and z, 0.57 m/s at the tool point) is counted
// as over the limit by a robot limited in Euclidean norm, and is within a per-axis robot's limits.
TEST(CartesianRobot, CountsDiagonalSpeedUnderTheEuclideanNormOnly) {
  for (const auto norm : {robots::LimitNorm::Euclidean, robots::LimitNorm::PerAxis}) {
    SimulatedCartesianConfig c;
    c.limits.norm = norm;
    SimulatedCartesianRobot r(c);
    r.reset(0.0);
    const Eigen::Vector3d v(0.0, 0.4, 0.4);
    for (int k = 1; k <= 10; ++k) {
      const double t = k * 0.004;
      // From rest: 0.4 m/s in 4 ms would be 100 m/s² per axis, so ramp up over 40 ms (10 m/s² per axis).
      const Eigen::Vector3d vk = v * std::min(1.0, k / 10.0);
      r.command({t, c.home + vk * 0.001, vk});
    }
    if (norm == robots::LimitNorm::Euclidean) {
      EXPECT_EQ(r.velocityViolations(), 2u);  // |v| > 0.5 once above 0.354 m/s per axis: the last two
      EXPECT_EQ(r.accelerationViolations(), 10u);  // 14.1 m/s² > 13 at the tool point
      EXPECT_NEAR(r.maxSpeedSeen(), 0.4 * std::sqrt(2.0), 1e-12);
    } else {
      EXPECT_EQ(r.velocityViolations(), 0u);
      EXPECT_EQ(r.accelerationViolations(), 0u);
      EXPECT_NEAR(r.maxSpeedSeen(), 0.4, 1e-12);
    }
  }
}

TEST(CartesianRobot, CountsLimitViolationsAndRefusesOutsideTheWorkspace) {
  SimulatedCartesianConfig c = armConfig();
  SimulatedCartesianRobot r(c);
  r.reset(0.0);
  r.command({0.004, c.home, Eigen::Vector3d(0, 0.6, 0)});  // too fast, and a 150 m/s² step
  EXPECT_EQ(r.velocityViolations(), 1u);
  r.command({0.008, c.home + Eigen::Vector3d(0, 1.0, 0), Eigen::Vector3d::Zero()});  // outside
  EXPECT_EQ(r.refusedSetpoints(), 1u);
  EXPECT_LT((r.read(1.0).p - c.home).norm(), 1e-12);  // held the last valid set point
  EXPECT_THROW(r.command({0.001, c.home, Eigen::Vector3d::Zero()}), core::InvalidInput);
  EXPECT_THROW(r.command({0.01, Eigen::Vector3d(NAN, 0, 0), Eigen::Vector3d::Zero()}), core::InvalidInput);
}

TEST(CartesianRobot, LinderothLimits) {
  const auto l = robots::CartesianLimits::linderoth();
  EXPECT_EQ(l.v_max, Eigen::Vector3d::Constant(0.5));
  EXPECT_EQ(l.a_max, Eigen::Vector3d::Constant(13.0));
  EXPECT_EQ(l.norm, robots::LimitNorm::Euclidean);
  // A diagonal 0.4 m/s on two axes is 0.57 m/s at the tool point: over the Euclidean limit, within
  // the per-axis one.
  EXPECT_FALSE(l.speedWithin(Eigen::Vector3d(0, 0.4, 0.4)));
  EXPECT_TRUE(l.speedWithin(Eigen::Vector3d(0, 0.3, 0.4)));
  EXPECT_FALSE(l.accelerationWithin(Eigen::Vector3d(10, 10, 0)));
  robots::CartesianLimits axis = l;
  axis.norm = robots::LimitNorm::PerAxis;
  EXPECT_TRUE(axis.speedWithin(Eigen::Vector3d(0, 0.4, 0.4)));
  EXPECT_TRUE(axis.accelerationWithin(Eigen::Vector3d(10, 10, 0)));
  EXPECT_FALSE(axis.speedWithin(Eigen::Vector3d(0, 0.51, 0)));
  robots::CartesianLimits uneven = l;
  uneven.v_max.z() = 0.3;  // a Euclidean limit is one number
  EXPECT_THROW(uneven.validate(), core::InvalidInput);
  uneven.norm = robots::LimitNorm::PerAxis;
  EXPECT_NO_THROW(uneven.validate());
  robots::CartesianLimits bad;
  bad.a_max.y() = 0;
  EXPECT_THROW(bad.validate(), core::InvalidInput);
}
