#pragma once
// Sub-pixel outline of a shaded ball and the viewing cone of the sphere fitted to it.
//
// Why: the ball's distance comes from its apparent size (d = r / sin α, SPEC §3). In [M]'s
// scene (r = 25 mm at about 0.5 m, f = 160 px) the ball is about 8 px in radius and 1 mm of
// distance is 0.016 px of radius: the outline must be right to a few hundredths of a pixel.
// A threshold (or the mid level of a "greenness" profile) on a Lambert-shaded sphere is not:
// the limb facing away from the light is darker, so the ball's own level there is lower and a
// fixed level cuts the rim too early on the dark side (the apparent radius shrinks by a few
// hundredths to a tenth of a pixel, depending on where the light is).
//
// 1. Coverage by colour unmixing (independent of the ball's brightness).
//    The ball's colour is s·B with one chromaticity direction B (BGR, unit) and a brightness
//    s ≥ 0 that varies with shading (diffuse material, white light; ambient + Lambert). An
//    anti-aliased (or blurred) pixel on the outline mixes the ball and what lies behind it,
//    T (table red, border, ...), linearly:
//        P = c·s·B + (1 - c)·T,     c = fraction of the pixel covered by the ball.
//    With T⊥ = T - (T·B)B (T without its component along B), dotting with T⊥ removes the
//    unknown s·B term:
//        P·T⊥ = (1 - c) T·T⊥ = (1 - c)|T⊥|²   ⇒   c = 1 - (P·T⊥) / |T⊥|².
//    B is the normalised sum of the colours inside 0.6 ρ of the centre; T is the mean colour
//    on the last pixel of each ray (outside the ball). A ray whose background is too close to
//    the ball's chromaticity (|T⊥| below min_separation, e.g. the black border: T ≈ 0) gives
//    no point, nor does a ray whose profile is not one clean step: every sample must be such a
//    mix (P = a B + (1 - c) T up to 0.15 |T⊥|), with c = 1 up to clean_margin_px inside the
//    edge and c = 0 from clean_margin_px outside, and wherever it holds ball (c ≥ 0.3) the
//    ball's implied brightness a / c must reach min_ball_level of the interior's mean (black is
//    s·B with s = 0, so a black strip would otherwise pass for ball). This rejects rays that
//    cross a second boundary: the black border between the ball and the red surface or the
//    white plate, an occluder, a tag.
// 2. Edge radius by the polar area integral along rays from the centre (not a 50 % crossing).
//    Bilinear interpolation of the colour is linear, so c(s) along a ray is the bilinear
//    interpolation of the pixel coverages. For a disc the per-sector area is conserved by any
//    blur, so with c = 1 inside r0 and c = 0 beyond r1,
//        R² = r0² + 2 ∫_{r0}^{r1} c(s) s ds.
//    A 50 % crossing (or ∫ c ds) of a blurred curved edge lies inside the outline by about
//    σ²/(2R) (σ² ≈ 0.25 px² for the pixel box plus the bilinear sampling: 0.016 px, i.e. 1 mm of
//    distance at R = 8 px); the area form has no such first-order bias.
// 3. The projected sphere: the outline of a sphere seen from the camera centre is the image of
//    the cone of unit rays w with w·v = cos α around the centre ray v (half angle α). Three
//    parameters (v on the unit sphere, α) instead of a general ellipse's five. With u = v / cos α
//    the constraint is linear, w·u = 1, and its residual w·u - 1 = (w·v - cos α)/cos α ≈
//    -tan α · (∠(w, v) - α) is the angular residual times a constant, so the linear
//    least-squares solution is the angular least-squares fit (to first order):
//        u = argmin Σ (wᵢ·u - 1)²,   v = u / |u|,   cos α = 1 / |u|.
//    Points whose angular residual is beyond max(3 · 1.4826 · MAD, outlier_floor_px / f) are
//    dropped and the fit repeated once.
// 4. circleFromSphereCone() returns the circle whose [M] construction (table_geometry.h:
//    c ± ρ e with e along the line from the principal point) gives back exactly this cone:
//    the two rays at ±α from v in the plane of v and the optical axis are the ends of the
//    ellipse's major axis, so c = their midpoint (the ellipse centre) and ρ = half their distance
//    (the semi-major axis). The known- and unknown-radius geometry of table_geometry.h then
//    uses the fitted v and α unchanged.
//
// Measured on module sim's renders of [M]'s scene (bench/vision/ball_outline_diag 500 2: 500
// frames of the ball rolling over the whole table, radius error against the exact projected
// sphere; ball 7.4-10.3 px in radius):
//   - [M]'s minimum enclosing circle of the thresholded mask: -0.40 px bias, 0.54 px RMS;
//   - the earlier greenness mid-level ellipse: -0.058 px bias, 0.067 px RMS (the dark limb);
//   - unmixed outline points + cv::fitEllipse (semi-major axis): 0.033 px RMS;
//   - unmixed outline points + this cone fit: 0.010 px RMS in the 449 frames it accepts;
//     in the others (ball against the black border on more than half its outline, or σ_α too
//     large) TableDetector keeps the greenness ellipse. Ball on the table, known radius, with
//     the estimated table pose: 0.53 mm RMS (417 frames with a pose) against 3.99 mm.
// Not measured separately: the 50 % crossing instead of the area integral (its σ²/(2R) bias is
// the analytic argument above).

