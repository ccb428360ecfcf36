#pragma once
// Mobile-capture scenario (SPEC §4, [K], issue 8): a differential-drive robot with a pan/tilt
// camera chases a red 8x6 cm object that moves on the floor with [K]'s speed and turn-rate
// profiles, and grasps it with a front gripper.
//
// One run (runMobileCapture), simulation time t in s, world frame z up, floor z = 0:
//   every control period (10 ms): wheel PID + motors (robots::DifferentialDrive), head joints
//     (rate-limited servo to the set point), base law to the capture point (control::goToPoint),
//     head set point = IK towards the filter's prediction of the object at the next tick;
//   every vision period (100 ms): the head camera's image is *rendered* (sim::GroundWorld,
//     sim::Renderer, sensor noise), the red blob is detected (vision::BallDetector with a red HSV
//     range, contour centroid), its pixel back-projected onto the plane of the object's centre
//     (robots::groundPointExact with the camera pose from odometry and the joint encoders), the
//     curvilinear EKF (estimation::UnicycleModel) is updated (innovation gate), the
//     least-squares predictor (estimation::UnicycleTrajectoryPredictor) rolls the path forward
//     M steps and the capture point is replanned ([K] eq 30, planning::planCapture);
//   lost target: control::SearchPattern (look at the prediction, then sweep; base turns).
//   Grasp: when the *estimated* object lies in the gripper's trigger zone, the gripper closes;
//   the grasp succeeds when the *true* object lies in the jaw zone (robot frame), else the
//   attempt is counted and the chase goes on.
//
// Oracle (same seed, same object path): the same planner, base law, robot and grasp rule, fed
// the object's true current position and true future path (no camera, no filter).
// capture_time_ratio_to_oracle = our capture time / the oracle's.
//
// [K]'s profiles (sim::GroundTarget): k is the index of the 100 ms vision/filter step
// (t = 0.1 k s); v in cm/s, ω in rad/s; ξv, ξω are drawn once per step k, independent, with
// variances in (cm/s)² and (rad/s)²: Capture 2 and 0.1, FilterTest 3 and 0.1. The filter test's
// measurement noise variance 2 is in cm² per axis of the measured floor position.
//
// Filter test ([K] §3.2, runFilterTest): the FilterTest profile, positions measured every 100 ms
// with that noise (no images), the same EKF; errors of θ, v, ω over time and their RMSE after a
// convergence time, against the true (noisy) inputs and against the nominal profile.
//
// Camera parameters (issue 9). Inline camera keys (width, height, hfov_deg, vfov_deg): one
// perfect pinhole camera renders and estimates. With `rig: <folder>` (calib/rigs/mobile): the
// renderer uses the TRUE head camera of truth.yaml (intrinsics with barrel distortion) on the
// true head (the DH chain of robots::MobilePanTilt: truth.yaml's pose is that chain at a rest
// joint position q0, found and checked at load), and every estimator uses the CALIBRATED camera:
// rig.yaml's intrinsics, and a pose from the camera-to-ground calibration taken at q0
// (rig.yaml's c_M_w = ground.yaml's c_M_g placed at the surveyed board spot). The calibrated pose
// differs from the DH camera at q0 by a fixed correction of the camera on its mount,
//   c'_M_c = c_M_w_cal · c_M_w_DH(q0)⁻¹,
// so the estimators' camera at joints q and base pose b is  c'_M_w(q, b) = c'_M_c · c_M_w_DH(q, b).
// The angle-per-pixel method then uses the calibrated fields of view (2 atan(W / 2 px), ...).
//
// Ground localisation: every detection is also located with [K]'s angle-per-pixel formula
// (printed slant range and corrected horizontal range); errors against the true object centre.
// compareGroundLocalization additionally sweeps the field of view with projected floor points.

#include <Eigen/Core>
#include <cstdint>
#include <functional>
#include <limits>
#include <optional>
#include <opencv2/core.hpp>
#include <string>
#include <vector>

#include "viewline/control/mobile_capture_control.h"
#include "viewline/core/camera.h"
#include "viewline/io/config.h"
#include "viewline/io/log.h"
#include "viewline/planning/capture_planner.h"
#include "viewline/robots/differential_drive.h"
#include "viewline/robots/mobile_pan_tilt.h"
#include "viewline/vision/ball_detector.h"

