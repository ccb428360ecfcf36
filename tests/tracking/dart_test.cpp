// Short seeded run of the dart scenario library (the long Monte Carlo is apps/dart_tracking).
#include <gtest/gtest.h>

#include <chrono>

#include "viewline/core/error.h"
#include "viewline/runtime/telemetry.h"
#include "viewline/scenarios/dart/config.h"
#include "viewline/scenarios/dart/loop.h"

using namespace viewline;

TEST(DartScenario, ShippedConfigLoadsAndThirtyRunsMeetTheFiguresLoosely) {
  const scenarios::DartScenarioConfig cfg = scenarios::loadDartScenario("config/dart_tracking.yaml");
  ASSERT_EQ(cfg.cameras.size(), 2u);
  const scenarios::DartSummary s = scenarios::runDartExperiments(cfg, 1, 30);
  EXPECT_EQ(s.nees_samples, 30u);
  EXPECT_TRUE(s.nees_bounds.contains(s.nees_mean)) << s.nees_mean;
  EXPECT_GT(s.rmse_to_pcrlb, 0.9);  // an estimator cannot beat the bound by much (sampling only)
  EXPECT_LT(s.rmse_to_pcrlb, 1.25);
  EXPECT_GE(s.outlier_rejected_fraction, 0.95);
  EXPECT_LE(s.inlier_rejected_fraction, 0.02);
  EXPECT_LE(s.late_vs_inorder_max_diff, 1e-9);
  EXPECT_EQ(s.late_outcome_mismatches, 0u);
  EXPECT_GT(s.late_inserted, 0u);
  EXPECT_LE(s.single_camera_convergence_p95, 7.0);
  EXPECT_LT(s.rmse_async_exact, 0.02);
  EXPECT_GT(s.measurements_per_flight, 10.0);
}

TEST(DartScenario, ConfigKeysAreStrict) {
  EXPECT_THROW(scenarios::dartScenarioFromString("tracker:\n  gate_kind: mahalanobis\n", "t.yaml"), core::InvalidInput);
  EXPECT_THROW(scenarios::dartScenarioFromString("tracker:\n  gate: chi\n", "t.yaml"), core::InvalidInput);
  EXPECT_THROW(scenarios::dartScenarioFromString("outlier_rate: 1.5\n", "t.yaml"), core::InvalidInput);
  EXPECT_NO_THROW(scenarios::dartScenarioFromString("outlier_rate: 0.1\n", "t.yaml"));
}

TEST(DartScenario, TheTelemetrySinkSeesEveryGateDecisionOfTheFullScenario) {
  const scenarios::DartScenarioConfig cfg = scenarios::defaultDartScenario();
  cfg.validate();
  runtime::MemorySink sink;
  scenarios::DartRunCallbacks cb;
  cb.telemetry = &sink;
  const scenarios::DartSummary s = scenarios::runDartExperiments(cfg, 3, 4, cb);
  const scenarios::DartSummary plain = scenarios::runDartExperiments(cfg, 3, 4);
  // One innovation per processed image of the full scenario (D), whose final fates the summary counts.
  const std::size_t processed = s.scenario_gate.inliers + s.scenario_gate.outliers;
  EXPECT_EQ(sink.innovations.size(), processed);
  EXPECT_EQ(sink.estimates.size(), processed);
  EXPECT_GE(sink.measurements.size(), processed);
  std::size_t decisions = 0;
  for (auto d : {tracking::GateDecision::Start, tracking::GateDecision::Accept, tracking::GateDecision::Reject,
                 tracking::GateDecision::Restart})
    decisions += sink.count(d, "dart");
  EXPECT_EQ(decisions, processed);
  EXPECT_EQ(sink.count(tracking::GateDecision::Start, "dart"), 4u);  // one track per flight
  EXPECT_GT(sink.count(tracking::GateDecision::Reject, "dart"), 0u);  // 5 % outliers
  // Telemetry only observes: the figures are those of a run without it.
  EXPECT_EQ(s.scenario_gate.rmse_position, plain.scenario_gate.rmse_position);
  EXPECT_EQ(s.nees_mean, plain.nees_mean);
}

TEST(DartScenario, PacedToTheWallClockTheFiguresAreTheSame) {
  const scenarios::DartScenarioConfig cfg = scenarios::defaultDartScenario();
  cfg.validate();
  scenarios::DartRunCallbacks paced;
  paced.pacing = runtime::Pacing{20.0};  // --realtime 20: about 15 ms of wall time per flight
  const auto t0 = std::chrono::steady_clock::now();
  const scenarios::DartSummary a = scenarios::runDartExperiments(cfg, 7, 3, paced);
  const double wall = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
  const scenarios::DartSummary b = scenarios::runDartExperiments(cfg, 7, 3);
  nlohmann::json ja = scenarios::summaryToJson(a, cfg), jb = scenarios::summaryToJson(b, cfg);
  for (auto* j : {&ja, &jb}) {  // wall-clock figures
    j->erase("runtime_s");
    (*j)["async"].erase("update_time_us");
  }
  EXPECT_EQ(ja.dump(), jb.dump());
  EXPECT_GT(a.late_inserted, 0u);
  EXPECT_GT(wall, 3 * 0.05 / 20.0);  // the deliveries of each flight span more than 0.05 s of simulated time
}

// CI guards of the headline figures (docs/results.md, "Conditions"): seeded, a fixed number of
// runs, thresholds about 20 % above what this seed gives today, so a regression of the method
// (not a threshold) fails them.
TEST(DartScenario, GuardTenPercentOutliersKeepTheRmseNearTheOutlierFreeOne) {
  scenarios::DartScenarioConfig cfg = scenarios::loadDartScenario("config/dart_tracking.yaml");
  cfg.outlier_rate = 0.10;
  const scenarios::DartSummary s = scenarios::runDartExperiments(cfg, 11, 150);
  // Seed 11, 150 runs today: 1.034 x the outlier-free RMSE (target <= 2), the better gate's
  // estimate reported after 94.9 % of the settled measurements (5.1 % wait for a confirmation).
  EXPECT_LE(s.rmse_outliers_to_outlier_free, 1.24);
  const scenarios::GateFigures& better = s.better_gate == "directional" ? s.gate_directional : s.gate_mahalanobis;
  EXPECT_GE(better.reported_fraction, 0.939);  // unreported 5.1 % -> at most 6.1 %
  EXPECT_GE(better.outlier_rejected_fraction, 0.99);
}

TEST(DartScenario, GuardSingleCameraConvergesWithinSixImagesUnderProcessNoise) {
  scenarios::DartScenarioConfig cfg = scenarios::loadDartScenario("config/dart_tracking.yaml");
  cfg.truth_accel_psd = 1.0;
  cfg.tracker.model.accel_psd = 1.0;
  const scenarios::DartSummary s = scenarios::runDartExperiments(cfg, 11, 150);
  // Seed 11, 150 runs today: p95 6 (median 4) measurements; the information limit (ideal
  // filters with the true depth) p95 5. A regression of one measurement is 17 %.
  EXPECT_LE(s.single_camera_convergence_p95, 6.0);
  EXPECT_LE(s.single_camera_convergence_p95, s.single_camera_convergence_bound_p95 + 1.0);
}
