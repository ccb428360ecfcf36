#pragma once
// Pan-tilt tracking scenario ([T], SPEC §5, issue 6): the closed loop at the
// camera frame rate, in library code so that the app and the tuning tool run
// the same thing (a plain config struct + a seed -> metrics).
//
// World (frame f = the unit's base frame of vpPtu46: x forward, y left, z up):
// a vertical screen at `screen.distance` along +x_f, its centre at height
// `screen.center_height`; screen frame x right (−y_f), y down (−z_f), z into the
// screen (+x_f). A dark disc moves on it along a sim::ScreenPath (rectangle,
// circle, random polyline) at constant speed. Rendered by sim::CameraRig
// (ray-cast, anti-aliased, sensor noise) through the camera on the simulated
// FLIR PTU-D46 (pose from vpPtu46 at the capture time).
//
// One frame k (capture time t_k = k / fps):
//   1. render; detect with [T]'s pipeline (vision::ScreenTargetDetector: crop,
//      resize 50 %, binarise, median, centroid);
//   2. back-project the centroid through the capture-time camera onto the
//      screen plane -> m_k (screen coordinates, m);
//   3. add [T]'s measurement noise: m̃_k = m_k + n_k, n_k ~ N(0, diag(σx², σy²)),
//      σ_axis = noise_fraction · A_axis, where A_axis = (max − min) / 2 of the
//      true path along that axis ("white noise of 10 % of the signal amplitude"),
//      taken over one lap for the rectangle and circle, over the run for the random path;
//      the noisy feature s̃_k is m̃_k projected into the capture-time camera;
//   4. the controller observes (s̃_k, m̃_k, diag(σx², σy²)) stamped t_k, and at
//      t_k + processing_delay issues a joint velocity command to the unit,
//      which applies it after the unit's latency.
//
// Metrics (after `metrics_start`, and outside [occlusion start, end + 2 s]):
//   rmse_measured_cm    RMS of m̃_k − truth per axis (frames with a detection)
//   rmse_filtered_cm    RMS of the filter's x(k|k) − truth per axis (same frames, including those whose
//                       measurement the gate rejected: then x(k|k−1); ours only)
//   image_error_rms_px  RMS distance of the *true* target projection from the
//                       principal point, all frames (target off-image included)
// Occlusion: the disc is not rendered during [occlusion_start, + duration);
// reacquired when a measurement is accepted after it, with the delay from the
// occlusion's end.
//
// Calibrated, imperfect parameters (issue 9). With `rig: <folder>` (a default
// simulated rig, scenarios::loadSimulatedRig; calib/rigs/pan_tilt), the simulator
// renders through the TRUE camera of truth.yaml (intrinsics with kud distortion,
// the camera mounted at the true e_M_c on the unit), while everything the
// controllers compute uses the CALIBRATED camera (rig.yaml: intrinsics, kdu) and
// the CALIBRATED hand-eye (e_M_c.yaml): step 2's back-projection goes through
// c_M_f(q) of the calibrated mount at the encoder reading q of the capture stamp,
// and both laws use the calibrated kinematics (cVe, pointAt, c_M_f). The truth
// (image error, truth_px) is always measured with the true camera, from its
// true principal point. Without `rig:`, the inline camera keys (width, height, fx,
// fy; principal point at the image centre, no distortion) and vpPtu46's nominal
// camera mount are used by both the simulator and the controllers.

#include <Eigen/Geometry>
#include <cstdint>
#include <functional>
#include <optional>
#include <nlohmann/json.hpp>
#include <opencv2/core.hpp>
#include <string>

#include "viewline/control/pan_tilt_servo.h"
#include "viewline/core/camera.h"
#include "viewline/io/config.h"
#include "viewline/io/log.h"
#include "viewline/robots/simulated_pan_tilt.h"
#include "viewline/sim/physics.h"
#include "viewline/vision/screen_target_detector.h"

