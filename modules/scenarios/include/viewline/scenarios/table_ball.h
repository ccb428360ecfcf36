#pragma once
// The table-ball balancing scenario ([M], SPEC §3, issue 7) as library code: one call runs the
// closed loop (world physics, rendering, detection, observer, controller, metrics) for a plain
// config and a seed, so the app and the tuning tool run exactly the same code.
//
// World (SI, world z up): a robot arm holds a square table (red, raised black borders) of side
// L = 0.3 m whose untilted centre is at `table.center`; a green ball (r = 0.025 m) rolls on it
// without slipping (sim::TiltTable: a = (5/7)[t_R_w g]_xy, inelastic borders). The table's two
// tilt angles are driven by the wrist (robots::SimulatedTableTilt: delay, rate and angle
// limits). A head camera (320x240, 90° horizontal FOV: fx = fy = 160, cx = 160, cy = 120, no
// distortion, 50 fps) looks at the table from `camera.position` towards `camera.look_at` and
// sways slightly like a head (rotation amplitude `sway_deg`, translation `sway_translation`,
// incommensurate frequencies around `sway_hz`); its rotation to the ground is known to the
// observer (with optional noise `ground_rotation_noise_deg`, as from an IMU or the neck joints).
// Frames are rendered by sim::CameraRig (sensor noise, motion blur, dropped frames).
//
// Camera parameters (issue 9). Inline camera keys (width, height, hfov_deg, position, look_at):
// the renderer and the observer share one perfect camera. With `rig: <folder>` (a default
// simulated rig, calib/rigs/table): the renderer uses the TRUE head camera of truth.yaml
// (intrinsics, distortion, rest pose) and the observer the CALIBRATED one: rig.yaml's intrinsics,
// and its rest-pose rotation to the ground from ground.yaml (g_R_c, camera-to-ground from floor
// board images). The head's sway is measured (neck joints / IMU), so the observer's camera at
// frame k is  c_M_w_obs(t) = D(t) · c_M_w_cal  with D(t) = c_M_w_true(t) · c_M_w_true(0)⁻¹ the true
// sway (plus the ground_rotation_noise); the calibration error stays in every frame.
//
// Loop timing (one 1 ms physics tick): frame k is captured at t_k (middle of the exposure),
// processed once the exposure is over, and the controller's tilt ramp starts at
// t_k + latency; the arm's trajectory interpolator sends the ramp to the wrist as 1 kHz
// position commands, and the wrist adds its delay. The controller's model delay is
// latency + wrist delay.
//
// Events: set-point changes (table frame, m) and pushes (an impulse on the ball: Δv, m/s).
//
// Metrics (position errors are 2-D Euclidean, in the table frame, truth at the capture time):
//   observer_rmse_mm        RMS |p̂ − p| over frames with an estimate after `warmup`
//   measurement_rmse_mm     RMS |y − p| over frames with a ball measurement after `warmup`
//   tuning comparison       the same RMSE for [M]'s two tunings (σw = 1, σv = 0.005 and
//                           σw = σv = 1) and the stationary-gain filter, all fed the same
//                           measurements (the loop itself runs on the configured filter)
//   per set-point step (|Δ| >= min_step): overshoot_pct = 100 · max over the window of the
//     position's excursion past the new set point along the step direction / |Δ|;
//     settling_time_s = time after the change until the stepped coordinate (p − ref)·Δ/|Δ| stays
//     within 2 % of |Δ| (the classic step-response definition; settling_time_2d_s uses |p − ref|
//     and so also counts cross-axis errors);
//     steady_state_error_mm = mean |p − ref| over the last `steady_window` s before the next
//     event. The summary reports the worst step.
//   push_recovery_s         time after a push until |p − ref| stays within `push_band`
//                           (worst push).
//   frame_time_ratio_to_reference  mean per-frame cost of the observer (detection + filter)
//     divided by that of the plain OpenCV reference of [M]'s steps (vision::referenceTableScene,
//     full frame, fresh buffers) + the same filter step, both timed on every frame of the run
//     (wall clock, steady_clock). frame_cpu_ratio_to_reference: the same with the CPU time of the
//     calling thread (CLOCK_THREAD_CPUTIME_ID). On a loaded machine the wall ratio is dominated
//     by waiting for a core (the observer runs right after the long render and is preempted
//     more often than the reference after it); the CPU ratio is the cost itself. Both pipelines
//     run on the calling thread for a 320x240 image (OpenCV does not split such small images).

