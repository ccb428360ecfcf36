#pragma once
// The dart experiment's figures ([L] §VI): what each experiment pools, the summary and its JSON.

#include <cstddef>
#include <cstdint>
#include <nlohmann/json.hpp>
#include <string>
#include <vector>

#include "viewline/core/statistics.h"
#include "viewline/estimation/state.h"
#include "viewline/scenarios/dart/config.h"
#include "viewline/scenarios/dart/world.h"
#include "viewline/tracking/tracker.h"

namespace viewline::scenarios {

struct GateFigures {
  std::string gate;
  std::size_t outliers = 0, outliers_rejected = 0, inliers = 0, inliers_rejected = 0;
  double outlier_rejected_fraction = 0.0;
  double inlier_rejected_fraction = 0.0;
  double rmse_position = 0.0;  ///< pooled over settled measurements, m
};

struct DartSummary {
  std::uint64_t seed = 0;
  int runs = 0;
  // A
  double nees_mean = 0.0;             ///< 6-dof state NEES, one sample per run
  core::Interval nees_bounds;
  std::size_t nees_samples = 0;
  double nees_position_mean = 0.0;    ///< 3-dof
  core::Interval nees_position_bounds;
  double rmse_position = 0.0;         ///< m (A, settled)
  double pcrlb_position = 0.0;        ///< m (A, settled)
  double rmse_to_pcrlb = 0.0;
  double rmse_to_pcrlb_final = 0.0;   ///< at the last measurement of each flight
  double measurements_per_flight = 0.0;
  // B
  GateFigures gate_directional, gate_mahalanobis;
  std::string better_gate;
  double outlier_rejected_fraction = 0.0;  ///< better gate
  double inlier_rejected_fraction = 0.0;   ///< better gate
  double rmse_image_ekf_alternating = 0.0;
  // C
  double rmse_async_exact = 0.0, rmse_async_dt_offset = 0.0, rmse_async_image_ekf = 0.0;
  double nees_async_exact = 0.0, nees_async_dt_offset = 0.0;  ///< position NEES, pooled settled
  double update_time_us = 0.0;  ///< mean ViewlineTracker::submit time in C (exact)
  // D
  GateFigures scenario_gate;    ///< full scenario with the configured gate (rmse_position = scenario RMSE)
  double late_vs_inorder_max_diff = 0.0;
  std::size_t late_inserted = 0;
  std::size_t late_outcome_mismatches = 0;
  std::size_t late_refused = 0;
  // E
  double single_camera_convergence_p95 = 0.0;
  double single_camera_convergence_median = 0.0;
  std::size_t single_camera_not_converged = 0;
  double runtime_s = 0.0;
};

/// Squared position errors (and the bound, the position NEES) pooled over the settled
/// measurements of many flights.
struct PooledError {
  double se = 0.0;
  double bound = 0.0;
  double nees = 0.0;
  std::size_t n = 0;
  /// √(se / n); 0 when nothing was pooled.
  double rmse() const;
  /// Adds the estimate's error against the truth (and its position NEES).
  void add(const estimation::StateEstimate& s, const tracking::Vector6& truth);
};

/// Counts the final fates of a flight's detections (inlier / outlier, rejected or not).
void countGate(GateFigures& g, const tracking::ViewlineTracker& tracker, const DartFlight& flight);
/// Fractions from the counts, RMSE from the pooled errors.
void finishGate(GateFigures& g, const PooledError& p);

/// The summary as the app prints it (a few lines).
std::string dartSummaryText(const DartSummary& s);

/// The summary as JSON (the app's --summary, the reference recorded by scripts/compare-summaries).
nlohmann::json summaryToJson(const DartSummary& s, const DartScenarioConfig& cfg);

}  // namespace viewline::scenarios