namespace viewline::scenarios {

struct PanTiltScenarioConfig {
  // World
  sim::ScreenPathParams path;            ///< shape, speed, centre, width/height, radius (duration set by the run)
  double screen_distance = 1.3;          ///< m
  double screen_center_height = -0.26;   ///< m (z_f)
  double screen_width = 2.4, screen_height = 1.8;  ///< m
  double disc_radius = 0.03;             ///< m
  // Camera
  unsigned image_width = 640, image_height = 480;
  double fx = 944.0, fy = 928.0;         ///< px ([T])
  double fps = 30.0;
  double sensor_noise = 2.0;             ///< grey levels
  double exposure = 0.0;                 ///< s (motion blur)
  // Rig (issue 9; all set together by `rig:`, or none): the simulator's and the controllers'
  // camera (intrinsics and image size) and camera mount on the unit. Unset: the inline camera
  // above and vpPtu46's nominal mount for both. (image_width/height, fx, fy then hold the true
  // camera's values, for reporting.)
  std::string rig_folder;
  std::optional<core::Camera> true_camera, calibrated_camera;
  std::optional<Eigen::Isometry3d> true_e_M_c, calibrated_e_M_c;
  // Measurement noise ([T])
  double noise_fraction = 0.10;
  // Unit
  robots::SimulatedPanTiltParams unit;   ///< limits, latency (q0 set from initial_offset)
  Eigen::Vector2d initial_offset = Eigen::Vector2d::Zero();  ///< rad from pointing at the start point
  double processing_delay = 0.01;        ///< s from capture to command
  // Detection
  vision::ScreenTargetDetectorConfig detector;
  // Control (the baseline uses control.servo)
  control::PredictiveConfig control;
  // Run
  double duration = 60.0;                ///< s
  double metrics_start = 5.0;            ///< s
  double occlusion_start = -1.0;         ///< s (< 0: none)
  double occlusion_duration = 1.0;       ///< s
  bool run_baseline = true;

  void validate() const;  ///< throws core::InvalidInput naming the field
};

/// Reads every key of a pan-tilt scenario file (documented in config/pan_tilt_rectangle.yaml)
/// and calls finish() (unknown keys rejected with file:line:key).
PanTiltScenarioConfig loadPanTiltScenarioConfig(const io::ConfigNode& root);

/// The camera (intrinsics, size; identity pose) the simulator renders with, and the one the
/// controllers believe in (the calibrated one with a rig; the same inline camera without).
core::Camera panTiltTrueCamera(const PanTiltScenarioConfig& config);
core::Camera panTiltModelCamera(const PanTiltScenarioConfig& config);

enum class PanTiltControllerKind { Predictive, Baseline };

/// What one frame looked like (for live display).
struct PanTiltFrameView {
  const cv::Mat* image = nullptr;  ///< BGR as rendered
  double t = 0.0;
  std::string controller;
  bool detected = false;
  Eigen::Vector2d measured_px = Eigen::Vector2d::Zero();   ///< detection + [T] noise, in this image
  Eigen::Vector2d truth_px = Eigen::Vector2d::Zero();
  bool has_prediction = false;
  Eigen::Vector2d predicted_px = Eigen::Vector2d::Zero();  ///< ŝ at the effect time, in pixels
  Eigen::Vector2d principal_px = Eigen::Vector2d::Zero();
  double error_px = 0.0;                                   ///< |truth − principal point|
  std::string mode;
};
using PanTiltFrameSink = std::function<void(const PanTiltFrameView&)>;

struct PanTiltRunMetrics {
  std::string controller;
  std::size_t frames = 0, detections = 0, metric_frames = 0;
  double image_error_rms_px = 0.0, image_error_max_px = 0.0;
  Eigen::Vector2d rmse_measured_cm = Eigen::Vector2d::Zero();
  Eigen::Vector2d rmse_filtered_cm = Eigen::Vector2d::Constant(std::nan(""));
  Eigen::Vector2d noise_sigma_cm = Eigen::Vector2d::Zero();
  double detection_pixel_rmse_px = 0.0;  ///< detector error (before [T] noise) vs the true centre projection
  // limits
  std::size_t commands = 0, unsafe_commands = 0, rate_violations = 0, limit_hits = 0;
  double max_rate_fraction = 0.0;            ///< max |q̇ cmd| / q̇max
  Eigen::Vector2d min_limit_distance_deg = Eigen::Vector2d::Constant(1e9);  ///< (pan, tilt)
  Eigen::Vector2d pan_range_deg = Eigen::Vector2d::Zero(), tilt_range_deg = Eigen::Vector2d::Zero();
  // occlusion
  bool occlusion = false, reacquired = false;
  double reacquisition_delay_s = std::nan("");
  std::size_t reacquisitions = 0;
  std::size_t frames_searching = 0;
  std::size_t filter_jumps = 0;              ///< velocity jumps (corners) the filter detected (ours)
  /// Ours, Kalman models with jump detection: the corner settings in force at the end of the run (the
  /// configured filter.jump_min_samples / jump_corner_sigma, or what "auto" made of them); 0 otherwise.
  int filter_min_samples = 0;
  double filter_corner_sigma = 0.0;
  bool filter_region_dropped = false;        ///< ours: filter.region was dropped (the target left it: a wrong box)
  double wall_ms_per_frame = 0.0;