namespace viewline::scenarios {

/// Gripper zones in the robot frame (x forward from the axle centre, y left), m.
struct GripperZone {
  double x_min = 0.12, x_max = 0.28, half_width = 0.07;
  bool contains(const Eigen::Vector2d& p_r) const {
    return p_r.x() >= x_min && p_r.x() <= x_max && std::abs(p_r.y()) <= half_width;
  }
};

struct MobileCaptureConfig {
  // Start ([K]) and world.
  Eigen::Vector2d robot_start = Eigen::Vector2d(-0.5, -0.5);  ///< m
  double robot_heading = 1.5707963267948966;                 ///< rad
  Eigen::Vector2d object_start = Eigen::Vector2d(-2.5, 3.0);  ///< m
  double object_heading = 0.0;                                ///< rad
  bool object_noise = true;             ///< ξv, ξω on (else the nominal profile)
  double max_time = 90.0;               ///< s; a run without capture by then is a failure
  double floor_size = 30.0;             ///< m (textured floor square centred at the origin)
  /// Camera blackout (lens covered: frames give no detection) on [start, start + duration), s;
  /// start < 0: none. Exercises losing the target and finding it again.
  double blackout_start = -1.0, blackout_duration = 0.0;

  // Timing.
  double vision_period = 0.1;           ///< s ([K]); also the profile step and the planner's T
  double control_period = 0.01;         ///< s ([K]: wheel PID every 10 ms)

  // Camera (320x240, 50° x 40°).
  unsigned width = 320, height = 240;
  double hfov = 0.8726646259971648;     ///< rad (50°)
  double vfov = 0.6981317008965228;     ///< rad (40°)
  double sensor_noise = 2.0;            ///< grey levels (std)
  int supersampling = 2;                ///< renderer anti-aliasing sub-samples on edges

  /// Calibrated rig (key `rig`): replaces width, height, hfov, vfov (see the header comment).
  struct RigCameras {
    std::string folder;
    core::Camera truth;                 ///< renders (intrinsics; its pose is the DH head at q0)
    core::Camera calibrated;            ///< estimators (intrinsics; c_M_w = calibrated pose at q0)
    robots::PanTiltJoints q0;           ///< head joints of truth.yaml's pose
    Eigen::Isometry3d cal_M_c = Eigen::Isometry3d::Identity();  ///< c'_M_c, calibrated vs DH camera
  };
  std::optional<RigCameras> rig;

  // Robot.
  robots::MobilePanTiltParams head;
  robots::DifferentialDriveParams base;
  GripperZone jaws;                                 ///< grasp succeeds when the true object is here
  GripperZone trigger{0.14, 0.26, 0.045};           ///< grasp is attempted when the estimate is here
  double grasp_cooldown = 0.5;                      ///< s after a failed grasp

  // Detection.
  vision::BallDetectorConfig detector;  ///< red HSV range etc. (set in defaults())
  double pixel_sigma = 1.0;             ///< px, blob centre noise used for the measurement covariance
  double floor_sigma = 0.01;            ///< m, added floor-position std (blob centroid vs centre)
  double object_height = 0.05;          ///< m: measurements on the plane z = height / 2

  // Estimation.
  double q_v = 0.01;                    ///< EKF speed random-walk intensity, m²/s³
  double q_w = 0.5;                     ///< EKF turn-rate random-walk intensity, rad²/s³
  double init_speed = 0.3, init_speed_sigma = 0.3;   ///< m/s
  double init_turn_sigma = 1.0;         ///< rad/s
  double gate_probability = 0.999;      ///< innovation gate (chi-square, 2 dof)
  int predictor_window = 10;            ///< LS samples (1 s)
  /// The LS accelerations are used only once the window is full, clamped to these (physically
  /// plausible) bounds; 0 switches them off (constant v, ω prediction).
  double max_accel_v = 0.1;             ///< m/s²
  double max_accel_omega = 0.5;         ///< rad/s²
  int horizon_steps = 200;              ///< M of [K] eq 30

  // Planning and control.
  planning::CapturePlannerParams planner;
  control::GoToPointParams go;
  control::SearchParams search;

  // Filter test ([K] §3.2).
  double filter_test_duration = 60.0;        ///< s
  double filter_test_measurement_var = 2.0;  ///< cm² per axis
  double filter_test_q_v = 0.003;            ///< m²/s³ (ξv variance 3 (cm/s)² per 0.1 s step)
  double filter_test_q_w = 1.0;              ///< rad²/s³ (ξω variance 0.1 (rad/s)² per step)
  double convergence_time = 10.0;            ///< s: RMSE is taken after this
  int filter_test_runs = 20;

