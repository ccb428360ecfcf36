#pragma once
// Ball-catching scenario ([L] §VI.C, SPEC §2 "Ball catcher", issue 5) as library code: a plain
// config struct + a seed -> per-throw results and a summary, so that apps/ball_catching and the
// tuning tool run exactly the same loop.
//
// World (the `catching` rig's frame, calib/rigs/catching/truth.yaml): z up, origin on the floor
// below the thrower, x towards the robot. The box hangs on the robot with its front face in the
// plane through the hole centre `robot.home` with unit normal `box.normal` (towards the thrower,
// default −x). A textured room (sim::makeRoom) is the static background.
//
// One throw (independent: its own seed deriveSeed(seed, i), its own camera rig and clocks):
//  1. draw the throw (ThrowDistribution): release point uniform in a box, aim point uniform in a
//     disc of radius aim_radius around the hole's home position on the box-front plane, mean
//     horizontal speed uniform in [speed_min, speed_max]; the flight time is the horizontal
//     distance over that speed, and the launch velocity is solved (Newton on the 3 components,
//     with the true drag) so that the ball centre is at the aim point at that time. Spin-free:
//     p̈ = g − k |ṗ| ṗ, k = ρ Cd π r² / (2 m) (sim::DragFlight, RK4 at 1 ms);
//  2. free-running cameras (sim::CameraRig: own rate, random phase, drift, jitter, drops, sensor
//     noise, motion blur) render images of the ball and of the box at the robot's position;
//  3. each image: the colour-blob detector (vision::BallDetector, window around the tracker's
//     predicted pixel) -> ImageMeasurement{stamp, pixel, σ_px} -> tracking::ViewlineTracker;
//     the result is available `processing_latency` after the capture;
//  4. after every fused image: planning::CatchPlanner::update (crossing prediction with the
//     configured model and covariance, replanning from the current set point, commit/give up);
//  5. every control period the planner's set point is streamed to the robot (robots::
//     SimulatedCartesianRobot: Cartesian stage or vpViper850 arm, command latency, limits
//     counted, IK + joint limits on every set point for the arm);
//  6. caught = the ball centre crosses the (moving) box-front plane within hole_radius −
//     ball_radius of the hole centre (5 mm for a 6 cm hole and a 5 cm ball); the true crossing
//     is found on the true flight against the robot's actual hole position at that instant.
//
// Reachability (the oracle): a throw is reachable when a robot that knows the true flight from
// the first capture in which the ball is inside at least one camera's image (truth of the
// rendered frame), starting at home at rest with the same limits and command latency, could put
// the hole exactly on the true crossing point by the crossing time:
//     t_first_visible + latency + T_min(home -> crossing) <= t_cross
// (T_min from the same synchronised profile generator; no processing latency).
//
// Miss reasons (each missed throw gets exactly one):
//   not_reachable  the oracle could not have caught it;
//   lost_track     reachable, but the planner never had a target (too few / no detections, or
//                  the crossing prediction never became certain enough to move);
//   late           the hole was more than the clearance away from the planner's final target
//                  at the crossing (still moving, or the planner gave up);
//   off_target     the hole was at the planner's final target but the prediction was off.

#include <Eigen/Geometry>
#include <cstdint>
#include <functional>
#include <map>
#include <nlohmann/json.hpp>
#include <opencv2/core.hpp>
#include <optional>
#include <string>
#include <vector>

#include "viewline/core/camera.h"
#include "viewline/io/config.h"
#include "viewline/io/log.h"
#include "viewline/planning/catch_planner.h"
#include "viewline/robots/cartesian_robot.h"
#include "viewline/sim/physics.h"
#include "viewline/sim/renderer.h"
#include "viewline/sim/worlds.h"
#include "viewline/tracking/tracker.h"
#include "viewline/vision/ball_detector.h"

