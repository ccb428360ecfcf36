#include <gtest/gtest.h>

#include <cmath>
#include <deque>
#include <visp3/core/vpExponentialMap.h>

#include "viewline/core/error.h"
#include "viewline/core/frames.h"
#include "viewline/core/random.h"
#include "viewline/robots/pan_tilt_hardware.h"
#include "viewline/robots/pan_tilt_kinematics.h"
#include "viewline/robots/simulated_pan_tilt.h"

using namespace viewline;
using robots::PanTiltKinematics;
using robots::PanTiltLimits;
using robots::SimulatedPanTiltParams;
using robots::SimulatedPanTiltUnit;

TEST(PanTiltKinematics, JacobianMatchesDerivativeOfPose) {
  PanTiltKinematics k;
  core::Rng rng = core::makeRng(3);
  for (int trial = 0; trial < 20; ++trial) {
    const Eigen::Vector2d q(core::uniform(rng, -2.5, 2.5), core::uniform(rng, -0.8, 0.5));
    const Eigen::Vector2d qd(core::uniform(rng, -1, 1), core::uniform(rng, -1, 1));
    const double h = 1e-6;
    const vpHomogeneousMatrix c0_M_c1 = k.f_M_c(q).inverse() * k.f_M_c(q + h * qd);
    const vpColVector v_fd = vpExponentialMap::inverse(c0_M_c1, h);
    vpColVector qdv(2);
    qdv[0] = qd(0);
    qdv[1] = qd(1);
    const vpColVector v = k.cVe() * k.eJe(q) * qdv;
    for (unsigned i = 0; i < 6; ++i) EXPECT_NEAR(v[i], v_fd[i], 1e-5) << "component " << i;
  }
}

TEST(PanTiltKinematics, OtherCameraMount) {
  // The nominal mount reproduces vpPtu46's chain exactly.
  const PanTiltKinematics nominal;
  const PanTiltKinematics same(PanTiltKinematics::nominalEyeInHand());
  const Eigen::Vector2d q0(0.3, -0.2);
  EXPECT_LT((nominal.c_M_f(q0).matrix() - same.c_M_f(q0).matrix()).cwiseAbs().maxCoeff(), 1e-12);
  // A camera mounted with errors (translation and a few tenths of a degree, as calib/rigs/pan_tilt):
  // f_M_c = f_M_e e_M_c, and cVe eJe still gives the camera twist.
  Eigen::Isometry3d e_M_c = PanTiltKinematics::nominalEyeInHand();
  e_M_c.translation() += Eigen::Vector3d(0.002, 0.0025, 0.0035);
  e_M_c.linear() = e_M_c.linear() * Eigen::AngleAxisd(0.012, Eigen::Vector3d(0.6, -0.5, 0.62).normalized()).toRotationMatrix();
  const PanTiltKinematics k(e_M_c);
  const Eigen::Isometry3d f_M_e = nominal.c_M_f(q0).inverse() * PanTiltKinematics::nominalEyeInHand().inverse();
  EXPECT_LT(((f_M_e * e_M_c).matrix() - k.c_M_f(q0).inverse().matrix()).cwiseAbs().maxCoeff(), 1e-12);
  EXPECT_GT((k.c_M_f(q0).matrix() - nominal.c_M_f(q0).matrix()).cwiseAbs().maxCoeff(), 1e-3);
  core::Rng rng = core::makeRng(4);
  for (int trial = 0; trial < 10; ++trial) {
    const Eigen::Vector2d q(core::uniform(rng, -2.5, 2.5), core::uniform(rng, -0.8, 0.5));
    const Eigen::Vector2d qd(core::uniform(rng, -1, 1), core::uniform(rng, -1, 1));
    const double h = 1e-6;
    const vpColVector v_fd = vpExponentialMap::inverse(k.f_M_c(q).inverse() * k.f_M_c(q + h * qd), h);
    vpColVector qdv(2);
    qdv[0] = qd(0);
    qdv[1] = qd(1);
    const vpColVector v = k.cVe() * k.eJe(q) * qdv;
    for (unsigned i = 0; i < 6; ++i) EXPECT_NEAR(v[i], v_fd[i], 1e-5) << "component " << i;
  }
  // pointAt uses the mount: the point lands on this camera's optical axis.
  const Eigen::Vector3d p(1.3, 0.2, -0.3);
  const Eigen::Vector3d s = k.project(k.pointAt(p), p);
  EXPECT_NEAR(s.x(), 0.0, 1e-10);
  EXPECT_NEAR(s.y(), 0.0, 1e-10);
  EXPECT_GT(std::abs(nominal.project(k.pointAt(p), p).x()), 1e-4);
}