#include <Eigen/Core>
#include <cstdint>
#include <functional>
#include <optional>
#include <nlohmann/json.hpp>
#include <opencv2/core.hpp>
#include <string>
#include <vector>

#include "viewline/control/table_balancer.h"
#include "viewline/core/camera.h"
#include "viewline/io/config.h"
#include "viewline/robots/table_tilt.h"
#include "viewline/scenarios/table_ball_observer.h"
#include "viewline/vision/apriltag_detector.h"

namespace viewline::io {
class LogDirectory;
}
namespace viewline::sim {
class TableWorld;
}

namespace viewline::scenarios {

struct TableBallSetpoint {
  double t = 0.0;
  Eigen::Vector2d xy = Eigen::Vector2d::Zero();  ///< table frame, m
};
struct TableBallPush {
  double t = 0.0;
  Eigen::Vector2d dv = Eigen::Vector2d::Zero();  ///< added to the ball velocity, m/s
};

struct TableBallConfig {
  // World
  double table_side = 0.3;                                     ///< L, m
  double ball_radius = 0.025;                                  ///< r, m
  Eigen::Vector3d table_center = Eigen::Vector3d(0.0, 0.0, 0.9);  ///< untilted table centre, world, m
  Eigen::Vector2d initial_ball = Eigen::Vector2d(0.06, 0.04);  ///< m
  Eigen::Vector2d initial_velocity = Eigen::Vector2d::Zero();  ///< m/s
  double border_height = 0.02;                                 ///< m, raised black borders (width 0.02 m)
  bool table_tags = false;                                     ///< tags around the borders (AprilTag pose)
  double tag_size = 0.05;                                      ///< m
  robots::TableTiltLimits wrist;                               ///< angle/rate limits, delay
  // Camera
  unsigned width = 320, height = 240;
  double hfov = 1.5707963267948966;                            ///< rad (90°)
  double rate_hz = 50.0;
  Eigen::Vector3d camera_position = Eigen::Vector3d(0.0, -0.3, 1.3);
  Eigen::Vector3d camera_look_at = Eigen::Vector3d(0.0, 0.0, 0.9);
  double sway = 0.0087;                                        ///< head rotation amplitude, rad
  double sway_hz = 0.3;
  double sway_translation = 0.003;                             ///< m
  double ground_rotation_noise = 0.0;                          ///< rad (std per axis, per frame)
  double sensor_noise = 2.0;                                   ///< grey levels
  double exposure = 0.004;                                     ///< s (motion blur)
  int blur_samples = 3;
  double drop_probability = 0.0;
  int supersampling = 3;
  /// Calibrated rig (key `rig`): when set, it replaces width, height, hfov, camera_position and
  /// camera_look_at (see the header comment).
  struct RigCameras {
    std::string folder;
    core::Camera truth;       ///< renders; c_M_w = rest pose (before the sway)
    core::Camera calibrated;  ///< the observer's; c_M_w = calibrated rest pose, rotation from ground.yaml
  };
  std::optional<RigCameras> rig;
  // Observer, controller
  TableBallObserverConfig observer;
  bool border_aware_pnp = true;                                ///< correct the PnP for the border occlusion
  double latency = 0.01;                                       ///< s, capture -> command
  control::TableBalancerConfig controller;                     ///< period/delay/limits filled in by run
  // Events and metrics
  std::vector<TableBallSetpoint> setpoints;                    ///< sorted by t; first at t = 0
  std::vector<TableBallPush> pushes;
  double duration = 30.0;                                      ///< s
  double warmup = 1.0;                                         ///< s, excluded from the RMSEs
  double min_step = 0.05;                                      ///< m, set-point changes scored as steps
  double settle_fraction = 0.02;
  double steady_window = 1.0;                                  ///< s
  double push_band = 0.005;                                    ///< m
  bool compare_tunings = true;                                 ///< run the side filters
  bool time_reference = true;                                  ///< time the plain OpenCV reference

