#include "viewline/tracking/rolling_ball_tracker.h"

#include <gtest/gtest.h>

#include <Eigen/Dense>

#include <cmath>

#include "viewline/core/error.h"
#include "viewline/core/random.h"
#include "viewline/core/statistics.h"
#include "viewline/estimation/consistency.h"

using namespace viewline;

TEST(RollingBallTracker, TrackerPredictsThroughMissedDetectionsAndClampsAtTheBorder) {
  tracking::RollingBallTrackerConfig cfg;
  tracking::RollingBallTracker trk(cfg);
  const double dt = 0.02;
  const Eigen::Vector2d a(0.5, 0.0);  // rolling towards +x
  // Nothing before the first detection.
  trk.step(0.0, a, std::nullopt);
  EXPECT_FALSE(trk.initialized());
  // Measurements of a ball accelerating at a along x from rest at x = 0.
  double t = 0.0;
  for (int k = 0; k < 25; ++k) {
    t = k * dt;
    trk.step(t, a, Eigen::Vector2d(0.5 * a.x() * t * t, 0.0));
  }
  ASSERT_TRUE(trk.initialized());
  EXPECT_EQ(static_cast<int>(trk.predictions().size()), 10);
  EXPECT_GT(trk.predictions().back().x(), trk.position().x());
  // Missed detections: keeps predicting, moving along x.
  const double x_before = trk.position().x();
  for (int k = 25; k < 30; ++k) trk.step(k * dt, a, std::nullopt);
  EXPECT_EQ(trk.missedStreak(), 5);
  EXPECT_GT(trk.position().x(), x_before + 0.005);
  // Long enough without measurements: stops at the border L/2 - r with zero velocity along x.
  for (int k = 30; k < 200; ++k) trk.step(k * dt, a, std::nullopt);
  EXPECT_NEAR(trk.position().x(), 0.125, 1e-12);
  EXPECT_EQ(trk.velocity().x(), 0.0);
  for (const auto& p : trk.predictions()) EXPECT_LE(p.x(), 0.125 + 1e-12);
}

TEST(RollingBallTracker, StationaryGainMatchesTheTimeVaryingFilterInSteadyState) {
  tracking::RollingBallTrackerConfig tv, st;
  st.stationary_gain = true;
  tracking::RollingBallTracker a(tv), b(st);
  core::Rng rng = core::makeRng(3);
  for (int k = 0; k < 400; ++k) {
    const Eigen::Vector2d y(0.05 * std::sin(0.02 * k) + core::gaussian(rng, 0.002), core::gaussian(rng, 0.002));
    a.step(k * 0.02, Eigen::Vector2d::Zero(), y);
    b.step(k * 0.02, Eigen::Vector2d::Zero(), y);
  }
  EXPECT_LT((a.position() - b.position()).norm(), 1e-5);
  EXPECT_LT((a.P() - b.P()).cwiseAbs().maxCoeff(), 1e-6);
}


TEST(RollingBallTracker, GateRejectsAJumpAndRestartsAfterARunOfThem) {
  tracking::RollingBallTrackerConfig cfg;
  cfg.gate = {0.999, 3};
  tracking::RollingBallTracker trk(cfg);
  const Eigen::Vector2d a = Eigen::Vector2d::Zero();
  double t = 0.0;
  for (int k = 0; k < 20; ++k, t += 0.02) trk.step(t, a, Eigen::Vector2d(0.01, 0.0));
  ASSERT_TRUE(trk.lastUpdate());
  EXPECT_EQ(trk.lastUpdate()->decision, tracking::GateDecision::Accept);
  // A detection 8 cm away (16 σv of the 5 mm noise) is rejected and not fused.
  const Eigen::Vector2d before = trk.position();
  trk.step(t, a, Eigen::Vector2d(0.09, 0.0));
  t += 0.02;
  ASSERT_TRUE(trk.lastUpdate());
  EXPECT_EQ(trk.lastUpdate()->decision, tracking::GateDecision::Reject);
  EXPECT_GT(trk.lastUpdate()->report.nis, core::chiSquareQuantile(2.0, 0.999));
  EXPECT_LT((trk.position() - before).norm(), 1e-3);
  EXPECT_EQ(trk.missedStreak(), 1);
  // The ball really moved: the third rejection in a row restarts the track there.
  trk.step(t, a, Eigen::Vector2d(0.09, 0.0));
  t += 0.02;
  EXPECT_EQ(trk.lastUpdate()->decision, tracking::GateDecision::Reject);
  trk.step(t, a, Eigen::Vector2d(0.09, 0.0));
  EXPECT_EQ(trk.lastUpdate()->decision, tracking::GateDecision::Restart);
  EXPECT_NEAR(trk.position().x(), 0.09, 1e-12);
  EXPECT_EQ(trk.gateCounts().starts, 1u);
  EXPECT_EQ(trk.gateCounts().restarts, 1u);
  EXPECT_EQ(trk.gateCounts().rejected, 2u);
}