TEST(PanTiltKinematics, ConventionsAndPointAt) {
  PanTiltKinematics k;
  // q = 0 looks along +x_f; image y is down (−z_f).
  const vpHomogeneousMatrix fMc = k.f_M_c(Eigen::Vector2d::Zero());
  EXPECT_NEAR(fMc[0][2], 1.0, 1e-12);
  EXPECT_NEAR(fMc[2][1], -1.0, 1e-12);
  // A point to the left and below: positive pan, negative tilt; exactly on the optical axis.
  const Eigen::Vector3d p(1.3, 0.4, -0.3);
  const Eigen::Vector2d q = k.pointAt(p);
  EXPECT_GT(q(0), 0.0);
  EXPECT_LT(q(1), 0.0);
  const Eigen::Vector3d s = k.project(q, p);
  EXPECT_NEAR(s.x(), 0.0, 1e-10);
  EXPECT_NEAR(s.y(), 0.0, 1e-10);
  EXPECT_GT(s.z(), 1.0);
  EXPECT_THROW(k.pointAt(Eigen::Vector3d(0.01, 0.0, 0.0)), core::InvalidInput);
}

TEST(SimulatedPanTilt, LatencyAccelerationRampAndHistory) {
  SimulatedPanTiltParams p;
  p.latency = 0.05;
  p.limits.qddot_max = Eigen::Vector2d::Constant(10.0);
  SimulatedPanTiltUnit unit(p);
  unit.commandVelocity(0.0, Eigen::Vector2d(1.0, -0.5));
  EXPECT_NEAR(unit.read(0.049).q.norm(), 0.0, 1e-12);    // nothing before the latency
  const auto s = unit.read(0.05 + 0.05);                  // 50 ms ramp at 10 rad/s²: v = 0.5
  EXPECT_NEAR(s.qdot(0), 0.5, 1e-9);
  EXPECT_NEAR(s.q(0), 0.5 * 10.0 * 0.05 * 0.05, 1e-9);
  const auto s2 = unit.read(0.5);
  EXPECT_NEAR(s2.qdot(0), 1.0, 1e-9);
  EXPECT_NEAR(s2.qdot(1), -0.5, 1e-9);
  const auto past = unit.read(0.1);                       // interpolated history
  EXPECT_NEAR(past.q(0), s.q(0), 1e-9);
  EXPECT_THROW(unit.commandVelocity(0.2, Eigen::Vector2d(0, 0)), core::InvalidInput);  // simulated past
  // The prediction model equals the simulator.
  SimulatedPanTiltUnit twin(p);
  twin.commandVelocity(0.0, Eigen::Vector2d(1.0, -0.5));
  twin.commandVelocity(0.02, Eigen::Vector2d(-2.0, 0.3));
  const auto now = twin.read(0.03);
  const auto pred = robots::predictJointState(p.limits, now, twin.commands(), p.latency, 0.2);
  const auto truth = twin.read(0.2);
  EXPECT_NEAR((pred.q - truth.q).norm(), 0.0, 1e-12);
  EXPECT_NEAR((pred.qdot - truth.qdot).norm(), 0.0, 1e-12);
  EXPECT_EQ(unit.rateViolations(), 0u);
  EXPECT_EQ(unit.limitHits(), 0u);
}

TEST(SimulatedPanTilt, NowIsTheTimeAskedFor) {
  // The scenario's loop: read at the capture and at the command time, command, and at the end stop at
  // now(). With 20 ms
  // latency the sub-steps summed to a hair short of the last command time, and the stop threw "time
  // goes backwards" (any run of the pan-tilt app with unit.latency 0.02 or 0.05).
  for (const double latency : {0.02, 0.03, 0.05}) {
    SimulatedPanTiltParams p;
    p.latency = latency;
    SimulatedPanTiltUnit unit(p);
    for (int k = 0; k < 90; ++k) {
      unit.read(k / 30.0);  // the capture
      const double t = k / 30.0 + 0.01;
      EXPECT_EQ(unit.read(t).t, t);
      unit.commandVelocity(t, Eigen::Vector2d(0.1, -0.05));
      EXPECT_EQ(unit.now().t, t) << latency << " " << k;
    }
    EXPECT_NO_THROW(unit.stop(unit.now().t)) << latency;
  }
}

TEST(SimulatedPanTilt, CountsRateViolationsAndHardStops) {
  SimulatedPanTiltParams p;
  p.latency = 0.0;
  SimulatedPanTiltUnit unit(p);
  unit.commandVelocity(0.0, Eigen::Vector2d(core::deg2rad(400.0), 0.0));  // above 300°/s
  EXPECT_EQ(unit.rateViolations(), 1u);
  unit.advanceTo(2.0);  // drives into the +150° stop
  EXPECT_NEAR(unit.now().q(0), p.limits.q_max(0), 1e-12);
  EXPECT_EQ(unit.limitHits(), 1u);
  EXPECT_LE(unit.now().q(0), p.limits.q_max(0));
}