#include <Eigen/Core>
#include <optional>
#include <opencv2/core.hpp>
#include <vector>

#include "viewline/core/camera.h"
#include "viewline/vision/table_geometry.h"

namespace viewline::vision {

/// Parameters of the sub-pixel ball outline and sphere-cone fit (rays, reach, cleanliness and acceptance gates).
struct BallOutlineParams {
  int rays = 48;                 ///< rays from the centre, evenly spread
  double reach_px = 2.0;         ///< each ray spans ρ ± reach (clamped to [1.5, 0.45 ρ])
  double min_separation = 30.0;  ///< minimum |T⊥| (8-bit units) of a ray's background
  double clean_margin_px = 1.25; ///< the step must be clean beyond R ± this ...
  double max_coverage_error = 0.15;  ///< ... and the two-colour mix holds, within this fraction
                                     ///< (of |T⊥| for colours; c itself within it)
  double min_ball_level = 0.3;   ///< ball brightness a / c at least this fraction of the interior's
  int min_points = 16;           ///< fewer outline points -> no fit
  double outlier_floor_px = 0.15;  ///< angular outlier gate never below this (in px of the image)
  double max_gap_deg = 180.0;    ///< refineBallBySphereCone: largest gap between outline points
                                 ///< around the ball, ...
  double max_alpha_sigma_px = 0.015;  ///< ... and largest σ_α (times f) of the fit, else no circle

  void validate() const;  ///< throws core::InvalidInput naming the field
};

/// Outline points (pixels) of a ball of roughly known image circle `initial` in a BGR CV_8UC3
/// image, by colour unmixing and the polar area integral (steps 1-2 of the file comment).
/// Empty when the ball's colour cannot be measured (too few interior pixels).
std::vector<Eigen::Vector2d> ballOutlinePoints(const cv::Mat& bgr, const Circle& initial,
                                               const BallOutlineParams& params = {});

/// Viewing cone of a sphere: unit axis v (camera frame, towards the centre) and half angle α.
struct SphereCone {
  Eigen::Vector3d axis = Eigen::Vector3d::UnitZ();  ///< unit axis v towards the sphere centre, camera frame
  double alpha = 0.0;    ///< rad
  double rms_px = 0.0;   ///< RMS angular residual of the inliers, times the focal length (px)
  int inliers = 0;  ///< outline points kept by the fit
  double max_gap_rad = 0.0;  ///< largest gap between consecutive inliers around the axis
  double alpha_sigma_px = 0.0;  ///< standard deviation of α from the fit (residuals and spread), times f
};

/// Fit of the cone to outline pixels (step 3). nullopt when fewer than params.min_points
/// points remain or the fit is degenerate.
std::optional<SphereCone> fitSphereCone(const core::Camera& camera, const std::vector<Eigen::Vector2d>& outline_px,
                                        const BallOutlineParams& params = {});

/// The circle whose [M] construction (ballViewingCone) gives back `cone` exactly (step 4).
Circle circleFromSphereCone(const core::Camera& camera, const SphereCone& cone);

/// Steps 1-4 from a rough circle in two passes: the first with half the rays and the reach
/// widened by `initial_error_px` (how far the initial outline may be off, e.g. 1 px for [M]'s
/// minimum enclosing circle of a thresholded mask), only to centre the second; the second with
/// `params`, accepted when its inliers leave no gap above max_gap_deg around the ball and
/// σ_α ≤ max_alpha_sigma_px. nullopt otherwise (ball occluded, clipped, against a background
/// too close to its colour, partial arc): the caller keeps another outline.
std::optional<Circle> refineBallBySphereCone(const cv::Mat& bgr, const core::Camera& camera, const Circle& initial,
                                             const BallOutlineParams& params = {}, double initial_error_px = 0.0);

}  // namespace viewline::vision
