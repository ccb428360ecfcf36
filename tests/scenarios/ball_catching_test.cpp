// Ball catching end to end: a short seeded session of the shipped scenario (rendered images ->
// colour-blob detector -> viewline tracker -> interception planner -> simulated robot).
#include <gtest/gtest.h>

#include <memory>
#include <vector>

#include "viewline/core/error.h"
#include "viewline/core/statistics.h"
#include "viewline/io/config.h"
#include "viewline/runtime/telemetry.h"
#include "viewline/scenarios/ball_catching.h"

using namespace viewline;

namespace {
scenarios::BallCatchingConfig shipped(const char* path) {
  return scenarios::loadBallCatchingConfig(io::ConfigNode::loadFile(path));
}

// The same throw run twice gives the same result, bit for bit.
void expectSameThrow(const scenarios::ThrowResult& a, const scenarios::ThrowResult& b) {
  EXPECT_EQ(a.frames, b.frames);
  EXPECT_EQ(a.detections, b.detections);
  EXPECT_EQ(a.fused, b.fused);
  EXPECT_EQ(a.gated, b.gated);
  EXPECT_EQ(a.caught, b.caught);
  EXPECT_EQ(a.miss_reason, b.miss_reason);
  EXPECT_EQ(a.miss_distance, b.miss_distance);
  EXPECT_EQ(a.prediction_error, b.prediction_error);
  EXPECT_EQ(a.prediction_error_lead, b.prediction_error_lead);
  EXPECT_EQ(a.decision_time, b.decision_time);
  EXPECT_EQ(a.t_first_move, b.t_first_move);
  EXPECT_TRUE(a.target == b.target);
  EXPECT_TRUE(a.hole_at_cross == b.hole_at_cross);
}

// Every image the tracker was given has one innovation record, whose decision is the tracker's:
// Start, Accept and Restart fused it, Reject gated it (the counts of the throw's result).
void expectEveryGateDecision(const runtime::MemorySink& sink, const scenarios::ThrowResult& r, double gate) {
  using D = tracking::GateDecision;
  const std::size_t used = sink.count(D::Start) + sink.count(D::Accept) + sink.count(D::Restart);
  EXPECT_EQ(used, static_cast<std::size_t>(r.fused)) << "throw " << r.index;
  EXPECT_EQ(sink.count(D::Reject), static_cast<std::size_t>(r.gated)) << "throw " << r.index;
  EXPECT_GE(sink.count(D::Start), 1u);
  EXPECT_EQ(sink.innovations.size(), static_cast<std::size_t>(r.fused + r.gated));
  EXPECT_EQ(sink.measurements.size(), static_cast<std::size_t>(r.detections));
  std::size_t ball_estimates = 0;
  for (const auto& e : sink.estimates) ball_estimates += e.channel == "ball";
  EXPECT_EQ(ball_estimates, static_cast<std::size_t>(r.fused));
  EXPECT_FALSE(sink.commands.empty());  // a set point every control period
  for (const auto& i : sink.innovations)
    if (i.decision == D::Accept) {
      EXPECT_LE(i.nis, gate * (1.0 + 1e-9)) << "an accepted image inside the chi-square gate";
    }
}
}  // namespace

// A short session (two threads, as fast as possible, telemetry in memory), then its first throws
// again on one thread paced at 20x real time (what --realtime 20 asks): the scheduler's pacing
// changes when events run, never their order, and telemetry only observes, so the throws are the
// same bit for bit; the telemetry saw every gate decision the tracker made.
TEST(BallCatchingScenario, ShortSessionCatchesWithinLimitsIsTheSamePacedAndTelemetrySeesEveryGateDecision) {
  auto cfg = shipped("config/ball_catching.yaml");
  cfg.threads = 2;
  std::vector<std::shared_ptr<runtime::MemorySink>> sinks;
  for (int i = 0; i < 6; ++i) sinks.push_back(std::make_shared<runtime::MemorySink>());
  scenarios::CatchHooks fast;
  fast.telemetry = [&](int i) { return sinks[static_cast<std::size_t>(i)]; };  // one per throw: thread-safe
  const auto s = scenarios::runBallCatching(cfg, 6, 3, fast);
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
  // Camera-to-robot registration: the marker's reprojection error with the registered poses is a
  // fraction of the calibrated rig's (~2 px), for both cameras of the session.
  ASSERT_TRUE(s.registration.has_value());
  EXPECT_GE(s.registration->cameras_registered, 2);
  EXPECT_LT(s.registration->reprojection_px_after, 0.5);
  EXPECT_LT(s.registration->reprojection_px_after, 0.5 * s.registration->reprojection_px_before);
  EXPECT_GE(s.reachable_throws, 1);  // the catch rate itself: CatchRateGuardWithHalfPixelDetectionNoise
  const double gate = core::chiSquareQuantile(2.0, 1.0 - cfg.tracker.gate.mahalanobis_alpha);
  for (std::size_t i = 0; i < s.results.size(); ++i) expectEveryGateDecision(*sinks[i], s.results[i], gate);
  // Same seeds, one thread, paced: identical results.
  cfg.threads = 1;
  scenarios::CatchHooks paced;
  paced.pacing = runtime::Pacing{20.0};
  const auto s1 = scenarios::runBallCatching(cfg, 3, 3, paced);
  ASSERT_EQ(s1.results.size(), 3u);
  for (std::size_t i = 0; i < 3; ++i) {
    expectSameThrow(s1.results[i], s.results[i]);
    EXPECT_GT(s1.results[i].wall_s, 0.9 * s1.results[i].t_cross / 20.0) << "paced: waits for the wall clock";
  }
  const auto j = scenarios::summaryJson(s, cfg);
  for (const char* key : {"catch_rate_reachable", "catch_rate_all", "throws", "reachable_throws", "miss_reasons",
                          "prediction_error_mm_at_catch", "decision_time_s"})
    EXPECT_TRUE(j.contains(key)) << key;
}

