#pragma once
// The table-ball scenario's configuration: one struct, one YAML reader (config/table_ball.yaml
// documents every key), validated once when read. Values other parts need are asked from here
// (frame period, the controller's model delay, the observer's filter) instead of being copied.

#include <Eigen/Core>
#include <optional>
#include <string>
#include <vector>

#include "viewline/control/table_balancer.h"
#include "viewline/core/camera.h"
#include "viewline/io/config.h"
#include "viewline/robots/table_tilt.h"
#include "viewline/runtime/faults.h"
#include "viewline/runtime/source_config.h"
#include "viewline/scenarios/table_ball/observer.h"

namespace viewline::scenarios {

/// A ball set point in force from time t.
struct TableBallSetpoint {
  double t = 0.0;  ///< s, from the start of the run
  Eigen::Vector2d xy = Eigen::Vector2d::Zero();  ///< table frame, m
};
/// An impulse on the ball at time t (a disturbance the controller must reject).
struct TableBallPush {
  double t = 0.0;  ///< s, from the start of the run
  Eigen::Vector2d dv = Eigen::Vector2d::Zero();  ///< added to the ball velocity, m/s
};

/// The table-ball scenario: table and ball, head camera, rig, observer, controller, events and
/// metric settings (SI units; positions on the table in the table frame).
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
  unsigned width = 320,   ///< image width, px
           height = 240;  ///< image height, px
  double hfov = 1.5707963267948966;                            ///< rad (90°)
  std::optional<double> cx,                                    ///< principal point u, px (absent: centre)
                        cy;                                    ///< principal point, px (absent: image centre)
  double rate_hz = 50.0;                                       ///< camera frame rate, Hz
  /// Rest position of the head camera's optical centre, m (world).
  Eigen::Vector3d camera_position = Eigen::Vector3d(0.0, -0.3, 1.3);
  /// World point on the optical axis at rest, m.
  Eigen::Vector3d camera_look_at = Eigen::Vector3d(0.0, 0.0, 0.9);
  double sway = 0.0087;                                        ///< head rotation amplitude, rad
  double sway_hz = 0.3;                                        ///< Hz, base frequency of the head sway
  double sway_translation = 0.003;                             ///< m
  double ground_rotation_noise = 0.0;                          ///< rad (std per axis, per frame)
  double sensor_noise = 2.0;                                   ///< grey levels
  double exposure = 0.004;                                     ///< s (motion blur)
  int blur_samples = 3;                                        ///< sub-frames averaged over the exposure
  double drop_probability = 0.0;                               ///< probability a frame is lost (seeded)
  int supersampling = 3;                                       ///< renderer anti-aliasing on edge pixels
  /// Calibrated rig (key `rig`): when set, it replaces width, height, hfov, cx, cy,
  /// camera_position and camera_look_at (see table_ball.h).
  struct RigCameras {
    std::string folder;       ///< the rig folder as resolved
    core::Camera truth;       ///< renders; c_M_w = rest pose (before the sway)
    core::Camera calibrated;  ///< the observer's; c_M_w = calibrated rest pose, rotation from ground.yaml
  };
  std::optional<RigCameras> rig;                               ///< empty: the inline camera for both
  // Observer, controller
  TableBallObserverConfig observer;                            ///< as read; observerConfig() completes it
  bool border_aware_pnp = true;                                ///< correct the PnP for the border occlusion
  double latency = 0.01;                                       ///< s, capture -> command
  control::TableBalancerConfig controller;                     ///< as read; controllerConfig() completes it
  // Events and metrics
  std::vector<TableBallSetpoint> setpoints;                    ///< sorted by t; first at t = 0
  std::vector<TableBallPush> pushes;                           ///< impulses on the ball, sorted by t
  double duration = 30.0;                                      ///< s
  double warmup = 1.0;                                         ///< s, excluded from the RMSEs
  double min_step = 0.05;                                      ///< m, set-point changes scored as steps
  double settle_fraction = 0.02;                               ///< settling band, fraction of the step size
  double settle_min_band = 0.002;                              ///< m, the settling band is at least this wide
  double nis_spacing = 0.1;                                    ///< s between the NIS samples of the consistency band
  double nees_spacing = 0.5;                                   ///< s between the NEES samples (position, velocity)
  double steady_window = 1.0;                                  ///< s
  double push_band = 0.005;                                    ///< m
  bool compare_tunings = true;                                 ///< run the side filters
  /// Where the frames come from (`source:`): sim (the rendered head camera, the default), a
  /// recording of a simulated run (its truth is the simulated world's, which a replay
  /// reproduces), or footage (images, video, v4l2: one session without truth, footage.h).
  runtime::SourceConfig source;
  /// Injected camera and detector faults (runtime/faults.h; windows in run time; empty: none).
  runtime::FaultConfig faults;
  bool time_reference = true;                                  ///< time the plain OpenCV reference

  /// Throws core::InvalidInput naming the field. tableBallConfigFromYaml calls it; code that
  /// edits a config afterwards (tests, the tuning tool) calls it again.
  void validate() const;

  /// True when the frames are footage (source.kind images, video or v4l2: runTableBallFootage).
  bool onFootage() const { return !source.simulated() && source.kind != runtime::SourceKind::Recording; }
  /// The camera frame period, s.
  double framePeriod() const { return 1.0 / rate_hz; }
  /// The set point in force at time t (the last one with t_i <= t).
  Eigen::Vector2d setpointAt(double t) const;
  /// The rolling-ball filter as the observer runs it: the configured tuning on this table
  /// (L, r) with the camera's frame period as its nominal period.
  tracking::RollingBallTrackerConfig trackerConfig() const;
  /// The controller: the configured weights, the camera's period, and what it asks the wrist
  /// it commands: its limits, and its delay, which with the processing latency is the model delay.
  control::TableBalancerConfig controllerConfig(const robots::TableTilt& wrist) const;
};

/// Reads the YAML scenario (documented in config/table_ball.yaml); unknown keys are errors.
/// `rig:` (a folder relative to the config file) loads the rig's truth.yaml, rig.yaml and
/// ground.yaml; with it the inline camera geometry keys are errors (one source of truth).
TableBallConfig tableBallConfigFromYaml(const io::ConfigNode& root);

/// Loads the head camera of a table rig folder: truth.yaml (renders), rig.yaml (calibrated
/// intrinsics and rest pose) and ground.yaml (calibrated camera-to-ground rotation g_R_c, which
/// must agree with rig.yaml's within 0.01°). Errors name the file.
TableBallConfig::RigCameras loadTableRig(const std::string& folder);

}  // namespace viewline::scenarios