  // Field-of-view sweep of the ground localisation.
  int fov_sweep_poses = 50;             ///< random head/base poses
  int fov_sweep_points = 200;           ///< floor points per pose
  double fov_sweep_pixel_sigma = 0.5;   ///< px noise added to the projected pixels

  int threads = 2;                      ///< parallel runs in runMobileCaptureBatch

  /// The defaults above plus [K]'s red-object detector settings.
  static MobileCaptureConfig defaults();
  /// Throws core::InvalidInput naming the field.
  void validate() const;
};

/// Reads the YAML keys documented in config/mobile_capture.yaml (unknown keys rejected).
/// `rig:` (folder relative to the config file) loads truth.yaml, rig.yaml and ground.yaml; with it
/// the camera's width, height, hfov_deg and vfov_deg keys are errors.
MobileCaptureConfig loadMobileCaptureConfig(const io::ConfigNode& root);

/// Loads the head camera of a mobile rig folder for the head `head` (see the header comment);
/// throws core::InvalidInput when truth.yaml's pose is not the DH head camera at some joints
/// (1 mm, 0.05°) or ground.yaml disagrees with rig.yaml.
MobileCaptureConfig::RigCameras loadMobileRig(const std::string& folder, const robots::MobilePanTiltParams& head);

/// Ground-localisation error accumulator (squared errors against truth, m²).
struct LocalizationErrors {
  double sse_exact = 0.0, sse_printed = 0.0, sse_horizontal = 0.0;
  long count = 0;
  void add(const LocalizationErrors& o) {
    sse_exact += o.sse_exact, sse_printed += o.sse_printed, sse_horizontal += o.sse_horizontal, count += o.count;
  }
};

/// What a display or a logger sees at each vision step (our run only).
struct MobileCaptureFrame {
  double t = 0.0;
  const cv::Mat* image = nullptr;           ///< rendered camera image (BGR)
  bool detected = false;
  Eigen::Vector2d pixel = Eigen::Vector2d::Zero();
  robots::BasePose robot;
  robots::PanTiltJoints joints;
  Eigen::Vector2d object_true = Eigen::Vector2d::Zero();
  bool fused = false;  ///< this frame's measurement passed the gate and was fused
  /// NIS d' S⁻¹ d of this frame's measurement against the predicted track (2 dof, S = R + P_pos),
  /// fused or gated out; NaN without a measurement or without a track to test it against.
  double nis = std::numeric_limits<double>::quiet_NaN();
  bool estimate_valid = false;
  Eigen::VectorXd estimate;                 ///< (x, y, θ, v, ω)
  std::vector<Eigen::Vector2d> prediction;  ///< p(k+1..k+M)
  planning::CapturePlan plan;
  control::SearchMode mode = control::SearchMode::Tracking;
};

struct MobileCaptureHooks {
  std::function<void(const MobileCaptureFrame&)> on_frame;  ///< called after every vision step
  io::LogDirectory* log = nullptr;                          ///< CSV streams (truth, measurements, estimates, plan)
};

struct MobileCaptureRun {
  std::uint64_t seed = 0;
  bool captured = false;
  double capture_time = 0.0;           ///< s (max_time when not captured)
  bool oracle_captured = false;
  double oracle_time = 0.0;
  int grasp_attempts = 0;              ///< including the successful one
  int frames = 0, detections = 0;
  double longest_lost = 0.0;           ///< s, longest gap between detections after the first one
  LocalizationErrors localization;
};

/// One run of our loop and of the oracle with the same object path (seed).
MobileCaptureRun runMobileCapture(const MobileCaptureConfig& cfg, std::uint64_t seed,
                                  const MobileCaptureHooks* hooks = nullptr);

/// The oracle alone: capture time of the planner fed the true path (nullopt: no capture).
struct OracleResult {
  bool captured = false;
  double time = 0.0;
};
OracleResult runOracle(const MobileCaptureConfig& cfg, std::uint64_t seed);

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
FilterTestResult runFilterTest(const MobileCaptureConfig& cfg, std::uint64_t seed);

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

/// The summary as JSON-ready key/values (keys of issue 8) — filled by the app into nlohmann::json.
std::string summaryJson(const MobileCaptureSummary& s, const MobileCaptureConfig& cfg, int indent = 2);

/// Percentile (linear interpolation, p in [0, 1]) of a non-empty sample.
double percentile(std::vector<double> v, double p);

}  // namespace viewline::scenarios
