#pragma once
// Mobile capture: the scenario's parameters and their one reader (keys documented in
// config/mobile_capture.yaml; the scenario itself in viewline/scenarios/mobile_capture.h).

#include <Eigen/Core>
#include <Eigen/Geometry>
#include <cmath>
#include <optional>
#include <string>

#include "viewline/control/mobile_capture_control.h"
#include "viewline/core/camera.h"
#include "viewline/io/config.h"
#include "viewline/planning/capture_planner.h"
#include "viewline/robots/differential_drive.h"
#include "viewline/robots/mobile_pan_tilt.h"
#include "viewline/runtime/faults.h"
#include "viewline/runtime/source_config.h"
#include "viewline/tracking/unicycle_tracker.h"
#include "viewline/vision/ball_detector.h"

namespace viewline::scenarios {

/// Gripper zones in the robot frame (x forward from the axle centre, y left), m.
struct GripperZone {
  double x_min = 0.12,       ///< m, nearest edge ahead of the axle centre
         x_max = 0.28,       ///< m, farthest edge
         half_width = 0.07;  ///< m, half the lateral extent (|y| bound)
  /// True when the point p_r (robot frame, m) lies in the zone, edges included.
  bool contains(const Eigen::Vector2d& p_r) const {
    return p_r.x() >= x_min && p_r.x() <= x_max && std::abs(p_r.y()) <= half_width;
  }
};

/// The mobile-capture scenario's parameters ([K]): start poses, timing, camera, robot, detection,
/// estimation, planning and the filter and field-of-view tests (SI units, world floor frame).
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
  double blackout_start = -1.0,    ///< s (< 0: no blackout)
         blackout_duration = 0.0;  ///< s

  // Timing.
  double vision_period = 0.1;           ///< s ([K]); also the profile step and the planner's T
  // The control period (key timing.control_period) is the base's wheel-PID period,
  // base.control_period ([K]: 10 ms): controlPeriod() asks it.

  // Camera (320x240, 50° x 40°).
  unsigned width = 320,   ///< image width, px
           height = 240;  ///< image height, px
  double hfov = 0.8726646259971648;     ///< rad (50°)
  double vfov = 0.6981317008965228;     ///< rad (40°)
  double sensor_noise = 2.0;            ///< grey levels (std)
  int supersampling = 2;                ///< renderer anti-aliasing sub-samples on edges

  /// Calibrated rig (key `rig`): replaces width, height, hfov, vfov (see mobile_capture.h).
  struct RigCameras {
    std::string folder;                 ///< the rig folder as resolved
    core::Camera truth;                 ///< renders (intrinsics; its pose is the DH head at q0)
    core::Camera calibrated;            ///< estimators (intrinsics; c_M_w = calibrated pose at q0)
    robots::PanTiltJoints q0;           ///< head joints of truth.yaml's pose
    Eigen::Isometry3d cal_M_c = Eigen::Isometry3d::Identity();  ///< c'_M_c, calibrated vs DH camera
  };
  std::optional<RigCameras> rig;  ///< empty: an ideal camera from width, height, hfov, vfov
  /// Injected camera and detector faults (runtime/faults.h; windows in run time; empty: none).
  runtime::FaultConfig faults;

  // Robot.
  robots::MobilePanTiltParams head;       ///< pan-tilt head on the base: DH geometry, joint limits
  robots::DifferentialDriveParams base;   ///< the base: wheels, speed limits, wheel-PID period
  GripperZone jaws;                                 ///< grasp succeeds when the true object is here
  GripperZone trigger{0.14, 0.26, 0.045};           ///< grasp is attempted when the estimate is here
  double grasp_cooldown = 0.5;                      ///< s after a failed grasp

