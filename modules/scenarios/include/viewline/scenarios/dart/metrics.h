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

/// How well one gate separated gross outliers from good detections, and the RMSE it left.
struct GateFigures {
  std::string gate;  ///< gate name ("directional", "mahalanobis"; D: the configured kind)
  std::size_t outliers = 0,           ///< generated outliers submitted
              outliers_rejected = 0,  ///< of which the gate rejected
              inliers = 0,            ///< good detections submitted
              inliers_rejected = 0;   ///< of which the gate rejected (wrongly)
  double outlier_rejected_fraction = 0.0;  ///< outliers_rejected / outliers
  double inlier_rejected_fraction = 0.0;   ///< inliers_rejected / inliers
  double rmse_position = 0.0;  ///< pooled over settled measurements, m
  /// Settled measurements after which the tracker reported an estimate (a confirmed track) /
  /// all settled measurements; the RMSE pools only the reported ones.
  double reported_fraction = 1.0;
  std::size_t restarts = 0;  ///< track restarts (rejections in a row) summed over the runs
};

/// The figures of experiments A-E over all runs (see loop.h for what each experiment does).
struct DartSummary {
  std::uint64_t seed = 0;  ///< the seed runDartExperiments() was given
  int runs = 0;            ///< seeded runs (one flight per experiment each)
  // A
  double nees_mean = 0.0;             ///< 6-dof state NEES, one sample per run
  core::Interval nees_bounds;         ///< two-sided χ² bounds of the mean NEES at cfg.confidence
  std::size_t nees_samples = 0;       ///< samples in nees_mean (runs reaching nees_index)
  double nees_position_mean = 0.0;    ///< 3-dof
  core::Interval nees_position_bounds;  ///< χ² bounds of nees_position_mean
  double rmse_position = 0.0;         ///< m (A, settled)
  double pcrlb_position = 0.0;        ///< m (A, settled)
  double rmse_to_pcrlb = 0.0;         ///< rmse_position / pcrlb_position (1: efficient)
  double rmse_to_pcrlb_final = 0.0;   ///< at the last measurement of each flight
  double reported_fraction = 1.0;     ///< settled measurements of A with a confirmed track / all
  double measurements_per_flight = 0.0;  ///< mean in-image detections per flight (A)
  // B
  GateFigures gate_directional,   ///< the directional gate on B's data
              gate_mahalanobis;   ///< the Mahalanobis gate on the same data
  std::string better_gate;        ///< the gate with fewer errors (outliers passed + inliers rejected)
  double outlier_rejected_fraction = 0.0;  ///< better gate
  double inlier_rejected_fraction = 0.0;   ///< better gate
  double rmse_image_ekf_alternating = 0.0;  ///< image-space EKF baseline on B's data, m
  /// The better gate's RMSE (B, outliers) / the outlier-free RMSE of A (1: outliers cost nothing).
  double rmse_outliers_to_outlier_free = 0.0;
  // C
  double rmse_async_exact = 0.0,      ///< exact propagation to each stamp, m
         rmse_async_dt_offset = 0.0,  ///< Δt-offset rows on a fixed grid, m
         rmse_async_image_ekf = 0.0;  ///< image-space EKF, m
  double nees_async_exact = 0.0,      ///< position NEES of the exact filter, pooled settled
         nees_async_dt_offset = 0.0;  ///< position NEES, pooled settled
  double update_time_us = 0.0;  ///< mean ViewlineTracker::submit time in C (exact)
  // D
  GateFigures scenario_gate;    ///< full scenario with the configured gate (rmse_position = scenario RMSE)
  /// Largest difference of the final x, P and time between arrival and capture order.
  double late_vs_inorder_max_diff = 0.0;
  std::size_t late_inserted = 0;            ///< late measurements inserted into the past (replayed)
  std::size_t late_outcome_mismatches = 0;  ///< detections whose fate differs between the two orders
  std::size_t late_refused = 0;             ///< arrivals refused (e.g. older than late_horizon)
  // E
  /// 95th percentile (nearest rank) of the measurements needed to stay within single_tolerance of
  /// the filter started at the truth (a count).
  double single_camera_convergence_p95 = 0.0;
  double single_camera_convergence_median = 0.0;  ///< median of the same count
  std::size_t single_camera_not_converged = 0;    ///< runs still off at their last measurement
  /// The same p95 for two ideal linear Kalman filters (rows with the true depth, same priors,
  /// no gate): the information limit of the criterion (loop.cpp, idealConvergence).
  double single_camera_convergence_bound_p95 = 0.0;
  double single_camera_convergence_bound_median = 0.0;  ///< median of the ideal filters' count
  double runtime_s = 0.0;  ///< wall-clock time of all experiments, s
};

/// Squared position errors (and the bound, the position NEES) pooled over the settled
/// measurements of many flights.
struct PooledError {
  double se = 0.0;     ///< sum of squared position errors, m²
  double bound = 0.0;  ///< sum of the position PCRLB traces, m²
  double nees = 0.0;   ///< sum of the position NEES
  std::size_t n = 0;   ///< measurements pooled
  std::size_t unreported = 0;  ///< settled measurements without a reported (confirmed) estimate
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