  /// Throws core::InvalidInput naming the field.
  void validate() const;
};

/// Reads the YAML scenario (documented in config/table_ball.yaml); unknown keys are errors.
/// `rig:` (a folder relative to the config file) loads the rig's truth.yaml, rig.yaml and
/// ground.yaml; with it the inline camera geometry keys are errors (one source of truth).
TableBallConfig tableBallConfigFromYaml(const io::ConfigNode& root);

/// Loads the head camera of a table rig folder: truth.yaml (renders), rig.yaml (calibrated
/// intrinsics and rest pose) and ground.yaml (calibrated camera-to-ground rotation g_R_c, which
/// must agree with rig.yaml's within 0.01°). Errors name the file.
TableBallConfig::RigCameras loadTableRig(const std::string& folder);

/// The AprilTag layout of the simulated table (tags ids, sizes, and their poses in the table frame
/// in vpDetectorAprilTag's tag frame: sim::TableWorld::table_M_vispTag).
std::vector<vision::TagOnTable> tableTagLayout(const sim::TableWorld& world);

struct StepMetrics {
  double t = 0.0;
  double size_m = 0.0;
  double overshoot_pct = 0.0;
  double settling_time_s = 0.0;   ///< step axis (the stepped coordinate); +inf when it never settles
  double settling_time_2d_s = 0.0;  ///< same with the 2-D distance (includes the cross axis)
  double steady_state_error_mm = 0.0;
};
struct PushMetrics {
  double t = 0.0;
  double speed = 0.0;             ///< |Δv|, m/s
  double recovery_s = 0.0;        ///< +inf when it never recovers in its window
  double peak_excursion_mm = 0.0;
};

struct TableBallResult {
  std::uint64_t seed = 0;
  double duration = 0.0;
  int frames = 0, frames_dropped = 0, table_detections = 0, ball_detections = 0;
  int tracked_frames = 0;  ///< frames measured by the fast path (edge tracking), not [M]'s full pipeline
  double observer_rmse_mm = 0.0;
  double measurement_rmse_mm = 0.0;
  double observer_rmse_mm_M_sw1_sv0005 = 0.0;   ///< [M]'s best tuning (side filter)
  double observer_rmse_mm_M_sw1_sv1 = 0.0;      ///< [M]'s lagging tuning (side filter)
  double observer_rmse_mm_stationary = 0.0;     ///< stationary (DARE) gain, configured σ
  double prediction_rmse_mm_10 = 0.0;           ///< 10-step (0.2 s) prediction vs truth
  double tilt_rmse_deg = 0.0;                   ///< measured table tilt vs truth
  double nis_mean = 0.0;
  std::vector<StepMetrics> steps;
  std::vector<PushMetrics> pushes;
  double overshoot_pct = 0.0, settling_time_s = 0.0, steady_state_error_mm = 0.0, push_recovery_s = 0.0;
  double observer_frame_ms = 0.0, reference_frame_ms = 0.0, frame_time_ratio_to_reference = 0.0;
  double observer_frame_cpu_ms = 0.0, reference_frame_cpu_ms = 0.0, frame_cpu_ratio_to_reference = 0.0;
  double max_commanded_angle_deg = 0.0, max_commanded_rate_deg_s = 0.0;
  bool limits_respected = true;
  double wall_seconds = 0.0;
};

nlohmann::json toJson(const TableBallResult& r);

/// Everything a viewer needs about one processed frame.
struct TableBallFrameView {
  const cv::Mat* image = nullptr;        ///< the camera image (null for a dropped frame)
  const core::Camera* camera = nullptr;  ///< camera at capture
  const ObserverFrame* observer = nullptr;
  Eigen::Vector2d truth = Eigen::Vector2d::Zero();
  Eigen::Vector2d setpoint = Eigen::Vector2d::Zero();
  Eigen::Vector2d tilt = Eigen::Vector2d::Zero();  ///< true table tilt
};

struct TableBallHooks {
  std::function<void(const TableBallFrameView&)> on_frame;  ///< e.g. the display
  std::function<void(double t, double duration)> on_progress;
  io::LogDirectory* log = nullptr;                          ///< CSV streams when non-null
};

/// Runs the closed loop for `config.duration` seconds with all randomness from `seed`.
TableBallResult runTableBall(const TableBallConfig& config, std::uint64_t seed, const TableBallHooks& hooks = {});

}  // namespace viewline::scenarios
