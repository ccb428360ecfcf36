#pragma once
// Mobile capture: the figures of the scenario. The batch of chases against the oracle, [K]'s
// filter test, the field-of-view sweep of the ground localisation, and the summary JSON.

#include <cstdint>
#include <functional>
#include <string>
#include <vector>

#include "viewline/io/log.h"
#include "viewline/scenarios/mobile_capture/loop.h"

namespace viewline::scenarios {

struct FilterTestResult {
  // RMSE after convergence_time, against the true inputs and against the nominal profile.
  double rmse_theta = 0.0, rmse_v = 0.0, rmse_omega = 0.0;
  double rmse_theta_moving = 0.0;      ///< θ only where the true speed is >= 5 cm/s (heading observable)
  double rmse_v_nominal = 0.0, rmse_omega_nominal = 0.0;
  double rmse_position = 0.0;          ///< m, filtered position
  double rmse_measurement = 0.0;       ///< m, raw measured position (for comparison)
  // Error time series of the run (t, θ, v, ω errors, estimate - truth).
  std::vector<double> t, err_theta, err_v, err_omega;
};
/// [K] §3.2: the FilterTest profile, positions measured every vision period with the filter
/// test's noise (no images), the scenario's track (its gate opened to 1 − 1e-9).
FilterTestResult runFilterTest(const MobileCaptureConfig& cfg, std::uint64_t seed);
/// The error series as filter_test.csv (t, err_theta, err_v, err_omega) in `log`.
void logFilterTest(const FilterTestResult& f, io::LogDirectory& log);

struct FovSweepResult {
  LocalizationErrors all, centre, border;  ///< centre: |u - u0| < W/6 and |v - v0| < H/6
};
FovSweepResult compareGroundLocalization(const MobileCaptureConfig& cfg, std::uint64_t seed);

struct MobileCaptureSummary {
  std::vector<MobileCaptureRun> runs;
  double success_rate = 0.0, oracle_success_rate = 0.0;
  double ratio_median = 0.0, ratio_p95 = 0.0;  ///< over runs where both captured
  int ratio_runs = 0;
  double time_median = 0.0, time_p95 = 0.0, oracle_time_median = 0.0;
  LocalizationErrors localization;              ///< in the loop, all runs
  FilterTestResult filter_first;                ///< first filter-test run (time series)
  double filter_rmse_theta_moving = 0.0;
  double filter_rmse_theta = 0.0, filter_rmse_v = 0.0, filter_rmse_omega = 0.0;  ///< mean over runs
  double filter_rmse_v_nominal = 0.0, filter_rmse_omega_nominal = 0.0;
  double filter_rmse_position = 0.0, filter_rmse_measurement = 0.0;
  FovSweepResult fov;
  double wall_time = 0.0;                       ///< s
};

/// `runs` runs with seeds deriveSeed(seed, i) on cfg.threads threads, the filter test
/// (cfg.filter_test_runs seeds) and the field-of-view sweep. `progress(done, total)` is called
/// from the worker threads (serialised).
MobileCaptureSummary runMobileCaptureBatch(const MobileCaptureConfig& cfg, int runs, std::uint64_t seed,
                                           const std::function<void(int, int)>& progress = nullptr);

/// The summary as JSON text.
std::string summaryJson(const MobileCaptureSummary& s, const MobileCaptureConfig& cfg, int indent = 2);
/// The summary as the few lines a person reads (what the app prints).
std::string summaryText(const MobileCaptureSummary& s, const MobileCaptureConfig& cfg, int runs, std::uint64_t seed);

}  // namespace viewline::scenarios
