#pragma once
// Ball catching: camera-to-robot registration (config `registration:`, CatchRegistration in
// config.h says why and how), once per session before the throws.

#include <cstdint>
#include <vector>

#include "viewline/scenarios/ball_catching/config.h"
#include "viewline/sim/scene.h"

namespace viewline::scenarios {

/// Outcome of registerCamerasToRobot(): how many cameras moved and how much the fit improved.
struct RegistrationResult {
  int poses = 0,               ///< robot set points the marker was shown at
      cameras_registered = 0,  ///< cameras whose pose c_M_w was replaced
      cameras_refused = 0;     ///< cameras that kept their calibrated pose (too few points, bad fit)
  std::vector<int> points_per_camera;               ///< marker detections per configured camera
  std::vector<bool> registered;                    ///< per configured camera: its pose was replaced
  double reprojection_px_before = 0.0;              ///< RMS over the registered cameras, calibrated pose
  double reprojection_px_after = 0.0;               ///< same, registered pose
  std::vector<double> centre_shift_mm,  ///< per registered camera: optical-centre shift, mm
                      rotation_deg;  ///< per registered camera: registered vs calibrated
};

/// Renders the marker at the grid poses through every configured camera (true cameras, sensor
/// noise), detects it and replaces each camera's calibrated_camera by the registered one. Throws
/// core::NumericalError when no camera has min_points detections.
RegistrationResult registerCamerasToRobot(BallCatchingConfig& cfg, const sim::Scene& room, std::uint64_t seed);

}  // namespace viewline::scenarios
