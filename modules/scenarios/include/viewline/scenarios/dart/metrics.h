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

/// One gate's decisions on the detections of experiment B (or D): counts, fractions and the RMSE.
struct GateFigures {
  std::string gate;  ///< gate name ("directional", "mahalanobis", ...)
  std::size_t outliers = 0,           ///< generated gross outliers seen
              outliers_rejected = 0,  ///< of them, rejected by the gate
              inliers = 0,            ///< genuine detections seen
              inliers_rejected = 0;   ///< of them, wrongly rejected
  double outlier_rejected_fraction = 0.0;  ///< outliers_rejected / outliers
  double inlier_rejected_fraction = 0.0;   ///< inliers_rejected / inliers
  double rmse_position = 0.0;  ///< pooled over settled measurements, m
};

/// The dart experiment's figures (experiments A-E of [L] §VI), written as the app's --summary JSON.
struct DartSummary {
  std::uint64_t seed = 0;  ///< master seed of the runs
  int runs = 0;            ///< Monte Carlo runs (flights) per experiment
  // A
  double nees_mean = 0.0;             ///< 6-dof state NEES, one sample per run
  core::Interval nees_bounds;         ///< chi-square interval of the mean NEES at the configured confidence
  std::size_t nees_samples = 0;       ///< NEES samples pooled
  double nees_position_mean = 0.0;    ///< 3-dof
  core::Interval nees_position_bounds;  ///< chi-square interval of the mean position NEES
  double rmse_position = 0.0;         ///< m (A, settled)
  double pcrlb_position = 0.0;        ///< m (A, settled)
  double rmse_to_pcrlb = 0.0;         ///< rmse_position / pcrlb_position (1: efficient)
  double rmse_to_pcrlb_final = 0.0;   ///< at the last measurement of each flight
  double measurements_per_flight = 0.0;  ///< mean detections per flight (A)
  // B
  GateFigures gate_directional,   ///< B: the directional gate of [L] §V
              gate_mahalanobis;   ///< B: the chi-square gate
  std::string better_gate;        ///< B: the gate with the lower RMSE
  double outlier_rejected_fraction = 0.0;  ///< better gate
  double inlier_rejected_fraction = 0.0;   ///< better gate
  double rmse_image_ekf_alternating = 0.0;  ///< B: image-space EKF baseline on the same detections, m
  // C
  double rmse_async_exact = 0.0,      ///< C: free-running cameras, exact capture times, m
         rmse_async_dt_offset = 0.0,  ///< C: the Δt-offset filter ([L] eq 26), m
         rmse_async_image_ekf = 0.0;  ///< C: image-space EKF baseline, m
  double nees_async_exact = 0.0,      ///< C: position NEES, exact times, pooled settled
         nees_async_dt_offset = 0.0;  ///< C: position NEES, Δt-offset filter, pooled settled
  double update_time_us = 0.0;  ///< mean ViewlineTracker::submit time in C (exact)
  // D
  GateFigures scenario_gate;    ///< full scenario with the configured gate (rmse_position = scenario RMSE)
  double late_vs_inorder_max_diff = 0.0;  ///< D: largest state difference, late vs in-order delivery (0: exact replay)
  std::size_t late_inserted = 0;          ///< D: late detections inserted and re-processed
  std::size_t late_outcome_mismatches = 0;  ///< D: detections whose fate differs from in-order delivery
  std::size_t late_refused = 0;           ///< D: detections refused as older than the horizon
  // E
  double single_camera_convergence_p95 = 0.0;     ///< E: 95th percentile of the time to converge from a far prior, s
  double single_camera_convergence_median = 0.0;  ///< E: median time to converge, s
  std::size_t single_camera_not_converged = 0;    ///< E: runs that never converged
  double runtime_s = 0.0;                          ///< wall-clock time of the whole experiment, s
};

/// Squared position errors (and the bound, the position NEES) pooled over the settled
/// measurements of many flights.
struct PooledError {
  double se = 0.0;     ///< sum of squared position errors, m²
  double bound = 0.0;  ///< sum of the position covariance traces, m²
  double nees = 0.0;   ///< sum of the position NEES
  std::size_t n = 0;   ///< samples pooled
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
