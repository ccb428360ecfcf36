#include "viewline/scenarios/ball_catching/detection.h"

#include <algorithm>
#include <cmath>

namespace viewline::scenarios {

std::optional<CatchDetection> detectCatchBall(const BallCatchingConfig& cfg, runtime::FaultPlan& faults,
                                              vision::BallDetector& detector, const runtime::Frame& frame,
                                              core::Timestamp fault_time,
                                              const std::optional<Eigen::Vector2d>& predicted) {
  const std::size_t ci = frame.camera;
  const auto det = runtime::guardedDetect(faults, ci, fault_time, [&] {
    return detector.detect(frame.image, frame.stamp, predicted);
  });
  if (!det || !det->ok()) return std::nullopt;
  const Eigen::Vector2d px = faults.detected(ci, fault_time, det->value().pixel, frame.image.cols, frame.image.rows);
  if (!runtime::usablePixel(px, frame.image.cols, frame.image.rows)) {
    faults.note("detections_rejected");
    return std::nullopt;
  }
  // The detector's std: as measured against the truth (detector.sigma_px), else the blob's own.
  const double sigma_det = cfg.sigma_px > 0.0
                               ? cfg.sigma_px
                               : std::max(cfg.sigma_px_floor, std::sqrt(0.5 * det->value().pixel_covariance.trace()));
  // The tracker is told the added noise too.
  return CatchDetection{px, sigma_det, std::hypot(sigma_det, cfg.pixel_noise_px)};
}

}  // namespace viewline::scenarios