TEST(RollingBallTracker, ShippedFilterHasNoGateAndFusesEveryFiniteMeasurement) {
  tracking::RollingBallTracker trk(tracking::RollingBallTrackerConfig{});
  trk.step(0.0, Eigen::Vector2d::Zero(), Eigen::Vector2d(0.0, 0.0));
  trk.step(0.02, Eigen::Vector2d::Zero(), Eigen::Vector2d(0.1, 0.0));
  EXPECT_EQ(trk.lastUpdate()->decision, tracking::GateDecision::Accept);
  EXPECT_THROW(trk.step(0.04, Eigen::Vector2d::Zero(), Eigen::Vector2d(std::nan(""), 0.0)), core::InvalidInput);
}

TEST(RollingBallTracker, RefusesAnInvalidGate) {
  tracking::RollingBallTrackerConfig cfg;
  cfg.gate.restart_after = 0;
  try {
    tracking::RollingBallTracker trk(cfg);
    FAIL();
  } catch (const core::InvalidInput& e) {
    EXPECT_NE(std::string(e.what()).find("gate.restart_after"), std::string::npos);
  }
}

// A push (a velocity jump between two frames) is taken up within a few frames when the filter
// models it (impulse_nis), while the filter tuned for the smooth rolling between pushes lags.
TEST(RollingBallTracker, APushIsTakenUpWithinAFewFrames) {
  auto run = [](double impulse_nis, int& impulses) {
    tracking::RollingBallTrackerConfig cfg;
    cfg.model.sigma_w = 0.01;
    cfg.model.sigma_v = 0.0003;
    cfg.impulse_nis = impulse_nis;
    tracking::RollingBallTracker trk(cfg);
    core::Rng rng = core::makeRng(5);
    const double dt = 0.02, t_push = 1.0, v = 0.25;
    Eigen::Vector2d velocity_after = Eigen::Vector2d::Zero();
    for (int k = 0; k <= 55; ++k) {
      const double t = k * dt;
      const double x = t > t_push ? v * (t - t_push) - 0.05 : -0.05;  // at rest, then pushed along +x
      trk.step(t, Eigen::Vector2d::Zero(), Eigen::Vector2d(x + core::gaussian(rng, 0.0003), core::gaussian(rng, 0.0003)));
      if (k == 53) velocity_after = trk.velocity();  // three frames after the push
      if (k == 49) {
        EXPECT_EQ(trk.impulses(), 0);  // no jump assumed while the ball rests
      }
    }
    impulses = trk.impulses();
    return velocity_after.x();
  };
  int with = 0, without = 0;
  const double v_with = run(13.8, with), v_without = run(0.0, without);
  EXPECT_GE(with, 1);
  EXPECT_EQ(without, 0);
  EXPECT_NEAR(v_with, 0.25, 0.03);
  EXPECT_LT(v_without, 0.15);
}

