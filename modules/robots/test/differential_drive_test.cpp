#include "viewline/robots/differential_drive.h"

#include <gtest/gtest.h>

#include <cmath>
#include <visp3/robot/vpSimulatorPioneerPan.h>

#include "viewline/core/error.h"

namespace viewline::robots {
namespace {

TEST(DifferentialDrive, UnicycleMatchesViSPsPioneerSimulator) {
  // ViSP's vpSimulatorPioneerPan integrates (v, ω) with Euler steps of its sampling time; with a
  // 1 ms step it must agree with our exact arcs to well under a millimetre over 5 s.
  vpSimulatorPioneerPan robot;
  robot.setSamplingTime(0.001);
  robot.setMaxTranslationVelocity(1.0);
  robot.setMaxRotationVelocity(3.0);
  robot.setRobotState(vpRobot::STATE_VELOCITY_CONTROL);
  vpHomogeneousMatrix w_M_c0;
  robot.getPosition(w_M_c0);  // platform at the origin, pan at 0: fixes m_M_c
  BasePose ours;
  vpColVector vel(3, 0.0);
  for (int i = 0; i < 5000; ++i) {
    const double t = i * 0.001;
    vel[0] = 0.25 + 0.05 * std::sin(t);
    vel[1] = 0.8 * std::cos(0.7 * t);
    robot.setVelocity(vpRobot::ARTICULAR_FRAME, vel);
    ours = integrateUnicycle(ours, vel[0], vel[1], 0.001);
  }
  vpHomogeneousMatrix w_M_c;
  robot.getPosition(w_M_c);
  const vpHomogeneousMatrix w_M_m = w_M_c * w_M_c0.inverse();  // platform pose (pan kept at 0)
  EXPECT_NEAR(w_M_m[0][3], ours.x, 1e-3);
  EXPECT_NEAR(w_M_m[1][3], ours.y, 1e-3);
  EXPECT_NEAR(std::remainder(std::atan2(w_M_m[1][0], w_M_m[0][0]) - ours.theta, 2 * M_PI), 0.0, 1e-3);
}

TEST(DifferentialDrive, WheelPidTracksASpeedStepWithoutSteadyStateError) {
  DifferentialDriveParams p;
  DifferentialDrive base(p, {});
  core::Rng rng = core::makeRng(1);
  base.setCommand(0.3, 0.0);
  double peak = 0.0, t_reach = -1.0;
  for (int i = 0; i < 300; ++i) {
    base.step(rng);
    peak = std::max(peak, base.speed());
    if (t_reach < 0 && base.speed() > 0.95 * 0.3) t_reach = base.time();
  }
  EXPECT_GT(t_reach, 0.0);
  EXPECT_LT(t_reach, 0.5);
  EXPECT_LT(peak, 0.3 * 1.05);
  EXPECT_NEAR(base.speed(), 0.3, 1e-3);
  EXPECT_NEAR(base.pose().y, 0.0, 1e-12);
  EXPECT_GT(base.pose().x, 0.7);
}

TEST(DifferentialDrive, SpeedLimitAndTurningPriority) {
  DifferentialDriveParams p;
  DifferentialDrive base(p, {});
  core::Rng rng = core::makeRng(2);
  base.setCommand(5.0, 0.0);
  for (int i = 0; i < 300; ++i) {
    base.step(rng);
    EXPECT_LE(base.speed(), p.max_speed * 1.01);  // up to the PI loop's transient overshoot (< 1%)
  }
  base.setCommand(0.3, 2.0);  // wheel limit 0.45: ω = 2 needs ±0.3 → v reduced to 0.15
  EXPECT_LE(base.wheelReferences().cwiseAbs().maxCoeff(), p.wheel_speed_max + 1e-12);
  EXPECT_NEAR(base.wheelReferences().y() - base.wheelReferences().x(), 2.0 * p.track, 1e-12);
  for (int i = 0; i < 300; ++i) base.step(rng);
  EXPECT_NEAR(base.turnRate(), 2.0, 1e-2);
  EXPECT_NEAR(base.speed(), 0.15, 1e-2);
}

TEST(DifferentialDrive, TheCommandWatchdogBrakesToRestWhenCommandsStop) {
  DifferentialDriveParams p;
  p.command_timeout = 0.5;
  DifferentialDrive base(p, {});
  core::Rng rng = core::makeRng(3);
  base.setCommand(0.3, 0.0);
  for (int i = 0; i < 49; ++i) base.step(rng);  // 0.49 s: still the command
  EXPECT_FALSE(base.watchdogStopped());
  EXPECT_NEAR(base.speed(), 0.3, 0.01);
  for (int i = 0; i < 51; ++i) base.step(rng);  // past 0.5 s without a command
  EXPECT_TRUE(base.watchdogStopped());
  EXPECT_NEAR(base.wheelReferences().norm(), 0.0, 0.0);
  for (int i = 0; i < 100; ++i) base.step(rng);
  EXPECT_LT(std::abs(base.speed()), 1e-3);
  base.setCommand(0.2, 0.0);  // a command re-arms it
  EXPECT_FALSE(base.watchdogStopped());
  // Without a watchdog (the default) the last command holds.
  DifferentialDrive hold(DifferentialDriveParams{}, {});
  hold.setCommand(0.3, 0.0);
  for (int i = 0; i < 300; ++i) hold.step(rng);
  EXPECT_FALSE(hold.watchdogStopped());
  EXPECT_NEAR(hold.speed(), 0.3, 1e-3);
}

TEST(DifferentialDrive, RejectsBadParameters) {
  DifferentialDriveParams p;
  p.track = 0.0;
  EXPECT_THROW(DifferentialDrive(p, {}), core::InvalidInput);
  p = {};
  p.wheel_speed_max = 0.1;
  EXPECT_THROW(DifferentialDrive(p, {}), core::InvalidInput);
  p = {};
  p.command_timeout = -0.1;
  EXPECT_THROW(DifferentialDrive(p, {}), core::InvalidInput);
  DifferentialDrive ok({}, {});
  EXPECT_THROW(ok.setCommand(NAN, 0.0), core::InvalidInput);
}

TEST(JointRateLimiter, MovesAtMostTheRateLimit) {
  EXPECT_DOUBLE_EQ(JointRateLimiter::step(0.0, 1.0, 2.0, 0.01), 0.02);
  EXPECT_DOUBLE_EQ(JointRateLimiter::step(0.0, -0.005, 2.0, 0.01), -0.005);
}

}  // namespace
}  // namespace viewline::robots
