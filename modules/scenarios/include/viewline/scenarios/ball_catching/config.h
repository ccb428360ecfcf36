#pragma once
// Ball catching ([L] §VI.C): the scenario's configuration, read once from YAML
// (config/ball_catching.yaml documents every key; unknown keys are errors) and validated once.
//
// One owner per value: the robot's limits and command latency belong to the robot config
// (robots::SimulatedCartesianConfig) and the planner asks the robot for them when it is built
// (planning::CatchPlanner(cfg, robot)); the drag of the known ball belongs to the throw's body;
// the box rotation is derived from the box normal when the file is read.

#include <Eigen/Geometry>
#include <cstdint>
#include <optional>
#include <string>
#include <vector>

#include "viewline/core/camera.h"
#include "viewline/io/config.h"
#include "viewline/planning/catch_planner.h"
#include "viewline/robots/cartesian_robot.h"
#include "viewline/runtime/faults.h"
#include "viewline/runtime/source_config.h"
#include "viewline/scenarios/ball_catching/flight_fit.h"
#include "viewline/sim/physics.h"
#include "viewline/sim/renderer.h"
#include "viewline/sim/worlds.h"
#include "viewline/tracking/tracker.h"
#include "viewline/vision/ball_detector.h"

namespace viewline::scenarios {

/// One simulated camera of the catching rig: intrinsics, world pose, clock and image defects.
struct CatchCameraConfig {
  std::string name = "camera";  ///< label in logs, summaries and the rig folder
  unsigned width = 640,   ///< image width, px
           height = 480;  ///< image height, px
  double hfov_rad = 1.0471975511965976;  ///< 60°
  double cx = -1.0,  ///< principal point u, px (< 0: image centre)
         cy = -1.0;  ///< principal point v, px (< 0: image centre)
  double kud = 0.0;                      ///< ViSP forward radial distortion
  /// Optical centre in the world frame, m (the pose c_M_w is built from it and look_at).
  Eigen::Vector3d position = Eigen::Vector3d(1.0, -3.2, 1.9);
  /// World point on the optical axis, m.
  Eigen::Vector3d look_at = Eigen::Vector3d(2.2, 0.0, 1.3);
  double rate_hz = 50.0;  ///< frames per second (nominal, before drift)
  double drift = 0.0;                 ///< relative clock period error
  double exposure_s = 0.002;          ///< motion blur exposure (0: none)
  int blur_samples = 3;                ///< sub-frames averaged over the exposure for motion blur
  double noise_sigma = 2.0;           ///< grey levels
  double drop_probability = 0.0;      ///< probability that a frame is lost (seeded)
  double trigger_jitter_s = 0.0002;   ///< s, std of the true capture instant around the tick
  double stamp_jitter_s = 0.0;        ///< s, std of the reported stamp's error (0: exact stamps)
  /// With a `rig:` (scenarios::loadSimulatedRig): the TRUE camera the simulator renders with
  /// (truth.yaml) and the CALIBRATED one the detector and tracker use (rig.yaml); the geometry
  /// fields above are then unused (width/height are copied from the truth). Without a rig both are
  /// built from the fields above: a perfectly calibrated rig.
  std::optional<core::Camera> true_camera,  ///< rig truth: what the simulator renders with
                              calibrated_camera;  ///< rig calibration: what the estimators use
  /// Where this camera's frames come from: sim (rendered, the default) or footage (images, video,
  /// v4l2; footage.h). Every active camera renders, or every one has footage.
  runtime::SourceConfig source;
  /// Set by registerCamerasToRobot when it replaced calibrated_camera's pose by the registered one
  /// (not a config key): the camera's persistent pixel error is then the registered rig's.
  bool registered = false;
  core::Camera renderCamera() const;     ///< true_camera, or the one built from the fields
  core::Camera estimatorCamera() const;  ///< calibrated_camera, or the one built from the fields
};

/// How throws are drawn (uniformly, per seeded throw): release box, aim disc, speed, ball body.
struct ThrowDistribution {
  Eigen::Vector3d release_min = Eigen::Vector3d(-1.0, -0.3, 1.0);  ///< m (x: 3-5 m from the box at x = 4)
  Eigen::Vector3d release_max = Eigen::Vector3d(1.0, 0.3, 1.6);   ///< m, upper corner of the release box
  double aim_radius = 0.35;         ///< m, aim points uniform in this disc around home (box plane)
  double speed_min = 6.0;           ///< m/s, mean horizontal speed
  double speed_max = 9.0;           ///< m/s, upper bound of the mean horizontal speed
  sim::DragBody body = sim::DragBody::ball5cm();  ///< 5 cm ball, 57 g, Cd 0.5, ρ 1.2 (k ≈ 0.0103 /m)
};

/// Camera-to-robot registration, once per session before the throws (config `registration:`).
/// The catcher needs the ball in the ROBOT's frame to a few mm (5 mm clearance), but a rig
/// calibrated from board views carries ~1 px / 5-10 mm of pose error per camera (docs/results.md).
/// So, as a real catcher would (eye-to-hand): a green marker sphere sits on the box top at a known
/// offset from the hole; the robot holds the box still at a grid of set points around home, every
/// configured camera renders it, the detector finds the marker (searching only around where the
/// calibrated camera expects it), and each camera's pose c_M_w is re-estimated by PnP (Levenberg-
/// Marquardt from the calibrated pose, calibrated intrinsics) from the known marker positions
/// (robot kinematics: set point + offset) and their detections. Nothing of the truth is used but
/// the robot's own set points. Detections beyond gate_px of the expected pixel are dropped, then
/// residuals above 3x the median after a first solve; cameras with fewer than min_points detections,
/// or whose registration fits badly (max_rms_px) or moves them implausibly far (max_shift_m,
/// max_rotation_deg), keep their calibrated pose.
struct CatchRegistration {
  bool enabled = false;  ///< off unless the config's registration.enabled says so
  Eigen::Vector3d marker_offset = Eigen::Vector3d(0.15, 0.0, 0.175);  ///< m, from the hole centre (world axes)
  double marker_radius = 0.025;  ///< m, radius of the marker sphere
  Eigen::Vector3d marker_albedo_bgr = Eigen::Vector3d(0.15, 0.75, 0.15);  ///< green
  vision::ColorRange marker_hsv{35, 85, 80, 255, 30, 255};  ///< HSV range the marker detector keeps
  std::vector<double> offsets_x{-0.08, 0.08},        ///< m, set-point grid along world x, from home
                      offsets_y{-0.4, 0.0, 0.4},     ///< m, set-point grid along world y, from home
                      offsets_z{-0.3, 0.0, 0.3};  ///< m, from home
  int min_points = 6;  ///< fewer marker detections: the camera keeps its calibrated pose
  double gate_px = 10.0;          ///< detections farther than this from the expected pixel are dropped
  double max_rms_px = 0.5;        ///< refuse a camera's registration above this reprojection RMS,
  double max_shift_m = 0.05;      ///< or moving its centre more than this,
  double max_rotation_rad = 0.0087;  ///< or rotating it more than this (0.5°)
  /// m, std per axis of the robot's positioning error while it holds the marker (the marker is
  /// rendered there; the registration believes the commanded position). 0: exact. Drawn from its
  /// own stream (deriveSeed(registration seed, 0x905)), so the rest of the session is unchanged.
  double robot_position_error_m = 0.0;
};

/// The whole ball-catching scenario: cameras, throws, box, robot, tracker, planner and rendering.
struct BallCatchingConfig {
  std::string name = "ball_catching";  ///< scenario name written into logs and summaries
  std::string rig;                   ///< rig folder as resolved ("" : inline cameras)
  std::vector<CatchCameraConfig> cameras;  ///< every configured camera (registration uses all)
  std::size_t camera_count = 0;      ///< use the first N cameras (0: all)
  /// Diagnosis: the estimators use the rig's true cameras (what the simulator renders with)
  /// instead of its calibration, so the detection error is the detector's own (needs a rig).
  bool true_cameras = false;
  double rate_override_hz = 0.0;     ///< > 0: every camera at this rate (throws; registration keeps rate_hz)
  ThrowDistribution throws;          ///< where, how fast and what is thrown
  Eigen::Vector3d ball_albedo_bgr = Eigen::Vector3d(0.08, 0.45, 0.95);  ///< orange (dart: flight colour)
  /// "ball" (a sphere of the body's radius) or "dart" (sim::makeDart oriented along its velocity;
  /// the detector then finds the coloured flights, 5 cm behind the centre of mass, and the
  /// tracked point is theirs: its crossing point lies on the same flight line).
  std::string object = "ball";
  double hole_radius = 0.03;         ///< m (6 cm hole)
  Eigen::Vector3d box_normal = -Eigen::Vector3d::UnitX();  ///< box-front normal (unit), towards the thrower
  double box_size = 0.3;             ///< m, cube side (rendered)
  bool render_box = true;            ///< draw the box in the images (it can occlude the ball)
  robots::SimulatedCartesianConfig robot;   ///< kind, limits, latency, home, workspace, arm geometry (w_R_box from box_normal)
  double control_period = 0.004;     ///< s between set points (250 Hz)
  double processing_latency = 0.0025; ///< s from capture to the tracker/planner update
  double post_crossing_s = 0.05;     ///< s simulated after the true crossing
  double prediction_lead_s = 0.2;    ///< the early-prediction metric uses the last prediction this long before the crossing
  vision::BallDetectorConfig detector;  ///< colour segmentation of the ball in every frame
  double sigma_px_floor = 0.3;       ///< px, floor of the measurement std given to the tracker
  /// px per axis: the detector's measured std (the summary's detection_error_px_rms on seeds the
  /// tracker is not scored on), told to the tracker instead of the blob's own covariance; 0: the
  /// blob covariance floored by sigma_px_floor.
  double sigma_px = 0.0;
  /// px per axis: white Gaussian noise added to every detected pixel (pixel-noise table; 0: none).
  /// The tracker is told: its σ is the detector's σ and this one added in quadrature. Drawn from
  /// its own stream (deriveSeed(throw seed, 0xD37)), so the rest of a throw is unchanged.
  double pixel_noise_px = 0.0;
  tracking::TrackerConfig tracker;   ///< multi-camera ball tracker (world frame, drag-free model + white acceleration)
  /// px: the pixel-bias std (tracker.pixel_bias) of a camera whose pose is its calibration only
  /// (registration off, refused, or the marker out of its view), whose calibration error is not
  /// removed; 0: tracker.pixel_bias.sigma_px for every camera. trackerConfig() applies it.
  double unregistered_bias_sigma_px = 0.0;
  /// Drag-model batch fit of the track's fused images (flight_fit.h): the state the planner predicts from.
  FlightFitConfig flight_fit;
  /// The planner's own settings (model, thresholds). Home, limits and latency are the robot's and
  /// the plane normal is the box's: plannerConfig() and CatchPlanner(cfg, robot) ask their owners.
  planning::CatchPlannerConfig planner;
  CatchRegistration registration;    ///< camera-to-robot registration before the throws
  sim::RenderSettings render;        ///< renderer quality (supersampling, shading)
  sim::RoomParams room;              ///< the simulated room around the scene (walls, floor, light)
  int threads = 2;                   ///< throws run in parallel (independent seeds: same results)
  runtime::SourceConfig source;      ///< `source:` sim (render) or recording (a folder of --record, recording.h)
  /// Injected faults (runtime/faults.h; windows in each throw's time, release at 0; empty: none).
  runtime::FaultConfig faults;

