#pragma once
// Image-space EKF: the comparison baseline for the viewline tracker.
//
// Same ballistic state and exact propagation to every capture time, but the
// innovation is in pixels: h(x) = pixel of p through the camera (pose, pinhole
// and the same distortion model the tracker removes, see exactPixelOf),
// H = ∂h/∂x = J_u⁻¹ ∂(x,y)/∂p_c R (J_u = undistortion Jacobian), R = σ_px² I.
// The linearisation is about the predicted position, so a poor prior (or one
// behind the camera) gives a poor or undefined H: exactly the weakness the
// linear viewline rows avoid. An image whose predicted point is not in front
// of the camera is skipped (counted). Gating is the Mahalanobis/directional
// gate on the pixel innovation; restart after N consecutive rejections from
// the prior (no history re-feed). In-order data only.

#include <vector>

#include "viewline/tracking/tracker.h"

namespace viewline::tracking {

/// Image-space EKF baseline: the ballistic state updated with pixel measurements (linearised projection), for
/// comparison with the viewline tracker.
class ImageSpaceEkf {
public:
  /// EKF over `cameras` (intrinsics, distortion, c_M_w) with the tracker's model, prior, gate and restart settings.
  ImageSpaceEkf(std::vector<core::Camera> cameras, TrackerConfig cfg);

  /// Fuses one image (must not be older than the previous one: TooOld otherwise).
  Refusal submit(const ImageMeasurement& m);

  /// True while a track is live.
  bool initialised() const { return active_; }
  /// The estimate after the last fused image (world frame, time = its capture time).
  const estimation::StateEstimate& state() const { return est_; }
  /// Images rejected by the gate (or skipped) so far.
  std::size_t gated() const { return gated_; }
  /// Images skipped because the predicted point was behind the camera.
  std::size_t skippedBehindCamera() const { return skipped_; }
  /// Tracks restarted after rejections in a row.
  std::size_t restarts() const { return restarts_; }
  /// Fate of the last submitted image (Fused or Gated; Gated also when skipped).
  Fate lastFate() const { return last_fate_; }

private:
  std::vector<core::Camera> cameras_;
  TrackerConfig cfg_;
  estimation::StateEstimate est_;
  bool active_ = false;
  int consecutive_ = 0;
  int fused_in_track_ = 0;
  core::Timestamp last_fused_t_ = 0.0;
  std::size_t gated_ = 0, skipped_ = 0, restarts_ = 0;
  Fate last_fate_ = Fate::Fused;
};

/// ∂pixel/∂p (2x3) of a world point through a camera with distortion (exactPixelOf model),
/// and the pixel itself; nothing when the point is not in front of the camera.
bool pixelJacobian(const core::Camera& camera, const Eigen::Vector3d& p_w, Eigen::Vector2d& uv,
                   Eigen::Matrix<double, 2, 3>& H, double min_depth = 1e-3);

}  // namespace viewline::tracking
