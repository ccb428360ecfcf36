// Cartesian robot back ends: stage and vpViper850 arm (IK + joint limits), set-point following
// with latency, limit and workspace accounting.
#include <gtest/gtest.h>

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
  robots::CartesianLimits bad;
  bad.a_max.y() = 0;
  EXPECT_THROW(bad.validate(), core::InvalidInput);
}