  /// The cameras a throw uses: the first camera_count (all when 0).
  std::size_t activeCameras() const { return camera_count > 0 ? camera_count : cameras.size(); }
  /// True when the active cameras take their frames from footage (cameras[].source, footage.h):
  /// one session over the footage instead of simulated throws.
  bool onFootage() const;
  /// Frame rate of camera i in a throw (rate_override_hz when set).
  double throwRate(std::size_t i) const { return rate_override_hz > 0.0 ? rate_override_hz : cameras[i].rate_hz; }
  /// The planner settings with what the planner takes from the world: the crossing plane (home,
  /// box normal), gravity and the known ball's drag. Limits and latency come from the robot.
  planning::CatchPlannerConfig plannerConfig() const;
  /// The tracker settings for the active cameras: `tracker`, with each camera's pixel-bias std
  /// (tracker.pixel_bias.camera_sigma_px) from whether it is registered (CatchCameraConfig::registered).
  tracking::TrackerConfig trackerConfig() const;
  /// Throws core::InvalidInput naming the key. loadBallCatchingConfig() calls it; code that edits
  /// a loaded config (benches, tests) calls it again through runBallCatching().
  void validate() const;
};

/// Reads the YAML scenario (documented in config/ball_catching.yaml); unknown keys are errors.
/// Validated before it returns.
BallCatchingConfig loadBallCatchingConfig(const io::ConfigNode& node);

/// Orientation of the box whose front face has unit normal n (z = n, x horizontal).
Eigen::Matrix3d boxRotation(const Eigen::Vector3d& n);

}  // namespace viewline::scenarios
