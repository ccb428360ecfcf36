#pragma once
// Pan-tilt tracking scenario ([T], SPEC §5): its configuration, read once from one YAML file by
// loadPanTiltScenarioConfig (strict keys, validated at load), and the cameras it implies.
//
// Calibrated, imperfect parameters. With `rig: <folder>` (a default simulated rig,
// scenarios::loadSimulatedRig; calib/rigs/pan_tilt), the simulator renders through the TRUE camera
// of truth.yaml (intrinsics with kud distortion, the camera mounted at the true e_M_c on the unit),
// while everything the controllers compute uses the CALIBRATED camera (rig.yaml: intrinsics, kdu)
// and the CALIBRATED hand-eye (e_M_c.yaml). Without `rig:`, the inline camera keys (width, height,
// fx, fy; principal point at the image centre, no distortion) and vpPtu46's nominal camera mount
// are used by both the simulator and the controllers.

#include <Eigen/Geometry>
#include <optional>
#include <string>

#include "viewline/control/pan_tilt_servo.h"
#include "viewline/core/camera.h"
#include "viewline/io/config.h"
#include "viewline/robots/flir_ptu.h"
#include "viewline/robots/simulated_pan_tilt.h"
#include "viewline/runtime/faults.h"
#include "viewline/runtime/source_config.h"
#include "viewline/sim/physics.h"
#include "viewline/vision/screen_target_detector.h"

namespace viewline::scenarios {

/// The pan-tilt scenario ([T]): screen and target path, camera, rig, noise, unit, detector,
/// controller and run settings (SI units; f: the unit's base frame, see pan_tilt/world.h).
struct PanTiltScenarioConfig {
  // World
  sim::ScreenPathParams path;            ///< shape, speed, centre, width/height, radius (duration set by the run)
  double screen_distance = 1.3;          ///< m
  double screen_center_height = -0.26;   ///< m (z_f)
  double screen_width = 2.4,   ///< m
         screen_height = 1.8;  ///< m
  double disc_radius = 0.03;             ///< m
  // Camera
  unsigned image_width = 640,   ///< px
           image_height = 480;  ///< px
  double fx = 944.0,  ///< focal length in pixels along u, px ([T])
         fy = 928.0;  ///< px ([T])
  double fps = 30.0;                     ///< camera frame rate, Hz (capture t_k = k / fps)
  double sensor_noise = 2.0;             ///< grey levels
  double exposure = 0.0;                 ///< s (motion blur)
  // Rig (all set together by `rig:`, or none): the simulator's and the controllers'
  // camera (intrinsics and image size) and camera mount on the unit. Unset: the inline camera
  // above and vpPtu46's nominal mount for both. (image_width/height, fx, fy then hold the true
  // camera's values, for reporting.)
  std::string rig_folder;                             ///< the rig folder as resolved ("" : none)
  std::optional<core::Camera> true_camera,            ///< what the simulator renders with
                              calibrated_camera;      ///< what the controllers compute with
  std::optional<Eigen::Isometry3d> true_e_M_c,        ///< true camera mount on the unit's end effector
                                   calibrated_e_M_c;  ///< hand-eye calibration of that mount
  // Measurement noise ([T])
  /// [T]'s measurement noise: white, per axis, this fraction of the path's amplitude (key
  /// measurement_noise_fraction).
  double noise_fraction = 0.10;
  // Unit
  robots::SimulatedPanTiltParams unit;   ///< limits, latency (q0 set from initial_offset)
  Eigen::Vector2d initial_offset = Eigen::Vector2d::Zero();  ///< rad from pointing at the start point
  double processing_delay = 0.01;        ///< s from capture to command
  /// `robot: {kind: flir_ptu, ...}`: drive this FLIR PTU (or its emulator) instead of the
  /// simulated unit; the run is then paced to the wall clock. Unset: the simulated unit.
  std::optional<robots::FlirPtuConfig> hardware_unit;
  // Detection
  vision::ScreenTargetDetectorConfig detector;  ///< [T]'s disc detector (crop, binarise, centroid)
  // Control (the baseline uses control.servo)
  control::PredictiveConfig control;  ///< our predictive law, its filter and the baseline's servo
  // Run
  double duration = 60.0;                ///< s
  double metrics_start = 5.0;            ///< s
  double occlusion_start = -1.0;         ///< s (< 0: none)
  double occlusion_duration = 1.0;       ///< s
  bool run_baseline = true;              ///< also run ViSP's law on the same seed for comparison
  /// Where the frames come from (`source:`; default: the renderer over the simulated world). A
  /// recording with truth is scored; other sources are not (the unit stays simulated).
  runtime::SourceConfig source;
  /// Injected faults (runtime/faults.h; windows in run time, robot faults on the unit's commands; empty: none).
  runtime::FaultConfig faults;

  void validate() const;  ///< throws core::InvalidInput naming the field
};

/// Reads every key of a pan-tilt scenario file (documented in config/pan_tilt_rectangle.yaml)
/// and calls finish() (unknown keys rejected with file:line:key).
PanTiltScenarioConfig loadPanTiltScenarioConfig(const io::ConfigNode& root);

/// The camera (intrinsics, size; identity pose) the simulator renders with, and the one the
/// controllers believe in (the calibrated one with a rig; the same inline camera without).
core::Camera panTiltTrueCamera(const PanTiltScenarioConfig& config);
/// The controllers' camera (calibrated with a rig, else the inline one; identity pose).
core::Camera panTiltModelCamera(const PanTiltScenarioConfig& config);

/// "rectangle", "circle" or "random" (the config's path.shape).
const char* pathShapeName(sim::PathShape shape);

}  // namespace viewline::scenarios
