#pragma once
// Geometry of [M]'s table-ball scene (SPEC §3), shared by the production
// detector and the plain reference implementation:
//   - the four table corners from the simplified convex hull of the red
//     contour (segments, pairwise intersection with the |ta|·|tb| test),
//   - the table pose by PnP (SOLVEPNP_AP3P) against (±L/2, ±L/2, 0),
//   - the ball centre on the table from its image circle (d = r / sin α).
//
// Table frame: origin at the table centre, x and y along the sides, z the
// surface normal on the camera's side (so the ball centre has z = +r).
// A plain square has a 4-fold symmetry: its pose is defined up to quarter
// turns about z. The detector resolves it with a prior pose (the previous
// frame, or one given by the caller); yawQuarterTurnsTo() aligns any estimate
// with a reference for evaluation.

#include <Eigen/Geometry>
#include <array>
#include <opencv2/core.hpp>
#include <optional>
#include <vector>

#include "viewline/core/camera.h"
#include "viewline/vision/detection.h"

namespace viewline::vision {

/// A circle in the image (px).
struct Circle {
  Eigen::Vector2d center = Eigen::Vector2d::Zero();  ///< px
  double radius = 0.0;                               ///< px
};

/// Parameters of the corner search ([M]'s values by default).
struct CornerSearchParams {
  double approx_epsilon_fraction = 0.01;  ///< approxPolyDP ε as a fraction of the image width
  double ball_exclusion_factor = 1.25;    ///< drop hull points within factor * ball radius + 2 px
  double max_ta_tb = 1.5;                 ///< keep intersections with |ta|·|tb| below this
};

/// Four table corners found in the image, with the simplified polygon and the sides they come from.
struct TableCorners {
  std::array<Eigen::Vector2d, 4> corners;  ///< unordered as found (see orderTableCorners)
  std::vector<cv::Point> polygon;          ///< simplified hull after dropping points near the ball
  std::array<std::array<Eigen::Vector2d, 2>, 4> sides;  ///< the four longest segments (end points)
};

/// [M]'s corner steps on the largest red contour: convex hull; approxPolyDP (ε = fraction of the
/// image width); drop hull points near the ball; the four longest segments between consecutive
/// points; all pairwise intersections, written with centred segment parameters
///   p = m_a + ta h_a = m_b + tb h_b   (m = segment mid point, h = half the segment vector,
///   so t = ±1 at the segment ends),
/// kept when |ta|·|tb| < max_ta_tb. Adjacent sides meet near their ends (|t| ≈ 1); opposite
/// sides meet far away or never. Fewer than four kept -> TooFewCorners, more -> Ambiguous.
Result<TableCorners> findTableCorners(const std::vector<cv::Point>& contour,
                                      const std::optional<Circle>& ball, int image_width,
                                      const CornerSearchParams& params);

/// Orders four corners to match the object corners
///   P0 = (-L/2, -L/2, 0), P1 = (L/2, -L/2, 0), P2 = (L/2, L/2, 0), P3 = (-L/2, L/2, 0):
/// a planar polygon seen from its front keeps its orientation under perspective, and P0..P3
/// seen from +z runs with decreasing atan2(v - v̄, u - ū) in the image (v down). The start is
/// the corner with the smallest u + v (image top-left); a prior pose overrides it later.
std::array<Eigen::Vector2d, 4> orderTableCorners(const std::array<Eigen::Vector2d, 4>& corners);

/// Table pose c_M_t from four ordered corners: corners undistorted with the camera model
/// (core::Camera::pixelToNormalized, so ViSP's distortion is handled) and solved with
/// cv::solvePnP(SOLVEPNP_AP3P) against (±L/2, ±L/2, 0). With `refine`, followed by a
/// Gauss-Newton minimisation of the pixel reprojection error of the four corners (the cost of
/// cv::solvePnPRefineLM, with analytic Jacobians: about 40 µs less per frame than OpenCV's,
/// whose every iteration calls projectPoints with Jacobian matrices). With a prior, the quarter
/// turn about z closest to it is chosen.
/// Fails (PoseFailed) when the solution puts the table behind the camera or seen from below.
struct TablePose {
  Eigen::Isometry3d c_M_t = Eigen::Isometry3d::Identity();  ///< table frame in the camera frame (p_c = c_M_t * p_t)
  std::array<Eigen::Vector2d, 4> corners;  ///< ordered like P0..P3 after the prior shift
  double reprojection_rms_px = 0.0;  ///< RMS reprojection error of the four corners, px
};
/// Table pose c_M_t from four ordered corners (PnP AP3P, optional Gauss-Newton refinement, prior's quarter
/// turn); PoseFailed when behind or seen from below.
Result<TablePose> solveTablePose(const std::array<Eigen::Vector2d, 4>& ordered_corners,
                                 const core::Camera& camera, double side_m, bool refine,
                                 const std::optional<Eigen::Isometry3d>& prior);

/// Gauss-Newton on the reprojection error of four object points P (table frame) seen at `uv`
/// through a pinhole (px, py, u0, v0; undistort the pixels first), from c_M_t (close to the
/// minimum): pose perturbed as R ← exp([δω]×) R, t ← t + δt; a step that does not lower the cost
/// ends it (at most 20). Used by solveTablePose's refinement; px = py = 1, u0 = v0 = 0 works on
/// normalised coordinates. Returns c_M_t when a point is behind the camera at the start.
Eigen::Isometry3d refinePoseOnPoints(const Eigen::Isometry3d& c_M_t, const std::array<Eigen::Vector3d, 4>& P,
                                     const std::array<Eigen::Vector2d, 4>& uv, double px, double py, double u0,
                                     double v0);

/// The k with c_M_t · Rz(k·90°) closest to `reference` (k in 0..3).
int yawQuarterTurnsTo(const Eigen::Isometry3d& c_M_t, const Eigen::Isometry3d& reference);
/// c_M_t · Rz(k·90°): the same square table with its frame turned by k quarter turns.
Eigen::Isometry3d turnTableFrame(const Eigen::Isometry3d& c_M_t, int quarter_turns);

/// Ball centre from its image circle ([M] §4, SPEC §3).
///
/// The projected outline of a sphere is an ellipse whose major axis lies along the line from
/// the principal point through its centre. Its end points are approximated by
///   a, b = c ± ρ e,   e = (c - p0) / |c - p0|   (any unit e when c = p0),
/// with (c, ρ) the minimum enclosing circle. Back-projected (distortion removed) to unit rays
/// va, vb, the viewing cone of the sphere has half angle α = ½ acos(va·vb) and axis
/// v̂ = (va + vb) / |va + vb|. A sphere of radius r touches the cone, so its centre is at
///   d = r / sin α
/// along v̂. ([M] eq 4.12 prints d = r sqrt(1 + 1/tan α); from its own d² = r² + c² with
/// c = r / tan α the right form is d = r sqrt(1 + 1/tan² α) = r / sin α.)
/// In table coordinates, with c_M_t = (R, t): camera centre t' = -Rᵀ t, ray v1 = Rᵀ v̂, centre
///   p_t = t' + d v1.
/// Unknown radius: the ball rests on the table, p_t.z = σ r with σ = sign(t'_z) (= +1 with our
/// frame); t'_z + (r / sin α) v1_z = σ r gives
///   r = t'_z / (σ - v1_z / sin α),
/// then d = r / sin α as above.
struct BallOnTableGeometry {
  Eigen::Vector3d va = Eigen::Vector3d::UnitZ(),  ///< unit ray of the major axis end a, camera frame
                  vb = Eigen::Vector3d::UnitZ();  ///< unit ray of the major axis end b, camera frame
  Eigen::Vector3d ray_c = Eigen::Vector3d::UnitZ();  ///< v̂, camera frame
  double alpha = 0.0;       ///< half angle of the viewing cone (rad)
  double radius_m = 0.0;    ///< r (given, or solved)
  double distance_m = 0.0;  ///< d = r / sin α
  Eigen::Vector3d p_t = Eigen::Vector3d::Zero();  ///< ball centre in table coordinates
  Eigen::Vector3d p_c = Eigen::Vector3d::Zero();  ///< ball centre in camera coordinates
};

/// Viewing cone (va, vb, v̂, α) of a ball image circle. Throws InvalidInput on a radius <= 0.
BallOnTableGeometry ballViewingCone(const core::Camera& camera, const Circle& circle);
/// Known radius r_m: d = r / sin α, p_t = t' + d v1.
BallOnTableGeometry ballOnTableKnownRadius(const core::Camera& camera, const Circle& circle,
                                           const Eigen::Isometry3d& c_M_t, double r_m);
/// Unknown radius: r from p_t.z = r, then as above. Fails (returns nullopt) when the ray is
/// parallel to the table or the solution is not positive.
std::optional<BallOnTableGeometry> ballOnTableUnknownRadius(const core::Camera& camera,
                                                            const Circle& circle,
                                                            const Eigen::Isometry3d& c_M_t);

}  // namespace viewline::vision