TEST(BallCatchingScenario, ViperArmBackEndFollowsThePlan) {
  auto cfg = shipped("config/ball_catching.yaml");
  cfg.robot.kind = robots::CartesianBackEnd::Arm;
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

TEST(BallCatchingScenario, RigRendersWithTheTruthAndEstimatesWithTheCalibration) {
  const auto cfg = shipped("config/ball_catching.yaml");
  ASSERT_FALSE(cfg.rig.empty());
  for (const auto& c : cfg.cameras) {
    ASSERT_TRUE(c.true_camera && c.calibrated_camera) << c.name;
    const core::Camera t = c.renderCamera(), e = c.estimatorCamera();
    EXPECT_EQ(t.name, c.name);
    EXPECT_EQ(e.width, t.width);
    // Calibrated from rendered board images: close to the truth, but not the truth itself.
    const double dc = (e.center_w() - t.center_w()).norm();
    EXPECT_GT(dc, 1e-5) << c.name << ": the estimator must not get the render camera";
    EXPECT_LT(dc, 0.05) << c.name;
    EXPECT_NE(e.intrinsics.get_px(), t.intrinsics.get_px()) << c.name;
  }
  // A camera geometry key next to rig: is an error naming file:line:key; so is an unknown camera.
  const std::string rig = "rig: calib/rigs/catching\nrobot: {kind: stage}\n";  // ctest runs from the source root
  try {
    scenarios::loadBallCatchingConfig(
        io::ConfigNode::fromString(rig + "cameras:\n  - {name: right, position: [0, 0, 0]}\n", "r.yaml"));
    ADD_FAILURE() << "geometry with rig: accepted";
  } catch (const core::InvalidInput& e) {
    EXPECT_NE(std::string(e.what()).find("r.yaml:"), std::string::npos) << e.what();
    EXPECT_NE(std::string(e.what()).find("position"), std::string::npos) << e.what();
  }
  EXPECT_THROW(scenarios::loadBallCatchingConfig(
                   io::ConfigNode::fromString(rig + "cameras:\n  - {name: nobody}\n", "r.yaml")),
               core::InvalidInput);
  // Inline cameras (no rig): the estimator uses the render camera.
  const auto inline_cfg = scenarios::loadBallCatchingConfig(io::ConfigNode::fromString(
      "robot: {kind: stage}\ncameras:\n  - {name: a, kud: 0.02, position: [4.6, -2.9, 2.1], look_at: [2.4, 0, 1.3]}\n",
      "i.yaml"));
  ASSERT_EQ(inline_cfg.cameras.size(), 1u);
  EXPECT_TRUE(inline_cfg.rig.empty());
  const core::Camera t = inline_cfg.cameras[0].renderCamera(), e = inline_cfg.cameras[0].estimatorCamera();
  EXPECT_TRUE(t.c_M_w.isApprox(e.c_M_w));
  EXPECT_DOUBLE_EQ(t.intrinsics.get_kud(), e.intrinsics.get_kud());
}

TEST(BallCatchingScenario, UnknownConfigKeyIsAnError) {
  const auto node = io::ConfigNode::fromString("cameras: []\nrobot: {kind: stage}\nbogus: 1\n", "t.yaml");
  EXPECT_THROW(scenarios::loadBallCatchingConfig(node), core::InvalidInput);
}

// CI guard of the catch rate under the hardest shipped condition of the envelope: 0.5 px of extra
// detection noise per axis (the tracker told). 20 seeded throws of the shipped scenario; the method
// catches 15 of the 15 reachable ones here (docs/results.md), so a regression of ~20 % (12 of 15)
// fails, and so does any set point over the robot's Euclidean limits. The tracker's consistency
// as shipped: its NIS (2 dof, ~1000 accepted images) and NEES (6 dof, one per throw after its 8th
// fused image, against the true flight) inside their two-sided 99 % chi-square bands (15 of 15,
// NIS 1.929 in [1.844, 2.164], NEES 6.81 in [4.19, 8.18] when written).
TEST(BallCatchingScenario, CatchRateGuardWithHalfPixelDetectionNoise) {
  auto cfg = shipped("config/ball_catching.yaml");
  cfg.threads = 2;
  cfg.pixel_noise_px = 0.5;
  ASSERT_EQ(cfg.robot.limits.norm, robots::LimitNorm::Euclidean);
  const auto s = scenarios::runBallCatching(cfg, 20, 11);
  ASSERT_GE(s.reachable_throws, 10) << "too few reachable throws to guard the rate";
  EXPECT_GT(s.catch_rate_reachable, 0.85) << s.caught_reachable << " of " << s.reachable_throws;
  ASSERT_GT(s.nis_samples, 500);
  EXPECT_GE(s.nis_mean, s.nis_band_lo) << "NIS " << s.nis_mean << " below its band: the tracker is told too much noise";
  EXPECT_LE(s.nis_mean, s.nis_band_hi) << "NIS " << s.nis_mean << " above its band: the tracker is told too little noise";
  ASSERT_GE(s.nees_samples, 15);
  EXPECT_GE(s.nees_mean, s.nees_band_lo) << "NEES " << s.nees_mean;
  EXPECT_LE(s.nees_mean, s.nees_band_hi) << "NEES " << s.nees_mean;
  EXPECT_EQ(s.limit_violations, 0u);
  EXPECT_LE(s.max_speed, 0.5 * (1 + 1e-6));
  EXPECT_LE(s.max_acceleration, 13.0 * (1 + 1e-6));
  EXPECT_EQ(s.refused_setpoints, 0u);
}
