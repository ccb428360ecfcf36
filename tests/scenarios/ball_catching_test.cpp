// Ball catching end to end: a short seeded session of the shipped scenario (rendered images ->
// colour-blob detector -> viewline tracker -> interception planner -> simulated robot).
#include <gtest/gtest.h>

#include "viewline/io/config.h"
#include "viewline/scenarios/ball_catching.h"

using namespace viewline;

namespace {
scenarios::BallCatchingConfig shipped(const char* path) {
  return scenarios::loadBallCatchingConfig(io::ConfigNode::loadFile(path));
}
}  // namespace

TEST(BallCatchingScenario, ShortSeededSessionCatchesAndRespectsTheLimits) {
  auto cfg = shipped("config/ball_catching.yaml");
  cfg.threads = 2;
  const auto s = scenarios::runBallCatching(cfg, 6, 3);
  ASSERT_EQ(s.results.size(), 6u);
  EXPECT_GT(s.frames, 100);
  EXPECT_GT(s.detection_rate, 0.7);  // the ball is detected in most images
  EXPECT_EQ(s.limit_violations, 0u);  // every set point within 0.5 m/s and 13 m/s²
  EXPECT_EQ(s.refused_setpoints, 0u);
  int with_target = 0;
  for (const auto& r : s.results) {
    EXPECT_GT(r.fused, 5) << "throw " << r.index;
    with_target += r.had_target;
    if (r.caught) {
      EXPECT_LE(r.miss_distance, cfg.hole_radius - cfg.throws.body.reference_radius);
    } else {
      EXPECT_FALSE(r.miss_reason.empty());
    }
    if (r.prediction_error >= 0.0) {
      EXPECT_LT(r.prediction_error, 0.02) << "throw " << r.index;
    }
  }
  EXPECT_EQ(with_target, 6);
  EXPECT_GE(s.reachable_throws, 1);
  EXPECT_GE(s.caught_reachable, 1);
  // Same seeds, one thread: identical results (throws are independent of the scheduling).
  cfg.threads = 1;
  const auto s1 = scenarios::runBallCatching(cfg, 3, 3);
  for (int i = 0; i < 3; ++i) {
    EXPECT_EQ(s1.results[i].caught, s.results[i].caught);
    EXPECT_DOUBLE_EQ(s1.results[i].miss_distance, s.results[i].miss_distance);
  }
  const auto j = scenarios::summaryJson(s, cfg);
  for (const char* key : {"catch_rate_reachable", "catch_rate_all", "throws", "reachable_throws", "miss_reasons",
                          "prediction_error_mm_at_catch", "decision_time_s"})
    EXPECT_TRUE(j.contains(key)) << key;
}

TEST(BallCatchingScenario, ViperArmBackEndFollowsThePlan) {
  auto cfg = shipped("config/ball_catching.yaml");
  cfg.robot.kind = robots::CartesianBackEnd::Arm;
  cfg.finalize();
  cfg.threads = 1;
  const auto s = scenarios::runBallCatching(cfg, 2, 5);
  EXPECT_EQ(s.limit_violations, 0u);
  EXPECT_EQ(s.refused_setpoints, 0u);  // every set point had an IK solution within the joint limits
  for (const auto& r : s.results) EXPECT_TRUE(r.had_target);
}

TEST(BallCatchingScenario, ShippedDartScenarioRuns) {
  auto cfg = shipped("config/ball_catching_dart.yaml");
  cfg.threads = 1;
  const auto s = scenarios::runBallCatching(cfg, 2, 1);
  EXPECT_GT(s.detection_rate, 0.5);
  for (const auto& r : s.results) {
    EXPECT_TRUE(r.had_target);
    EXPECT_LT(r.prediction_error, 0.02);
  }
}

TEST(BallCatchingScenario, UnknownConfigKeyIsAnError) {
  const auto node = io::ConfigNode::fromString("cameras: []\nrobot: {kind: stage}\nbogus: 1\n", "t.yaml");
  EXPECT_THROW(scenarios::loadBallCatchingConfig(node), core::InvalidInput);
}
