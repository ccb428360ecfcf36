#pragma once
// One camera image's ball detection as the catching loop (loop.cpp) and its footage session
// (footage.cpp) hand it to the tracker: the detector searches around the tracker's predicted
// pixel, the injected detection faults are applied (runtime/faults.h), the pixel is screened
// (runtime::usablePixel) and given the std the tracker is told. One rule for both, so a footage
// session fuses what a simulated throw would.

#include <Eigen/Core>
#include <optional>

#include "viewline/core/time.h"
#include "viewline/runtime/faults.h"
#include "viewline/runtime/frame_source.h"
#include "viewline/scenarios/ball_catching/config.h"
#include "viewline/vision/ball_detector.h"

namespace viewline::scenarios {

/// A screened ball detection and the stds that go with it.
struct CatchDetection {
  Eigen::Vector2d pixel;     ///< px, the detected centre after the injected faults (no added noise yet)
  double sigma_detector_px;  ///< px per axis: detector.sigma_px when set, else the blob's own std floored by sigma_px_floor
  double sigma_px;           ///< px per axis, told to the tracker: the detector's std and pixel_noise_px in quadrature
};

/// Detects the ball in `frame` (around `predicted`, px, when given) with `detector`, applies the
/// faults `faults` injects at `fault_time` (s; the loop's capture time) and screens the pixel.
/// nullopt when the detector threw or found nothing, or the pixel is not usable (counted in
/// `faults` as detector_errors or detections_rejected).
std::optional<CatchDetection> detectCatchBall(const BallCatchingConfig& cfg, runtime::FaultPlan& faults,
                                              vision::BallDetector& detector, const runtime::Frame& frame,
                                              core::Timestamp fault_time,
                                              const std::optional<Eigen::Vector2d>& predicted);

}  // namespace viewline::scenarios
