#pragma once
// The dart experiment's world ([L] §VI), MEASUREMENT LEVEL: darts are thrown at a board, their
// true flights come from the ballistic model (with optional white acceleration noise), and the
// detected pixels are generated from the true trajectory through each calibrated camera (with
// distortion) + Gaussian pixel noise + gross outliers anywhere in the image. No images are
// rendered or detected here: this is the tracker's statistical test bench.

#include <cstdint>
#include <vector>

#include "viewline/core/camera.h"
#include "viewline/core/random.h"
#include "viewline/scenarios/dart/config.h"
#include "viewline/tracking/tracker.h"

namespace viewline::scenarios {

/// The cameras of the scenario (lookAt poses, intrinsics from the field of view, kud).
std::vector<core::Camera> makeDartCameras(const DartScenarioConfig& cfg);

/// One generated detection with its truth.
struct DartDetection {
  tracking::ImageMeasurement m;  ///< the detection as the tracker receives it (pixel, σ, capture time, camera)
  bool outlier = false;          ///< a generated gross outlier (not the dart)
  tracking::Vector6 truth;  ///< true state at the capture time
};

/// A generated flight: detections in capture-time order.
struct DartFlight {
  std::vector<DartDetection> detections;  ///< in capture-time order
  double duration = 0.0;                  ///< release to board, s
};

/// Alternating: camera 1 at odd, camera 2 at even steps of `alternate_step` ([L] §VI.A);
/// FreeRunning: every camera on its own drifting, jittered clock; SingleCamera: `single_camera` only.
enum class DartClockMode { Alternating, FreeRunning, SingleCamera };

/// Draws a throw and its detections (in-image only) for the given clock mode.
DartFlight simulateDartFlight(const DartScenarioConfig& cfg, const std::vector<core::Camera>& cameras,
                              DartClockMode mode, double outlier_rate, core::Rng& rng, std::uint64_t first_id = 1);

/// Position PCRLB trace (m²) after each detection of a flight (bound from the true states,
/// pixel measurement with σ² I, prior P0 = cfg.tracker.prior_cov, process noise of the truth).
std::vector<double> positionPcrlb(const DartScenarioConfig& cfg, const std::vector<core::Camera>& cameras,
                                  const DartFlight& flight);

}  // namespace viewline::scenarios
