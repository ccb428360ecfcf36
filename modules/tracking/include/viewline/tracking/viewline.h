#pragma once
// Viewline measurements ([L] §IV, SPEC §2).
//
// A camera is a core::Camera (ViSP intrinsics with distortion, pose c_M_w).
// A detected pixel (u, v) is first undistorted to normalised coordinates
// (x, y) = camera.pixelToNormalized(u, v) (vpPixelMeterConversion). In
// normalised coordinates the projection is Pc = [R | t] (c_M_w), and the two
// image lines through (x, y),
//
//   lx = (−1, 0, x)ᵀ,   ly = (0, −1, y)ᵀ,
//
// back-project to the planes π = Pcᵀ l ∈ R⁴ (both contain the camera centre
// and the object). With r1, r2, r3 the rows of R and t = (t1, t2, t3):
//
//   πx = (−r1 + x r3,  −t1 + x t3),   |−r1 + x r3| = √(1 + x²)
//   πy = (−r2 + y r3,  −t2 + y t3),   |−r2 + y r3| = √(1 + y²)
//
// (rows of R are orthonormal). Each plane is normalised so that
// |(π1, π2, π3)| = 1; then πᵀ (p, 1) is the signed distance of p to the plane
// and the object on the plane gives one linear row of the ballistic state
// x = (p, ṗ):
//
//   y = −π4 = c x,   c = (π1, π2, π3, 0, 0, 0).
//
// An image captured Δt after the filter's sample instant ([L] eq 26):
// p(t+Δt) = p + Δt ṗ + ½ g Δt² + (integrated noise), so
//   c = (π1, π2, π3, Δt π1, Δt π2, Δt π3),   y = −π4 − π₁₂₃ · ½ g Δt².
// The ½ g Δt² term is ours ([L] drops it; it is deterministic, so keeping it
// costs nothing), and so is adding π₁₂₃ᵀ Q_pp(Δt) π₁₂₃ to the row variance
// (the process noise over Δt; its correlation with the next step's noise is
// neglected). Exact propagation to the capture time (Δt = 0) needs neither.
//
// ---------------------------------------------------------------------------
// Row noise: derivation (SPEC §2 asks for it next to the code).
//
// Let (X, Y, Z) = R p + t be the TRUE object in the camera frame and
// x_m = X/Z + δx, y_m = Y/Z + δy the measured, undistorted normalised
// coordinates. The x-plane built from x_m evaluated at the true point is
//
//   πxᵀ (p, 1) = (−X + x_m Z) / √(1 + x_m²) = Z δx / √(1 + x_m²).
//
// This is exact (no linearisation): the plane rotates about the camera
// centre by the pixel error, and at the object's depth Z it has moved by Z δx
// in the image-plane direction, shortened by the normalisation √(1 + x²) (the
// plane is tilted by atan x with respect to the optical axis). Since
// y = −π4 and c x = π₁₂₃ · p, the row residual at the true state is
//
//   e_x = y − c x_true = −πxᵀ(p, 1) = −Z δx / √(1 + x_m²),
//   e_y = −Z δy / √(1 + y_m²).
//
// Pixel noise: (δu, δv) with covariance σ_px² I. Undistortion maps it to
// (δx, δy) = J (δu, δv), J = ∂(x, y)/∂(u, v) (= diag(1/px, 1/py) without
// distortion; with ViSP's radial model J has off-diagonal terms 2 k a b / p).
// Hence, with D = diag(1/√(1+x²), 1/√(1+y²)),
//
//   R_row = E[Z²] σ_px² D J Jᵀ D.
//
// Without distortion J Jᵀ is diagonal: the x- and y-rows of one image are
// uncorrelated (independent for Gaussian pixel noise) because e_x depends on
// δu only and e_y on δv only; the only coupling is the shared depth Z, which
// multiplies both but does not correlate zero-mean independent δx, δy:
// E[e_x e_y] = E[Z²] E[δx] E[δy] / (…) = 0. With distortion the off-diagonal
// term of J Jᵀ is kept (it is tiny but it is the exact first-order value).
// Rows from different images have independent pixel noise: R is block
// diagonal over images, which is why images can be fused one at a time.
//
// The depth is unknown; the filter only has its prediction Ẑ with variance
// σ_Z² = r3ᵀ P_pp r3. Because δ is zero-mean and independent of the state
// error, e is uncorrelated with the state error and its variance is
// E[Z²] σ² (…) = (Ẑ² + σ_Z²) σ² (…): with R computed this way the linear
// update is the best linear (LMMSE) update and P stays an honest covariance,
// even while Ẑ is still poor. Ẑ is floored at `min_depth` (a prediction
// behind the camera must not give a zero variance). Small-angle form:
// variance ≈ (σ_px Z / f)² as SPEC §2 says.
// ---------------------------------------------------------------------------