TEST(PanTiltLimiter, LimitedCommandsNeverHitTheStops) {
  // Random desired velocities, limited with the predicted effect position, through latency and
  // the acceleration ramp: no command outside the limits, no hard-stop hit, positions inside.
  SimulatedPanTiltParams p;
  p.latency = 0.03;
  p.limits.q_min = Eigen::Vector2d(core::deg2rad(-20.0), core::deg2rad(-30.0));
  p.limits.q_max = Eigen::Vector2d(core::deg2rad(20.0), core::deg2rad(10.0));
  SimulatedPanTiltUnit unit(p);
  core::Rng rng = core::makeRng(7);
  const double period = 1.0 / 30.0;
  for (int k = 0; k < 3000; ++k) {
    const double t = k * period;
    const auto s = unit.read(t);
    // predicted position at the effect time: current + commands in flight (worst case: accel lag
    // only slows the axis, so this is conservative when moving towards a stop).
    // Predicted position at the effect time with the drive model (ramp towards the active command).
    const auto e = robots::predictJointState(p.limits, s, unit.commands(), p.latency, t + p.latency);
    const Eigen::Vector2d desired(core::uniform(rng, -8, 8), core::uniform(rng, -8, 8));
    const Eigen::Vector2d v = robots::limitVelocityCommand(p.limits, e.q, e.qdot, desired, period, core::deg2rad(0.5));
    EXPECT_TRUE(robots::isSafeCommand(p.limits, e.q, e.qdot, v, period));
    unit.commandVelocity(t, v);
    if (unit.limitHits() > 0) ADD_FAILURE() << "hit at t=" << t << " q=" << s.q.transpose() << " v=" << v.transpose();
    ASSERT_EQ(unit.limitHits(), 0u);
  }
  unit.stop(3000 * period);  // a command holds until the next one: end with a stop
  unit.advanceTo(3000 * period + 1.0);
  EXPECT_EQ(unit.rateViolations(), 0u);
  EXPECT_EQ(unit.limitHits(), 0u);
  // The limiter never enlarges a command and keeps its sign.
  const Eigen::Vector2d d(0.3, -0.2);
  const Eigen::Vector2d z = Eigen::Vector2d::Zero();
  const Eigen::Vector2d l = robots::limitVelocityCommand(p.limits, z, z, d, period, 0.0);
  EXPECT_LE(l.cwiseAbs().maxCoeff(), d.cwiseAbs().maxCoeff());
  EXPECT_EQ(l, d);
  // At a limit, outward is refused and inward allowed.
  const Eigen::Vector2d at_max = p.limits.q_max;
  const Eigen::Vector2d out = robots::limitVelocityCommand(p.limits, at_max, z, Eigen::Vector2d(1, 1), period, 0.0);
  EXPECT_DOUBLE_EQ(out(0), 0.0);
  EXPECT_DOUBLE_EQ(out(1), 0.0);
  const Eigen::Vector2d in = robots::limitVelocityCommand(p.limits, at_max, z, Eigen::Vector2d(-1, -1), period, 0.0);
  // Excursion of a simple profile: from rest, 1 rad/s for 0.1 s at a = 10: ramp 0.1 s (0.05 rad),
  // then brake 0.1 s (0.05 rad).
  const Eigen::Vector2d ex = robots::excursion(0.0, 1.0, 0.1, 10.0);
  EXPECT_NEAR(ex(1), 0.1, 1e-12);
  EXPECT_NEAR(ex(0), 0.0, 1e-12);
  // Reversal: from 1 rad/s to −1: peak at the zero crossing (0.05 rad), then back.
  const Eigen::Vector2d ex2 = robots::excursion(1.0, -1.0, 0.5, 10.0);
  EXPECT_NEAR(ex2(1), 0.05, 1e-12);
  EXPECT_NEAR(ex2(0), 0.0 - (0.5 - 0.2) * 1.0 - 0.05, 1e-12);
  EXPECT_DOUBLE_EQ(in(0), -1.0);
}

TEST(PanTiltHardware, UnavailableBackendsSayWhy) {
  robots::PanTiltHardwareConfig cfg;
  cfg.backend = "nonexistent";
  EXPECT_THROW(robots::openPanTiltHardware(cfg), core::InvalidInput);
#if !defined(VISP_HAVE_FLIR_PTU_SDK)
  cfg.backend = "flir_ptu";
  try {
    robots::openPanTiltHardware(cfg);
    FAIL() << "expected InvalidInput";
  } catch (const core::InvalidInput& e) {
    EXPECT_NE(std::string(e.what()).find("not compiled"), std::string::npos);
  }
#endif
}

TEST(SimulatedPanTilt, RejectsBadParameters) {
  SimulatedPanTiltParams p;
  p.q0 = Eigen::Vector2d(0.0, core::deg2rad(40.0));  // above +31°
  EXPECT_THROW(SimulatedPanTiltUnit{p}, core::InvalidInput);
  p = {};
  p.latency = -1.0;
  EXPECT_THROW(SimulatedPanTiltUnit{p}, core::InvalidInput);
  SimulatedPanTiltUnit unit;
  EXPECT_THROW(unit.commandVelocity(0.0, Eigen::Vector2d(std::nan(""), 0.0)), core::InvalidInput);
}