  nlohmann::json toJson() const;
};

/// Runs one controller on the scenario; deterministic for (config, seed): both controllers see the
/// same path, sensor noise stream and [T] noise draws for the same frame index.
PanTiltRunMetrics runPanTilt(const PanTiltScenarioConfig& config, std::uint64_t seed, PanTiltControllerKind kind,
                             const PanTiltFrameSink& sink = nullptr, io::LogDirectory* log = nullptr,
                             const std::function<void(double)>& progress = nullptr);

struct PanTiltComparison {
  PanTiltRunMetrics ours, baseline;
  bool has_baseline = false;
  std::string path;
  std::uint64_t seed = 0;
  /// The summary (issue 6 keys: rmse_measured_cm, rmse_filtered_cm, image_error_rms_px,
  /// baseline_image_error_rms_px, [T]'s Table 1 beside ours, limits, occlusion).
  nlohmann::json toJson(const PanTiltScenarioConfig& config) const;
};

/// Ours, then (when config.run_baseline) ViSP's law on the same seed.
PanTiltComparison runPanTiltComparison(const PanTiltScenarioConfig& config, std::uint64_t seed,
                                       const PanTiltFrameSink& sink = nullptr, io::LogDirectory* log = nullptr,
                                       const std::function<void(double)>& progress = nullptr);

/// Filter-only replay: the predictive controller's target filter (same config, same reacquisition
/// rule) re-run on the measurements of a logged run (`<log>/predictive_frames.csv` of
/// pan_tilt_tracking --log), scored against the path of `seed` with the run's metric windows.
/// Used to compare filters on identical measurements without rendering; the closed loop is not
/// re-run (the measurements depend on it only through the detector's sub-pixel error). A log whose truth
/// columns are not the path of `seed` (another seed, shape, size or speed) is refused (core::InvalidInput).
struct PanTiltReplayMetrics {
  std::size_t measurements = 0, jumps = 0;
  Eigen::Vector2d rmse_measured_cm = Eigen::Vector2d::Zero(), rmse_filtered_cm = Eigen::Vector2d::Zero();
  double horizon_s = 0.0;  ///< processing delay + latency + lead: how far ahead the law predicts
  Eigen::Vector2d rmse_predicted_cm = Eigen::Vector2d::Zero();  ///< x(t + horizon | t) − truth, every frame
  double predicted_error_px = 0.0;  ///< its RMS norm × fx / screen distance (px near the image centre)
  /// The horizon the image error sees: a command issued after capture t acts from t + processing delay +
  /// latency, so the first frame it moves is n frames later, n = ⌊(processing delay + latency) fps⌋ + 1
  /// (66.7 ms at 40 ms and 30 fps), and each frame's error is set by a prediction that old.
  double frame_horizon_s = 0.0;
  double frame_predicted_error_px = 0.0;  ///< as predicted_error_px, at frame_horizon_s
  bool region_dropped = false;            ///< the filter dropped filter.region (the target left it)
  int min_samples = 0;                    ///< the filter's corner settings at the end (see PanTiltRunMetrics)
  double corner_sigma = 0.0;
  nlohmann::json toJson() const;
};
/// What a replay runs on the logged measurements.
enum class PanTiltReplayEstimator {
  /// The config's filter (the predictive controller's, same reacquisition rule).
  Filter,
  /// Rectangle and random paths: a bound, a constant-speed leg filter told the path's true corner times
  /// and speed (control::PlanarTargetFilter::startLeg); `jumps` is then the number of corners. No causal
  /// filter that must detect the corners can expect to beat it.
  OracleCorners,
  /// Random path: control::WaypointParticleFilter, the posterior mean under the path's generator
  /// (waypoints uniform in filter.region, one constant speed), the causal reference; `jumps` is 0.
  WaypointParticles,
};
/// With a log, writes the stream replay_frames (t, truth, detected, measurement, the estimator's output,
/// accepted, jumps so far) for per-frame comparisons. `particles`: the particle count of
/// WaypointParticles.
PanTiltReplayMetrics replayPanTiltFilter(const PanTiltScenarioConfig& config, std::uint64_t seed,
                                         const std::string& frames_csv,
                                         PanTiltReplayEstimator estimator = PanTiltReplayEstimator::Filter,
                                         io::LogDirectory* log = nullptr, std::size_t particles = 20000);

/// [T] Table 1 (RMSE in cm, (x, y)): noisy measurement and Kalman filter; nothing for the random path.
struct TTable1Row {
  bool available = false;
  Eigen::Vector2d measured = Eigen::Vector2d::Zero(), kalman = Eigen::Vector2d::Zero();
};
TTable1Row tTable1(sim::PathShape shape);

/// "rectangle", "circle" or "random" (the config's path.shape).
const char* pathShapeName(sim::PathShape shape);

/// Per-axis amplitude A = (max − min)/2 of a path's true position over [0, duration] (m).
Eigen::Vector2d pathAmplitude(const sim::ScreenPath& path, double duration);

}  // namespace viewline::scenarios
