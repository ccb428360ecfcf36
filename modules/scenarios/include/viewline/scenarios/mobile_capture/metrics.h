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

/// The filter test of [K] §3.2: RMSE after convergence_time, against the true inputs and against the nominal profile.
struct FilterTestResult {
  double rmse_theta = 0.0,  ///< heading, rad
         rmse_v = 0.0,      ///< speed, m/s
         rmse_omega = 0.0;  ///< turn rate, rad/s
  double rmse_theta_moving = 0.0;      ///< θ only where the true speed is >= 5 cm/s (heading observable)
  double rmse_v_nominal = 0.0,      ///< speed against the nominal profile, m/s
         rmse_omega_nominal = 0.0;  ///< turn rate against the nominal profile, rad/s
  double rmse_position = 0.0;          ///< m, filtered position
  double rmse_measurement = 0.0;       ///< m, raw measured position (for comparison)
  // Error time series of the run (t, θ, v, ω errors, estimate - truth).
  std::vector<double> t,          ///< time, s
                      err_theta,  ///< heading error, rad
                      err_v,      ///< speed error, m/s
                      err_omega;  ///< turn-rate error, rad/s
};
/// [K] §3.2: the FilterTest profile, positions measured every vision period with the filter
/// test's noise (no images), the scenario's track (its gate opened to 1 − 1e-9).
FilterTestResult runFilterTest(const MobileCaptureConfig& cfg, std::uint64_t seed);
/// The error series as filter_test.csv (t, err_theta, err_v, err_omega) in `log`.
void logFilterTest(const FilterTestResult& f, io::LogDirectory& log);

/// Ground-localisation errors over the field of view: exact back-projection vs [K]'s angle-per-pixel method.
struct FovSweepResult {
  LocalizationErrors all,     ///< every point
                     centre,  ///< points with |u - u0| < W/6 and |v - v0| < H/6
                     border;  ///< the other points
};
FovSweepResult compareGroundLocalization(const MobileCaptureConfig& cfg, std::uint64_t seed);

/// The batch's figures (the --summary JSON): capture rates and times against the oracle, filter test, field-of-view sweep.
struct MobileCaptureSummary {
  std::vector<MobileCaptureRun> runs;  ///< every run, in seed order
  double success_rate = 0.0,         ///< runs captured / runs
         oracle_success_rate = 0.0;  ///< runs the oracle captured / runs
  double ratio_median = 0.0,  ///< median capture time / oracle time, over runs where both captured
         ratio_p95 = 0.0;     ///< its 95th percentile
  int ratio_runs = 0;  ///< runs where both captured
  double time_median = 0.0,         ///< median capture time, s
         time_p95 = 0.0,            ///< its 95th percentile, s
         oracle_time_median = 0.0;  ///< the oracle's median capture time, s
  LocalizationErrors localization;              ///< in the loop, all runs
  FilterTestResult filter_first;                ///< first filter-test run (time series)
  double filter_rmse_theta_moving = 0.0;  ///< heading RMSE where the object moves, rad, mean over runs
  double filter_rmse_theta = 0.0,  ///< heading RMSE, rad, mean over runs
         filter_rmse_v = 0.0,      ///< speed RMSE, m/s, mean over runs
         filter_rmse_omega = 0.0;  ///< turn-rate RMSE, rad/s, mean over runs
  double filter_rmse_v_nominal = 0.0,      ///< speed RMSE against the nominal profile, m/s
         filter_rmse_omega_nominal = 0.0;  ///< turn-rate RMSE against the nominal profile, rad/s
  double filter_rmse_position = 0.0,     ///< filtered position RMSE, m
         filter_rmse_measurement = 0.0;  ///< raw measured position RMSE, m
  FovSweepResult fov;  ///< the field-of-view sweep
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
