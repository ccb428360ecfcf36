#pragma once
// The dart experiment of [L] §VI as a MEASUREMENT-LEVEL scenario: darts are
// thrown at a board, their true flights come from the ballistic model (with
// optional white acceleration noise), and the detected pixels are generated
// from the true trajectory through each calibrated camera (with distortion) +
// Gaussian pixel noise + gross outliers anywhere in the image. No images are
// rendered or detected here (that is the vision/sim issue's job): this is the
// tracker's statistical test bench, used by apps/dart_tracking and
// tests/tracking.
//
// Experiments (every run has its own seed: deriveSeed(seed, run)):
//  A consistency  alternating cameras ([L] §VI.A: camera 1 at odd 100 Hz steps,
//                 camera 2 at even ones), no outliers: NEES (one sample per run
//                 at a fixed measurement index, so the samples are
//                 independent), position RMSE against the posterior
//                 Cramér-Rao bound computed from the true trajectories.
//  B gates        alternating cameras, gross outliers: the directional gate and
//                 the Mahalanobis gate on the same data, plus the image-space
//                 EKF baseline.
//  C async        free-running unsynchronised clocks (drift, phase, jitter), no
//                 outliers: exact propagation vs Δt-offset rows vs image EKF.
//  D scenario     the full scenario (free-running clocks, jitter, outliers) with
//                 the configured gate, in capture order and in arrival order
//                 (capture + U(0, max delay)): maximum difference of the final
//                 states and of the per-measurement decisions.
//  E single cam   one camera, priors up to `single_offset_max` off (position and
//                 velocity), P0 = std² I, vs a filter started at the truth.

#include <Eigen/Core>
#include <cstdint>
#include <functional>
#include <string>
#include <vector>

#include "viewline/core/camera.h"
#include "viewline/core/random.h"
#include "viewline/core/statistics.h"
#include "viewline/tracking/tracker.h"

namespace viewline::tracking {

struct DartCameraConfig {
  std::string name = "camera";
  Eigen::Vector3d eye_w = Eigen::Vector3d::Zero();     ///< camera centre, world, m
  Eigen::Vector3d target_w = Eigen::Vector3d::UnitX(); ///< look-at point, world, m
  double hfov_rad = 1.0;
  unsigned width = 656;
  unsigned height = 480;
  double kud = 0.0;            ///< ViSP undistortion coefficient (pixel -> metre)
  double rate_hz = 50.0;
  double clock_drift_std = 1e-4;  ///< relative frequency error of the free-running clock (std)
  double jitter_std_s = 0.5e-3;   ///< capture-time jitter (std), s
};

struct DartScenarioConfig {
  std::vector<DartCameraConfig> cameras;
  Eigen::Vector3d gravity_w{0.0, 0.0, -9.81};
  // Throws.
  Eigen::Vector3d release_mean{0.0, 0.0, 1.75};
  Eigen::Vector3d release_std{0.05, 0.05, 0.05};
  Eigen::Vector3d board_center{2.37, 0.0, 1.73};
  double aim_std = 0.1;        ///< m, spread of the aim point on the board (y and z)
  double speed_min = 12.0;     ///< m/s
  double speed_max = 16.0;
  double truth_accel_psd = 0.0;  ///< white acceleration of the true flights, m²/s³
  // Detection.
  double pixel_noise_px = 0.5;
  double outlier_rate = 0.05;
  // Tracker (its prior, gate, model...). tracker.model.gravity_w is set from gravity_w.
  TrackerConfig tracker;
  double dt_offset_period = 0.01;  ///< grid of the Δt-offset filter, s
  // Experiments.
  double alternate_step = 0.01;    ///< s between alternating images (camera rate = 1/(2 step))
  double late_max_delay = 0.1;     ///< s
  double late_horizon = 0.15;      ///< s
  std::size_t single_camera = 0;
  double single_offset_max = 70.0;  ///< m (and m/s for the velocity)
  double single_prior_std = 100.0;  ///< m
  double single_tolerance = 0.05;   ///< m
  std::size_t nees_index = 9;       ///< measurement (0-based) at which each run gives its NEES sample
  std::size_t settled_index = 4;    ///< RMSE / PCRLB pooled over measurements with index >= this
  double confidence = 0.99;
  /// Throws core::InvalidInput naming the field.
  void validate() const;
};

/// A default rig and throw (two cameras of 656x480 at 50 Hz, 2-3 m from the thrower).
DartScenarioConfig defaultDartScenario();
/// The cameras of the scenario (lookAt poses, intrinsics from the field of view, kud).
std::vector<core::Camera> makeDartCameras(const DartScenarioConfig& cfg);

/// One generated detection with its truth.
struct SimDetection {
  ImageMeasurement m;
  bool outlier = false;
  Vector6 truth;  ///< true state at the capture time
};

/// A generated flight: detections in capture-time order.
struct SimFlight {
  std::vector<SimDetection> detections;
  double duration = 0.0;
};

enum class ClockMode { Alternating, FreeRunning, SingleCamera };
/// Draws a throw and its detections (in-image only) for the given clock mode.
SimFlight simulateFlight(const DartScenarioConfig& cfg, const std::vector<core::Camera>& cameras,
                         ClockMode mode, double outlier_rate, core::Rng& rng, std::uint64_t first_id = 1);

/// Position PCRLB trace (m²) after each detection of a flight (bound from the true states,
/// pixel measurement with σ² I, prior P0 = cfg.tracker.prior_cov, process noise of the truth).
std::vector<double> positionPcrlb(const DartScenarioConfig& cfg, const std::vector<core::Camera>& cameras,
                                  const SimFlight& flight);

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

/// One logged detection (for --log): experiment, run, detection and the estimate after it.
struct DartLogRow {
  std::string experiment;
  int run = 0;
  SimDetection det;
  Fate fate = Fate::Fused;
  Vector6 estimate;
};

struct DartRunCallbacks {
  std::function<void(int done, int total)> progress;  ///< after each run
  std::function<void(const DartLogRow&)> log;         ///< per processed detection (optional)
};

/// Runs experiments A-E for `runs` seeded runs.
DartSummary runDartExperiments(const DartScenarioConfig& cfg, std::uint64_t seed, int runs,
                               const DartRunCallbacks& cb = {});

}  // namespace viewline::tracking