  // Detection.
  vision::BallDetectorConfig detector;  ///< red HSV range etc. (set in defaults())
  double pixel_sigma = 1.0;             ///< px, white blob-centre noise: R = σ² J Jᵀ (J the ground-projection Jacobian)
  /// m, std of the blob centroid's offset from the box centre on the floor: a bias (it follows the
  /// view, not the frame), reported in the object's covariance, not in R.
  double floor_sigma = 0.01;
  /// rad, std of the calibrated camera-to-ground rotation about each world axis (a bias of every
  /// floor point, through ∂z/∂pose; reported in the object's covariance, not in R).
  double calibration_angle_sigma = 0.0;
  double calibration_height_sigma = 0.0;  ///< m, std of the calibrated camera height (a bias, as above)
  double object_height = 0.05;          ///< m: measurements on the plane z = height / 2

  // Estimation: the target track (keys filter.q_v, q_w, init_speed_sigma, init_turn_sigma,
  // gate_probability, predictor_window; it restarts after 5 rejections in a row).
  tracking::UnicycleTrackerConfig filter;  ///< unicycle EKF of the object, gate and restart rule
  double init_speed = 0.3;              ///< m/s (key filter.init_speed; the two-point start measures it)
  /// The LS accelerations are used only once the window is full, clamped to these (physically
  /// plausible) bounds; 0 switches them off (constant v, ω prediction).
  double max_accel_v = 0.1;             ///< m/s²
  double max_accel_omega = 0.5;         ///< rad/s²
  int horizon_steps = 200;              ///< M of [K] eq 30

  // Planning and control.
  /// The planner's own settings (reach, turn_rate); its T and v_max belong to vision_period and
  /// base.max_speed and are filled in by plannerParams(), so they are not read from here.
  planning::CapturePlannerParams planner;
  /// The go-to-point law's gains; its speed and turn-rate limits are the base's (goParams()).
  control::GoToPointParams go;
  control::SearchParams search;  ///< how the head and base search when the target is lost

  // Filter test ([K] §3.2).
  double filter_test_duration = 60.0;        ///< s
  double filter_test_measurement_var = 2.0;  ///< cm² per axis
  double filter_test_q_v = 0.003;            ///< m²/s³ (ξv variance 3 (cm/s)² per 0.1 s step)
  double filter_test_q_w = 1.0;              ///< rad²/s³ (ξω variance 0.1 (rad/s)² per step)
  double convergence_time = 10.0;            ///< s: RMSE is taken after this
  int filter_test_runs = 20;                 ///< seeded runs of the filter test

  // Field-of-view sweep of the ground localisation.
  int fov_sweep_poses = 50;             ///< random head/base poses
  int fov_sweep_points = 200;           ///< floor points per pose
  double fov_sweep_pixel_sigma = 0.5;   ///< px noise added to the projected pixels

  int threads = 2;                      ///< parallel runs in runMobileCaptureBatch
  runtime::SourceConfig source;         ///< `source:` sim (render) or recording (a folder of --record, recording.h)

  /// The control tick (s): the base's wheel-PID period, which every other control-rate step follows.
  double controlPeriod() const { return base.control_period; }
  /// The planner's parameters as it runs: T = vision_period, v_max = base.max_speed.
  planning::CapturePlannerParams plannerParams() const;
  /// The go-to-point law as it runs: speed and turn-rate limits from the base.
  control::GoToPointParams goParams() const;

  /// The defaults above plus [K]'s red-object detector settings.
  static MobileCaptureConfig defaults();
  /// Throws core::InvalidInput naming the field.
  void validate() const;
};

/// Reads the YAML keys documented in config/mobile_capture.yaml (unknown keys rejected).
/// `rig:` (folder relative to the config file) loads truth.yaml, rig.yaml and ground.yaml; with it
/// the camera's width, height, hfov_deg and vfov_deg keys are errors.
MobileCaptureConfig loadMobileCaptureConfig(const io::ConfigNode& root);

/// Loads the head camera of a mobile rig folder for the head `head` (see mobile_capture.h);
/// throws core::InvalidInput when truth.yaml's pose is not the DH head camera at some joints
/// (1 mm, 0.05°) or ground.yaml disagrees with rig.yaml.
MobileCaptureConfig::RigCameras loadMobileRig(const std::string& folder, const robots::MobilePanTiltParams& head);

}  // namespace viewline::scenarios