#include <Eigen/Core>
#include <vector>

#include "viewline/core/camera.h"
#include "viewline/estimation/kalman_filter.h"
#include "viewline/tracking/ballistic.h"

namespace viewline::tracking {

/// The two normalised planes of a detected pixel.
struct ViewlinePlanes {
  Eigen::Vector4d pi_x;   ///< from lx = (−1, 0, x), |(π1,π2,π3)| = 1
  Eigen::Vector4d pi_y;   ///< from ly = (0, −1, y)
  Eigen::Vector2d xy;     ///< undistorted normalised coordinates
  /// Unit direction of the viewline (the planes' intersection) in the world; sign arbitrary.
  Eigen::Vector3d direction_w() const;
};

/// Planes of a pixel (distortion removed with the camera's model). Throws on non-finite input.
ViewlinePlanes viewlinePlanes(const core::Camera& camera, const Eigen::Vector2d& uv);

/// ∂(x, y)/∂(u, v) of the camera's pixel-to-normalised map at uv (central differences
/// through pixelToNormalized, so it follows whatever distortion model ViSP applies).
Eigen::Matrix2d undistortionJacobian(const core::Camera& camera, const Eigen::Vector2d& uv);

/// The pixel whose undistortion is exactly xy (Newton on pixelToNormalized): the forward map
/// consistent with the tracker's model (ViSP's kdu forward model is only an approximate inverse).
Eigen::Vector2d exactPixelOf(const core::Camera& camera, const Eigen::Vector2d& xy);

/// Row-noise covariance (2x2) of the two planes (derivation above). depth_sq = E[Z²].
Eigen::Matrix2d viewlineRowNoise(const core::Camera& camera, const Eigen::Vector2d& uv,
                                 const ViewlinePlanes& planes, double sigma_px, double depth_sq);

/// ∂(rows' residual)/∂(pixel error) = −√E[Z²] D J (2x2, per px): the columns a pixel bias b of
/// the image adds to its two rows (y = C x − √E[Z²] D J b + e; tracker.h, pixel bias). From the
/// derivation above, e_x = −Z δx / √(1 + x²) with δ = J δuv; Z is taken as √E[Z²] so that a bias
/// of covariance σ_b² I adds E[Z²] σ_b² D J Jᵀ D to the rows' variance, as white noise would.
Eigen::Matrix2d viewlinePixelJacobian(const core::Camera& camera, const Eigen::Vector2d& uv, double depth_sq);

/// Two rows of C, y and their 2x2 noise for one image.
struct ViewlineRows {
  Eigen::Matrix<double, 2, 6> C;  ///< two rows of the measurement matrix (on x = (p, v))
  Eigen::Vector2d y;  ///< two measurement values
  Eigen::Matrix2d R;  ///< their 2 x 2 noise covariance
};

/// Rows for one image. `predicted` = filter mean at the state's time, `P` its covariance (for
/// E[Z²]); `dt_offset` = capture time − state time (0 for exact propagation, [L] eq 26 otherwise);
/// `model` supplies g and Q for the offset terms. min_depth floors the predicted depth.
ViewlineRows viewlineRows(const core::Camera& camera, const Eigen::Vector2d& uv, double sigma_px,
                          const Vector6& predicted, const Matrix6& P, double dt_offset,
                          const BallisticModel& model, double min_depth = 0.05,
                          bool depth_variance_in_noise = true);

/// Same with E[Z²] given (e.g. from a later, better estimate: the young-track refit of the tracker).
ViewlineRows viewlineRowsWithDepth(const core::Camera& camera, const Eigen::Vector2d& uv, double sigma_px,
                                   double dt_offset, const BallisticModel& model, double depth_sq);

/// Predicted E[Z²] = Ẑ² + r3ᵀ P_pp r3 of the point p + Δt v + ½gΔt² (Ẑ floored at min_depth);
/// Ẑ² alone when include_variance is false.
double expectedSquaredDepth(const core::Camera& camera, const Vector6& x, const Matrix6& P,
                            double dt_offset, const BallisticModel& model, double min_depth,
                            bool include_variance = true);

/// Stacks the rows of any number of images (zero included: a 0x6 measurement, predict only)
/// into one measurement with block-diagonal R.
estimation::LinearMeasurement stackRows(const std::vector<ViewlineRows>& images);

}  // namespace viewline::tracking
