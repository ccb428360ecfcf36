#pragma once
// The dart experiment's configuration ([L] §VI): the rig, the throws, the detector's noise, the
// tracker and the experiments, with its one reader (config/dart_tracking.yaml) and its checks.
//
//   const scenarios::DartScenarioConfig cfg = scenarios::loadDartScenario("config/dart_tracking.yaml");
//
// Keys are strict (io::ConfigNode): an unknown key is an error naming file:line and key path; a
// bad value names its key. Every key is optional (defaults = defaultDartScenario()). The camera
// keys are `eye` / `target` (not the `position` / `look_at` of io::readPinholeFields: user files
// keep their keys) and hfov_deg is required per camera.

#include <Eigen/Core>
#include <cstddef>
#include <string>
#include <vector>

#include "viewline/io/config.h"
#include "viewline/runtime/faults.h"
#include "viewline/runtime/source_config.h"
#include "viewline/tracking/tracker.h"
#include "viewline/vision/ball_detector.h"

namespace viewline::scenarios {

/// The marker detector's defaults for a dart: the ball detector's, with area floors for a blob
/// of a few pixels across (a 2 cm marker at 2.5 m is about 4 px in radius on the default rig).
vision::BallDetectorConfig defaultDartDetector();

/// One camera of the dart rig: pose (eye/target, world frame), intrinsics and free-running clock.
struct DartCameraConfig {
  std::string name = "camera";  ///< label in logs and messages
  Eigen::Vector3d eye_w = Eigen::Vector3d::Zero();     ///< camera centre, world, m
  Eigen::Vector3d target_w = Eigen::Vector3d::UnitX(); ///< look-at point, world, m
  double hfov_rad = 1.0;       ///< horizontal field of view, rad (the file's hfov_deg)
  unsigned width = 656;        ///< image width, px
  unsigned height = 480;       ///< image height, px
  double kud = 0.0;            ///< ViSP undistortion coefficient (pixel -> metre)
  double rate_hz = 50.0;       ///< nominal frame rate of the free-running clock, Hz
  double clock_drift_std = 1e-4;  ///< relative frequency error of the free-running clock (std)
  double jitter_std_s = 0.5e-3;   ///< capture-time jitter (std), s
  /// The camera's footage (images, video or v4l2; dart/footage.h); sim (absent): generated detections.
  runtime::SourceConfig source;
};

/// The dart experiments' whole configuration: rig, throws, detection noise, tracker, experiments.
struct DartScenarioConfig {
  std::vector<DartCameraConfig> cameras;  ///< the rig, in camera-index order
  /// The one owner of gravity: the tracker's model asks trackerConfig() for it.
  Eigen::Vector3d gravity_w{0.0, 0.0, -9.81};
  // Throws.
  Eigen::Vector3d release_mean{0.0, 0.0, 1.75};   ///< mean release point, m (world)
  Eigen::Vector3d release_std{0.05, 0.05, 0.05};  ///< per-axis std of the release point, m
  Eigen::Vector3d board_center{2.37, 0.0, 1.73};  ///< bull's eye, m (world; 2.37 m from the oche)
  double aim_std = 0.1;        ///< m, spread of the aim point on the board (y and z)
  double speed_min = 12.0;     ///< m/s
  double speed_max = 16.0;     ///< m/s (speed drawn uniformly in [speed_min, speed_max])
  double truth_accel_psd = 0.0;  ///< white acceleration of the true flights, m²/s³
  // Detection.
  double pixel_noise_px = 0.5;   ///< std of the white detection noise per pixel axis, px
  double outlier_rate = 0.05;    ///< probability that a detection is a gross outlier (uniform in the image)
  /// Tracker (its prior, gate, model...); its model's gravity is gravity_w (see trackerConfig()).
  tracking::TrackerConfig tracker;
  double dt_offset_period = 0.01;  ///< grid of the Δt-offset filter, s
  // Experiments.
  double alternate_step = 0.01;    ///< s between alternating images (camera rate = 1/(2 step))
  double late_max_delay = 0.1;     ///< s
  double late_horizon = 0.15;      ///< s
  std::size_t single_camera = 0;    ///< index of the camera experiment E uses
  double single_offset_max = 70.0;  ///< m (and m/s for the velocity)
  double single_prior_std = 100.0;  ///< m
  double single_tolerance = 0.05;   ///< m
  std::size_t nees_index = 9;       ///< measurement (0-based) at which each run gives its NEES sample
  std::size_t settled_index = 4;    ///< RMSE / PCRLB pooled over measurements with index >= this
  double confidence = 0.99;  ///< two-sided probability of the NEES consistency bounds
  runtime::SourceConfig source;  ///< `source:` sim (generated detections) or recording (dart/recording.h)
  /// The dart's coloured marker detector on footage (a dart seen by a camera is a small blob:
  /// smaller area floors than the ball's); unused on generated detections.
  vision::BallDetectorConfig detector = defaultDartDetector();
  /// Footage: the detection's std per axis told to the tracker, px (0: the blob's own, floored).
  double detector_sigma_px = 0.0;
  /// Footage: floor of the blob's own std, px (a few-pixel blob's edge noise model is optimistic).
  double detector_sigma_px_floor = 0.3;
  /// Footage: injected camera and detector faults (runtime/faults.h; windows on the footage's
  /// stamps; empty: none). Refused on generated detections, which have no frames to fault.
  runtime::FaultConfig faults;

  /// True when the cameras give footage (cameras[].source), not generated detections.
  bool onFootage() const;

  /// The tracker's configuration with the scenario's gravity in its model.
  tracking::TrackerConfig trackerConfig() const;
  /// Throws core::InvalidInput naming the field.
  void validate() const;
};

/// A default rig and throw (two cameras of 656x480 at 50 Hz, 2-3 m from the thrower).
DartScenarioConfig defaultDartScenario();

/// Defaults of defaultDartScenario() overridden by the file's keys, validated. With `key_values`
/// ("key=value", the app's --set) applied to the file first (io::loadConfigWithValues).
DartScenarioConfig loadDartScenario(const std::string& path, const std::vector<std::string>& key_values = {});
/// Same from YAML text (`name` stands for the file in messages).
DartScenarioConfig dartScenarioFromString(const std::string& yaml, const std::string& name);
/// Same from a parsed tree (reads every key, then finish() and validate()).
DartScenarioConfig dartScenarioFromNode(const io::ConfigNode& root);

}  // namespace viewline::scenarios