namespace viewline::scenarios {

struct CatchCameraConfig {
  std::string name = "camera";
  unsigned width = 640, height = 480;
  double hfov_rad = 1.0471975511965976;  ///< 60°
  double cx = -1.0, cy = -1.0;           ///< principal point, px (< 0: image centre)
  double kud = 0.0;                      ///< ViSP forward radial distortion
  Eigen::Vector3d position = Eigen::Vector3d(1.0, -3.2, 1.9);
  Eigen::Vector3d look_at = Eigen::Vector3d(2.2, 0.0, 1.3);
  double rate_hz = 50.0;
  double drift = 0.0;                 ///< relative clock period error
  double exposure_s = 0.002;          ///< motion blur exposure (0: none)
  int blur_samples = 3;
  double noise_sigma = 2.0;           ///< grey levels
  double drop_probability = 0.0;
  double trigger_jitter_s = 0.0002;
  double stamp_jitter_s = 0.0;
  /// With a `rig:` (scenarios::loadSimulatedRig): the TRUE camera the simulator renders with
  /// (truth.yaml) and the CALIBRATED one the detector and tracker use (rig.yaml); the geometry
  /// fields above are then unused (width/height are copied from the truth). Without a rig both are
  /// built from the fields above: a perfectly calibrated rig.
  std::optional<core::Camera> true_camera, calibrated_camera;
  core::Camera renderCamera() const;     ///< true_camera, or the one built from the fields
  core::Camera estimatorCamera() const;  ///< calibrated_camera, or the one built from the fields
};

struct ThrowDistribution {
  Eigen::Vector3d release_min = Eigen::Vector3d(-1.0, -0.3, 1.0);  ///< m (x: 3-5 m from the box at x = 4)
  Eigen::Vector3d release_max = Eigen::Vector3d(1.0, 0.3, 1.6);
  double aim_radius = 0.35;         ///< m, aim points uniform in this disc around home (box plane)
  double speed_min = 6.0;           ///< m/s, mean horizontal speed
  double speed_max = 9.0;
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
  double marker_radius = 0.025;
  Eigen::Vector3d marker_albedo_bgr = Eigen::Vector3d(0.15, 0.75, 0.15);  ///< green
  vision::ColorRange marker_hsv{35, 85, 80, 255, 30, 255};
  std::vector<double> offsets_x{-0.08, 0.08}, offsets_y{-0.4, 0.0, 0.4}, offsets_z{-0.3, 0.0, 0.3};  ///< m, from home
  int min_points = 6;
  double gate_px = 10.0;          ///< detections farther than this from the expected pixel are dropped
  double max_rms_px = 0.5;        ///< refuse a camera's registration above this reprojection RMS,
  double max_shift_m = 0.05;      ///< or moving its centre more than this,
  double max_rotation_rad = 0.0087;  ///< or rotating it more than this (0.5°)
};

struct RegistrationResult {
  int poses = 0, cameras_registered = 0, cameras_refused = 0;
  std::vector<int> points_per_camera;               ///< marker detections per configured camera
  double reprojection_px_before = 0.0;              ///< RMS over the registered cameras, calibrated pose
  double reprojection_px_after = 0.0;               ///< same, registered pose
  std::vector<double> centre_shift_mm, rotation_deg;  ///< per registered camera: registered vs calibrated
};

struct BallCatchingConfig {
  std::string name = "ball_catching";
  std::string rig;                   ///< rig folder as resolved ("" : inline cameras)
  std::vector<CatchCameraConfig> cameras;
  std::size_t camera_count = 0;      ///< use the first N cameras (0: all)
  double rate_override_hz = 0.0;     ///< > 0: every camera at this rate
  ThrowDistribution throws;
  Eigen::Vector3d ball_albedo_bgr = Eigen::Vector3d(0.08, 0.45, 0.95);  ///< orange (dart: flight colour)
  /// "ball" (a sphere of the body's radius) or "dart" (sim::makeDart oriented along its velocity;
  /// the detector then finds the coloured flights, 5 cm behind the centre of mass, and the
  /// tracked point is theirs: its crossing point lies on the same flight line).
  std::string object = "ball";
  double hole_radius = 0.03;         ///< m (6 cm hole)
  Eigen::Vector3d box_normal = -Eigen::Vector3d::UnitX();  ///< box-front normal, towards the thrower
  double box_size = 0.3;             ///< m, cube side (rendered)
  bool render_box = true;
  robots::SimulatedCartesianConfig robot;   ///< kind, limits, latency, home, workspace, arm geometry
  double control_period = 0.004;     ///< s between set points (250 Hz)
  double processing_latency = 0.008; ///< s from capture to the tracker/planner update
  double post_crossing_s = 0.05;     ///< s simulated after the true crossing
  double prediction_lead_s = 0.2;    ///< the early-prediction metric uses the last prediction this long before the crossing
  vision::BallDetectorConfig detector;
  double sigma_px_floor = 0.3;       ///< px, floor of the measurement std given to the tracker
  /// px per axis: white Gaussian noise added to every detected pixel (pixel-noise table; 0: none).
  /// The tracker is told: its σ is the detector's σ and this one added in quadrature. Drawn from
  /// its own stream (deriveSeed(throw seed, 0xD37)), so the rest of a throw is unchanged.
  double pixel_noise_px = 0.0;
  tracking::TrackerConfig tracker;
  planning::CatchPlannerConfig planner;  ///< model, thresholds (home/normal/limits/latency copied from robot/box)
  CatchRegistration registration;
  sim::RenderSettings render;
  sim::RoomParams room;
  int threads = 2;                   ///< throws run in parallel (independent seeds: same results)
  /// Fills the planner's home/normal/limits/latency from robot/box, derives the box rotation;
  /// throws core::InvalidInput naming the key.
  void finalize();
  void validate() const;
};

/// Reads the YAML scenario (documented in config/ball_catching.yaml); unknown keys are errors.
BallCatchingConfig loadBallCatchingConfig(const io::ConfigNode& node);

struct ThrowResult {
  int index = 0;
  std::uint64_t seed = 0;
  // Throw
  Eigen::Vector3d release = Eigen::Vector3d::Zero(), launch_velocity = Eigen::Vector3d::Zero();
  double launch_speed = 0.0, launch_elevation_deg = 0.0, distance = 0.0;
  // Truth
  double t_cross = 0.0;                                 ///< true crossing time (release at 0)
  Eigen::Vector3d cross_true = Eigen::Vector3d::Zero(); ///< true crossing point
  double t_first_visible = -1.0;                        ///< first capture with the ball in an image
  bool reachable = false;
  double oracle_time = 0.0;                             ///< T_min home -> crossing, s
  // Run
  int frames = 0, detections = 0, fused = 0, gated = 0;
  double t_first_detection = -1.0;
  double t_first_move = -1.0;                           ///< planner's first move towards a target
  bool had_target = false, committed = false, gave_up = false;
  double give_up_lead = -1.0;                           ///< true crossing − give-up decision, s
  double decision_time = -1.0;                          ///< commit − first update, s
  Eigen::Vector3d target = Eigen::Vector3d::Zero();     ///< planner's final target
  double prediction_error = -1.0;                       ///< |target − true crossing|, m
  double prediction_error_lead = -1.0;                  ///< same, last prediction >= prediction_lead_s before it
  Eigen::Vector3d hole_at_cross = Eigen::Vector3d::Zero();
  double miss_distance = 0.0;                           ///< in-plane |ball − hole| at the crossing, m
  bool caught = false;
  std::string miss_reason;                              ///< "" when caught
  std::size_t limit_violations = 0, refused_setpoints = 0;
  double wall_s = 0.0;
};

struct CatchSummary {
  std::uint64_t seed = 0;
  int throws = 0, reachable_throws = 0, caught = 0, caught_reachable = 0;
  double catch_rate_all = 0.0, catch_rate_reachable = 0.0;
  std::map<std::string, int> miss_reasons;
  double prediction_error_mm_median = 0.0, prediction_error_mm_p95 = 0.0;
  double prediction_error_lead_mm_median = 0.0, prediction_error_lead_mm_p95 = 0.0;
  int predictions_at_lead = 0;
  double decision_time_s_median = 0.0, decision_time_s_p95 = 0.0;
  int decisions = 0;
  int gave_up_unreachable = 0;   ///< not-reachable throws the planner gave up on (early decision)
  int gave_up_reachable = 0;     ///< reachable throws it gave up on (wrong decisions)
  double give_up_lead_s_median = 0.0;  ///< how long before the crossing it gave up (unreachable ones)
  double miss_distance_mm_median_reachable = 0.0;
  std::size_t limit_violations = 0, refused_setpoints = 0;
  int frames = 0, detections = 0;
  double detection_rate = 0.0;
  std::optional<RegistrationResult> registration;
  double launch_speed_min = 0.0, launch_speed_max = 0.0, launch_speed_mean = 0.0;
  double elevation_deg_min = 0.0, elevation_deg_max = 0.0;
  double flight_time_min = 0.0, flight_time_max = 0.0;
  double wall_s = 0.0, ms_per_frame = 0.0;
  std::vector<ThrowResult> results;
};

/// What the live view gets for every image.
struct CatchFrame {
  int throw_index = 0;
  std::size_t camera = 0;
  const core::Camera* camera_model = nullptr;
  double t = 0.0;
  const cv::Mat* image = nullptr;
  std::optional<Eigen::Vector2d> detection;
  std::optional<planning::Crossing> crossing;   ///< planner's current target
  Eigen::Vector3d hole = Eigen::Vector3d::Zero();
  std::optional<Eigen::Vector3d> estimate;      ///< tracker position
};

struct CatchHooks {
  io::LogDirectory* log = nullptr;                    ///< CSV streams (runs single-threaded when set)
  std::function<void(const CatchFrame&)> on_frame;    ///< live view (single-threaded)
  std::function<void(int done, int total)> progress;
};

/// The registration above: renders the marker at the grid poses through every configured camera
/// (true cameras, sensor noise), detects it and replaces each camera's calibrated_camera by the
/// registered one. Throws core::NumericalError when no camera has min_points detections.
RegistrationResult registerCamerasToRobot(BallCatchingConfig& cfg, const sim::Scene& room, std::uint64_t seed);

/// One throw with its own seed.
ThrowResult runThrow(const BallCatchingConfig& cfg, const sim::Scene& room, int index, std::uint64_t seed,
                     const CatchHooks* hooks = nullptr);

/// `throws` throws (throw i uses deriveSeed(seed, i)), in parallel over cfg.threads unless hooks
/// need one thread; the results do not depend on the thread count. With registration.enabled the
/// session first registers the cameras to the robot (seed deriveSeed(seed, 0x4E6)).
CatchSummary runBallCatching(const BallCatchingConfig& cfg, int throws, std::uint64_t seed,
                             const CatchHooks& hooks = {});

nlohmann::json summaryJson(const CatchSummary& s, const BallCatchingConfig& cfg);

/// The launch velocity that puts the ball centre at `aim` after `flight_time` with drag k
/// (Newton with a finite-difference Jacobian, from the drag-free solution).
Eigen::Vector3d solveLaunchVelocity(const Eigen::Vector3d& release, const Eigen::Vector3d& aim, double flight_time,
                                    const sim::DragBody& body);

}  // namespace viewline::scenarios
