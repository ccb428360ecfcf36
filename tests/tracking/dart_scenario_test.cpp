// Short seeded run of the dart scenario library (the long Monte Carlo is apps/dart_tracking).
#include <gtest/gtest.h>

#include "dart_config.h"
#include "viewline/core/error.h"
#include "viewline/tracking/dart_scenario.h"

using namespace viewline;

TEST(DartScenario, ShippedConfigLoadsAndThirtyRunsMeetTheFiguresLoosely) {
  const tracking::DartScenarioConfig cfg = apps::loadDartScenario("config/dart_tracking.yaml");
  ASSERT_EQ(cfg.cameras.size(), 2u);
  const tracking::DartSummary s = tracking::runDartExperiments(cfg, 1, 30);
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
  EXPECT_THROW(apps::dartScenarioFromString("tracker:\n  gate_kind: mahalanobis\n", "t.yaml"), core::InvalidInput);
  EXPECT_THROW(apps::dartScenarioFromString("tracker:\n  gate: chi\n", "t.yaml"), core::InvalidInput);
  EXPECT_THROW(apps::dartScenarioFromString("outlier_rate: 1.5\n", "t.yaml"), core::InvalidInput);
  EXPECT_NO_THROW(apps::dartScenarioFromString("outlier_rate: 0.1\n", "t.yaml"));
}
