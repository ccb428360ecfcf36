#pragma once
// Ball catching: a drag-model batch fit of the tracked flight, the state the planner predicts from.
//
// Why: the viewline tracker's motion model is drag-free (tracking/ballistic.h); its white
// acceleration noise (tracker.accel_psd, 0.1 m²/s³) absorbs the ball's ~0.4-0.9 m/s² of drag, and
// with it the filter forgets its older images. With exact detections that costs little, but with
// detection noise (0.5 px per axis is ~4 mm at 4 m) the crossing predicted 50-100 ms ahead is off
// by ~5 mm median: the whole clearance of a 6 cm hole and a 5 cm ball. The flight itself is
// known up to its initial state (gravity and the ball's drag p̈ = g − k|v|v, as the planner's
// crossing model), so every fused image of the track constrains those six numbers.
//
// Method: Gauss-Newton least squares over the initial state x_ref = (p, v) at the track's first
// fused image. Each image i (camera c_i, stamp t_i, pixel z_i, std σ_i) contributes the residual
//     r_i = z_i − π_ci(p(t_i)),   p(t_i) from x_ref by RK4 under the drag model,
// linearised as J_i = ∂π/∂p · Φ(t_i, t_ref)_{p rows}, Φ the state transition (variational
// equations, estimation::DragBallisticModel::jacobianFixed), ∂π/∂p by central differences of the
// calibrated camera's projection (with its distortion). Normal equations H δ = Σ J_iᵀ r_i / σ_i²,
// H = Σ J_iᵀ J_i / σ_i²; each new image warm-starts from the previous solution, so one or two
// iterations converge. The estimate handed on is the state at the newest image with covariance
// Φ H⁻¹ Φᵀ (the model is taken as exact: no process noise; the planner adds its own).
// The fit is used once it has min_images images from min_cameras cameras (before that the
// depth along a single viewline is not determined); the tracker still gates every image, and a
// new track (tracker seed or restart) starts a new fit.
//
// Prior of the throws (optional; what the catcher knows about throws before any image): a
// Gaussian on the state at the first image, x_ref ~ N(x0, diag(σ_p², σ_v²)) (the release region
// and the launch velocities), and one on where the flight crosses the box plane, c(x_ref) ~
// N(aim centre, σ_aim² I) in the plane (the aim disc). Both enter the normal equations as
// pseudo-measurements (maximum a posteriori Gauss-Newton):
//     H = Σ J_iᵀ J_i / σ_i² + P0⁻¹ + J_cᵀ J_c / σ_aim²,
//     b = Σ J_iᵀ r_i / σ_i² + P0⁻¹ (x0 − x_ref) + J_cᵀ Eᵀ (c0 − c(x_ref)) / σ_aim²,
// with E the plane's in-plane basis, J_c = Eᵀ A Φ(τ, t_ref)_{p rows}, A = I − v nᵀ / (n·v) the
// oblique projection onto the plane along the crossing velocity v (planning/crossing.h), τ the
// crossing time. With the prior the six unknowns are determined from the first image on, so the
// fit can be used at once (min_images 1, min_cameras 1): the first images give a crossing with an
// honest covariance instead of waiting for a determined track.

#include <Eigen/Core>
#include <cstddef>
#include <optional>
#include <vector>

#include "viewline/core/camera.h"
#include "viewline/estimation/models/ballistic_drag.h"
#include "viewline/estimation/state.h"

namespace viewline::scenarios {

/// Settings of the flight fit (config `flight_fit:`).
struct FlightFitConfig {
  bool enabled = true;   ///< false: the planner gets the tracker's estimate
  int min_images = 8;    ///< fused images before the fit is used
  int min_cameras = 2;   ///< distinct cameras among them
  int max_iterations = 3;  ///< Gauss-Newton iterations per new image (warm-started)
  /// Prior mean of the state at the first image: position (m, world) and velocity (m/s, world).
  Eigen::Matrix<double, 6, 1> prior_mean = Eigen::Matrix<double, 6, 1>::Zero();
  /// Prior std per state component (m, m/s); all zero: no state prior.
  Eigen::Matrix<double, 6, 1> prior_std = Eigen::Matrix<double, 6, 1>::Zero();
  /// Std per in-plane axis of where throws cross the box plane around the aim centre, m (0: no aim prior).
  double aim_prior_std = 0.0;
  /// True when any prior is configured (then fewer than six images may be used).
  bool hasPrior() const { return aim_prior_std > 0.0 || prior_std.maxCoeff() > 0.0; }
};

/// The plane the throws aim at (the box plane through the hole's home) and its centre.
struct FitAimPlane {
  Eigen::Vector3d centre = Eigen::Vector3d::Zero();  ///< aim centre (the hole's home), world, m
  Eigen::Vector3d normal = Eigen::Vector3d::UnitX();  ///< unit normal towards the thrower, world
};

/// One fused image of the track: camera, capture stamp, pixel and its std.
struct FitImage {
  std::size_t camera = 0;  ///< index into the fit's cameras
  double t = 0.0;          ///< capture stamp, s
  Eigen::Vector2d uv = Eigen::Vector2d::Zero();  ///< detected pixel, px
  double sigma_px = 1.0;   ///< std per pixel axis, px
};

/// Drag-model batch fit of one track's fused images (file comment).
class FlightFit {
public:
  /// `cameras`: the estimator's cameras (calibrated / registered), indexed by FitImage::camera;
  /// `model`: gravity and drag of the flight (its q is ignored).
  /// `aim`: the plane of the aim prior (used when cfg.aim_prior_std > 0).
  FlightFit(FlightFitConfig cfg, std::vector<core::Camera> cameras, estimation::DragBallisticModel model,
            FitAimPlane aim = {});
  /// Forget the track (a new one starts).
  void reset();
  /// Adds a fused image; `guess` (the tracker's estimate, x = (p, v)) seeds the first solve.
  /// Returns the fitted state at the newest image, once the fit is used (min_images, min_cameras).
  std::optional<estimation::StateEstimate> add(const FitImage& image, const estimation::StateEstimate& guess);
  /// Images in the fit.
  std::size_t images() const { return images_.size(); }

private:
  bool solve();
  void addPrior(const Eigen::Matrix<double, 6, 1>& x, Eigen::Matrix<double, 6, 6>& H,
                Eigen::Matrix<double, 6, 1>& b) const;
  FlightFitConfig cfg_;
  FitAimPlane aim_;
  Eigen::Matrix<double, 3, 2> E_ = Eigen::Matrix<double, 3, 2>::Zero();  ///< in-plane basis of the aim plane
  std::vector<core::Camera> cams_;
  estimation::DragBallisticModel model_;
  /// Images reserved for at first: a throw's track (2 cameras at 50 Hz for under 1 s) fits, so
  /// the steady state does not allocate; a longer track grows the vector.
  static constexpr std::size_t kReservedImages = 256;
  std::vector<FitImage> images_;  ///< sorted by stamp
  std::vector<unsigned char> camera_seen_;  ///< per camera: has an image in the fit (add's scratch)
  std::optional<Eigen::Matrix<double, 6, 1>> x_ref_;  ///< state at images_.front().t
  Eigen::Matrix<double, 6, 6> H_ = Eigen::Matrix<double, 6, 6>::Zero();
};

}  // namespace viewline::scenarios
