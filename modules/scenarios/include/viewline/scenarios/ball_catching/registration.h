#pragma once
// Ball catching: camera-to-robot registration (config `registration:`, CatchRegistration in
// config.h says why and how), once per session before the throws.

#include <cstdint>
#include <vector>

#include "viewline/scenarios/ball_catching/config.h"
#include "viewline/sim/scene.h"

namespace viewline::scenarios {

/// What the camera-to-robot registration did: poses, cameras registered or refused, errors before and after.
struct RegistrationResult {
  int poses = 0,               ///< robot set points rendered
      cameras_registered = 0,  ///< cameras whose pose was replaced
      cameras_refused = 0;     ///< cameras that kept their calibrated pose
  std::vector<int> points_per_camera;               ///< marker detections per configured camera
  double reprojection_px_before = 0.0;              ///< RMS over the registered cameras, calibrated pose
  double reprojection_px_after = 0.0;               ///< same, registered pose
  std::vector<double> centre_shift_mm,  ///< per registered camera: centre moved, registered vs calibrated, mm
                      rotation_deg;     ///< per registered camera: rotation, registered vs calibrated, deg
};

/// Renders the marker at the grid poses through every configured camera (true cameras, sensor
/// noise), detects it and replaces each camera's calibrated_camera by the registered one. Throws
/// core::NumericalError when no camera has min_points detections.
RegistrationResult registerCamerasToRobot(BallCatchingConfig& cfg, const sim::Scene& room, std::uint64_t seed);

}  // namespace viewline::scenarios
