#include "viewline/tracking/rolling_ball_tracker.h"

#include <gtest/gtest.h>

#include <cmath>

#include "viewline/core/error.h"
#include "viewline/core/random.h"
#include "viewline/core/statistics.h"

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