// Measurement error with a frame-to-frame correlated part: the filter that models it as AR(1)
// states is consistent (position NEES in its 99 % band over independent seeded runs), the one
// treating it as white of the same total variance is overconfident (it averages correlated
// errors as if they were independent).
TEST(RollingBallTracker, ColouredMeasurementErrorKeepsThePositionNeesInItsBand) {
  const double se = 0.0002, phi = 0.55, sv = 0.0001;
  auto nees = [&](bool coloured) {
    tracking::RollingBallTrackerConfig cfg;
    cfg.model.sigma_w = 1e-4;  // the ball rests: (almost) no process noise
    cfg.model.sigma_v = coloured ? sv : std::sqrt(sv * sv + se * se);
    cfg.coloured_sigma = coloured ? se : 0.0;
    cfg.coloured_correlation = phi;
    estimation::ConsistencyStats stats;
    for (std::uint64_t run = 0; run < 150; ++run) {  // independent runs: one sample each
      tracking::RollingBallTracker trk(cfg);
      core::Rng rng = core::makeRng(100 + run);
      Eigen::Vector2d e(core::gaussian(rng, se), core::gaussian(rng, se));
      for (int k = 0; k < 60; ++k) {
        e = phi * e + std::sqrt(1.0 - phi * phi) * Eigen::Vector2d(core::gaussian(rng, se), core::gaussian(rng, se));
        trk.step(0.02 * k, Eigen::Vector2d::Zero(), e + Eigen::Vector2d(core::gaussian(rng, sv), core::gaussian(rng, sv)));
      }
      EXPECT_EQ(trk.x().size(), 6);
      const Eigen::MatrixXd P = trk.P();
      Eigen::Matrix2d Pp;
      Pp << P(0, 0), P(0, 2), P(2, 0), P(2, 2);
      const Eigen::Vector2d d = trk.position();  // the ball rests at the origin
      stats.add(d.dot(Pp.ldlt().solve(d)), 2.0);
    }
    return stats;
  };
  const estimation::ConsistencyStats coloured = nees(true), white = nees(false);
  EXPECT_TRUE(coloured.consistent(0.99)) << coloured.mean();
  EXPECT_GT(white.mean(), white.bounds(0.99).hi) << white.mean();
}

TEST(RollingBallTracker, RefusesAColouredErrorWithTheStationaryGain) {
  tracking::RollingBallTrackerConfig cfg;
  cfg.stationary_gain = true;
  cfg.coloured_sigma = 0.0002;
  EXPECT_THROW(tracking::RollingBallTracker{cfg}, core::InvalidInput);
  cfg.stationary_gain = false;
  cfg.coloured_correlation = 1.0;
  EXPECT_THROW(tracking::RollingBallTracker{cfg}, core::InvalidInput);
}

// A wrist that turns the table between frames makes the ball's acceleration ramp from one frame's
// value to the next. The ball simulated with the model itself (its own Φ, Q) under such ramps:
// the tracker told the ramp (InputHold::Ramp) is consistent; the one holding each frame's value
// over the interval before it (InputHold::End, [M]) is overconfident by the input it misplaces.
TEST(RollingBallTracker, ARampedTiltIsConsistentWithTheRampHoldOnly) {
  estimation::RollingBallModel model;
  model.sigma_w = 0.002;
  model.sigma_v = 2e-5;
  model.beta = 1.0;
  const double dt = 0.02;
  auto nis = [&](tracking::InputHold hold) {
    tracking::RollingBallTrackerConfig cfg;
    cfg.model = model;
    cfg.input_hold = hold;
    estimation::ConsistencyStats stats;
    for (std::uint64_t run = 0; run < 4; ++run) {
      tracking::RollingBallTracker trk(cfg);
      core::Rng rng = core::makeRng(300 + run);
      // p = (0.05 sin 3t, 0.04 cos 2t) m without the noise: a = (−0.45 sin 3t, −0.16 cos 2t) m/s².
      Eigen::VectorXd x = Eigen::VectorXd::Zero(6);
      x[1] = 0.15;
      x[2] = 0.04;
      auto accel = [](double t) { return Eigen::Vector2d(-0.45 * std::sin(3.0 * t), -0.16 * std::cos(2.0 * t)); };
      trk.step(0.0, accel(0.0), Eigen::Vector2d(x[0], x[2]));
      for (int k = 1; k <= 250; ++k) {  // 5 s: the ball stays well inside the table
        const estimation::LinearTransition tr = model.transitionRamp(dt, accel((k - 1) * dt), accel(k * dt));
        x = tr.Phi * x + tr.Gamma * tr.u + core::sampleGaussian(rng, Eigen::VectorXd::Zero(6), tr.Q);
        EXPECT_LT(std::max(std::abs(x[0]), std::abs(x[2])), model.positionLimit());
        const Eigen::Vector2d y(x[0] + core::gaussian(rng, model.sigma_v), x[2] + core::gaussian(rng, model.sigma_v));
        trk.step(k * dt, accel(k * dt), y);
        if (k > 25) stats.add(trk.lastUpdate()->report.nis, 2.0);
      }
    }
    return stats;
  };
  const estimation::ConsistencyStats ramp = nis(tracking::InputHold::Ramp), end = nis(tracking::InputHold::End);
  EXPECT_TRUE(ramp.consistent(0.99)) << ramp.mean() << " outside [" << ramp.bounds().lo << ", " << ramp.bounds().hi << "]";
  EXPECT_GT(end.mean(), end.bounds(0.99).hi) << end.mean();
}
