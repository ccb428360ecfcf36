#pragma once
// Mobile capture: the figures of the scenario. The batch of chases against the oracle, [K]'s
// filter test, the field-of-view sweep of the ground localisation, and the summary JSON.

#include <cstdint>
#include <functional>
#include <string>
#include <vector>

#include "viewline/io/log.h"
#include "viewline/scenarios/mobile_capture/loop.h"
#include "viewline/scenarios/mobile_capture/recording.h"

namespace viewline::scenarios {

/// One run of [K]'s filter test: RMSE of the unicycle track's states and the error time series.
struct FilterTestResult {
  // RMSE after convergence_time, against the true inputs and against the nominal profile.
  double rmse_theta = 0.0,  ///< heading RMSE, rad
         rmse_v = 0.0,      ///< speed RMSE against the true (noisy) input, m/s
         rmse_omega = 0.0;  ///< turn-rate RMSE against the true input, rad/s
  double rmse_theta_moving = 0.0;      ///< θ only where the true speed is >= 5 cm/s (heading observable)
  double rmse_v_nominal = 0.0,      ///< speed RMSE against the nominal profile, m/s
         rmse_omega_nominal = 0.0;  ///< turn-rate RMSE against the nominal profile, rad/s
  double rmse_position = 0.0;          ///< m, filtered position
  double rmse_measurement = 0.0;       ///< m, raw measured position (for comparison)
  // Error time series of the run (t, θ, v, ω errors, estimate - truth).
  std::vector<double> t,          ///< s, time of each filter step
                      err_theta,  ///< heading error, rad
                      err_v,      ///< speed error, m/s
                      err_omega;  ///< turn-rate error, rad/s
};
/// [K] §3.2: the FilterTest profile, positions measured every vision period with the filter
/// test's noise (no images), the scenario's track (its gate opened to 1 − 1e-9).
FilterTestResult runFilterTest(const MobileCaptureConfig& cfg, std::uint64_t seed);
/// The error series as filter_test.csv (t, err_theta, err_v, err_omega) in `log`.
void logFilterTest(const FilterTestResult& f, io::LogDirectory& log);

/// Ground-localisation errors of the field-of-view sweep, over the whole image and by region.
struct FovSweepResult {
  LocalizationErrors all,     ///< every projected floor point
                     centre,  ///< points with |u - W/2| < W/6 and |v - H/2| < H/6
                     border;  ///< the other points
};
/// The field-of-view sweep: floor points seen from random head and base poses (fov_sweep_*),
/// localised by the exact back-projection and by [K]'s angle-per-pixel method, against the truth.
FovSweepResult compareGroundLocalization(const MobileCaptureConfig& cfg, std::uint64_t seed);

/// A batch's figures: capture success and time against the oracle, filter test, FOV sweep.
struct MobileCaptureSummary {
  std::vector<MobileCaptureRun> runs;  ///< every completed run, in seed order
  bool interrupted = false;            ///< a stop request ended the batch early (runs holds those that completed)
  double success_rate = 0.0,         ///< fraction of runs captured before max_time
         oracle_success_rate = 0.0;  ///< the same for the oracle
  double ratio_median = 0.0,  ///< median capture time / oracle's, over runs where both captured
         ratio_p95 = 0.0;     ///< over runs where both captured
  int ratio_runs = 0;  ///< runs in the ratio statistics (both captured)
  double time_median = 0.0,         ///< s, median capture time of the captured runs
         time_p95 = 0.0,            ///< s, 95th percentile of the same
         oracle_time_median = 0.0;  ///< s, median capture time of the oracle's captures
  LocalizationErrors localization;              ///< in the loop, all runs
  FilterTestResult filter_first;                ///< first filter-test run (time series)
  double filter_rmse_theta_moving = 0.0;  ///< rad, mean over the filter-test runs (moving only)
  double filter_rmse_theta = 0.0,  ///< rad, mean over the filter-test runs
         filter_rmse_v = 0.0,      ///< m/s, mean over the filter-test runs
         filter_rmse_omega = 0.0;  ///< mean over runs
  double filter_rmse_v_nominal = 0.0,      ///< m/s, against the nominal profile, mean over runs
         filter_rmse_omega_nominal = 0.0;  ///< rad/s, against the nominal profile, mean over runs
  double filter_rmse_position = 0.0,     ///< m, filtered position, mean over runs
         filter_rmse_measurement = 0.0;  ///< m, raw measurements, mean over runs
  FovSweepResult fov;  ///< the field-of-view sweep
  double wall_time = 0.0;                       ///< s
};

/// `runs` runs with seeds deriveSeed(seed, i) on cfg.threads threads, the filter test
/// (cfg.filter_test_runs seeds) and the field-of-view sweep. `progress(done, total)` is called
/// from the worker threads (serialised). `io`: record the runs into a new session recording, or run
/// on one (recording.h; the config's `source:` names one too), run i in DIR/run_iii.
MobileCaptureSummary runMobileCaptureBatch(const MobileCaptureConfig& cfg, int runs, std::uint64_t seed,
                                           const std::function<void(int, int)>& progress = nullptr,
                                           const MobileCaptureSessionIo& io = {});

/// The summary as JSON text.
std::string summaryJson(const MobileCaptureSummary& s, const MobileCaptureConfig& cfg, int indent = 2);
/// The summary as the few lines a person reads (what the app prints).
std::string summaryText(const MobileCaptureSummary& s, const MobileCaptureConfig& cfg, int runs, std::uint64_t seed);

}  // namespace viewline::scenarios
