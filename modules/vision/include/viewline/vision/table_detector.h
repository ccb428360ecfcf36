#pragma once
// [M]'s table-ball image analysis (SPEC §3): table pose from the red surface
// and ball position on the table from the green ball.
//
// Steps (both implementations): Gaussian blur; BGR -> HLS; threshold red;
// morphological open and close; largest external contour; convex hull;
// approxPolyDP (ε = 1 % of the image width); drop hull points near the ball;
// four longest segments; pairwise intersections with |ta|·|tb| < 1.5; order;
// solvePnP(SOLVEPNP_AP3P) against (±L/2, ±L/2, 0). Ball: threshold green (same
// HLS image); open; largest external contour; minEnclosingCircle; viewing cone
// and d = r / sin α (table_geometry.h), known- and unknown-radius variants.
//
// TableDetector is the production version, same steps, faster:
//   - works in a window around the last table (and ball) found, with the full
//     frame only for the first frame and when the window cuts the table;
//     blur and morphology read the real neighbourhood of the window (OpenCV
//     filters on a sub-matrix use the parent image), so inside the window the
//     masks equal the full-frame ones;
//   - the red and green masks come out of one pass over the HLS image through
//     three 256-entry lookup tables (bit-exact with cv::inRange);
//   - all buffers are reused between frames.
// With `refine = false` it returns what the reference returns (tested). With
// `refine = true` (default) it adds, after [M]'s steps, sub-pixel edges: the
// thresholded masks put the edges where a colour threshold happens to cut the
// blurred transition (1-2 px off, depending on the neighbouring colour), so
// each side is re-fitted (robust line fit) to sub-pixel edge points
// found on the raw image along its normal (crossing of the mid level of the
// "redness" R - max(G, B) profile), the corners re-intersected, the AP3P pose
// refined by Levenberg-Marquardt on the four corners, and the ball circle
// replaced by a least-squares ellipse through sub-pixel edge points of the
// "greenness" G - max(R, B) on 32 rays (centre = ellipse centre, radius =
// semi-major axis, i.e. the minimum enclosing circle of the true outline).
// With raised borders (border_height_m > 0) the pose is then refined on the
// edge points against the visible 3D boundary (see refinePoseWithBorders).
// The greenness mid level is biased on a shaded ball (its dark limb has a lower
// level: -0.05 px of radius), too much for the distance d = r / sin α (1 mm is
// 0.016 px at 0.5 m). So with ball_outline = SphereCone (default) the ball's
// circle comes from the fit of the sphere's viewing cone to outline points
// found by colour unmixing, which do not depend on the shading (ball_outline.h),
// started from [M]'s circle; only when that fit is refused (ball against the
// black border on much of its outline, occluded) does the greenness ellipse
// above give the circle. ball_outline = GreennessEllipse always uses the
// ellipse (the earlier production path, kept for comparison).
//
// referenceTableScene() is the plain speed baseline written the straightforward
// way (as [M]'s Python): full frame at every step, fresh buffers, two inRange
// calls per colour, no reuse.

#include <Eigen/Geometry>
#include <array>
#include <opencv2/core.hpp>
#include <optional>
#include <vector>

#include "viewline/core/camera.h"
#include "viewline/vision/ball_outline.h"
#include "viewline/vision/color.h"
#include "viewline/vision/detection.h"
#include "viewline/vision/table_geometry.h"

namespace viewline::vision {

/// Configuration of [M]'s table-ball detector (geometry in m, colour ranges, morphology, refinements).
struct TableDetectorConfig {
  double side_m = 0.3;            ///< L, side of the red square (m)
  /// Height of raised borders around the red square (m); 0 = flat. With `refine`, sides seen
  /// from outside are modelled by the border's top inner edge (which hides the surface edge).
  double border_height_m = 0.0;
  double ball_radius_m = 0.025;   ///< r for the known-radius variant (m)
  int blur_ksize = 5;             ///< Gaussian blur kernel (odd; 1 = none)
  ColorRange red_hls{165, 12, 30, 225, 80, 255};   ///< (H, L, S) of the table surface
  ColorRange green_hls{35, 90, 20, 235, 60, 255};  ///< (H, L, S) of the ball
  int open_kernel_px = 5;         ///< table mask opening (odd; 1 = none)
  int close_kernel_px = 5;        ///< table mask closing
  int ball_open_kernel_px = 3;    ///< ball mask opening
  CornerSearchParams corners;     ///< approxPolyDP ε, ball exclusion, |ta|·|tb|
  double min_table_area_px = 300.0;  ///< smallest red blob accepted as the table, px
  double min_ball_area_px = 8.0;  ///< smallest green blob accepted as the ball, px
  double roi_margin_fraction = 0.1;  ///< window = last table box grown by this fraction ...
  int roi_margin_px = 10;            ///< ... plus this many pixels on each side
  bool refine = true;                ///< production refinements (see above); false = [M] exactly
  /// Ball outline with `refine`: SphereCone (production) or GreennessEllipse (the earlier one).
  enum class BallOutline { GreennessEllipse, SphereCone };
  BallOutline ball_outline = BallOutline::SphereCone;  ///< outline method of the ball circle with `refine`
  BallOutlineParams ball_outline_params;  ///< rays, reach, background separation (ball_outline.h)
  double max_reprojection_px = 2.0;  ///< corner reprojection RMS above which the pose is refused
  double corner_sigma_px = 0.5;      ///< corner noise used for the table "pixel" covariance
  double ball_edge_noise_px = 0.5;   ///< σe of the ball circle centre: var = σe² / (π ρ)

  void validate() const;  ///< throws core::InvalidInput naming the field
};

/// Table pose c_M_t from the red square's four corners.
struct TableMeasurement : Measurement {  ///< pixel = mean of the four corners
  Eigen::Isometry3d c_M_t = Eigen::Isometry3d::Identity();  ///< table frame in the camera frame
  std::array<Eigen::Vector2d, 4> corners;  ///< image corners of P0..P3 (see orderTableCorners)
  double reprojection_rms_px = 0.0;  ///< RMS reprojection error of the four corners, px
  bool used_roi = false;  ///< found in the window around the last table
};

/// The ball on the table: its circle and its centre with known and unknown radius.
struct BallOnTableMeasurement : Measurement {  ///< pixel = ball circle centre
  Circle circle;                       ///< image circle used for the geometry
  BallOnTableGeometry known_radius;    ///< with config.ball_radius_m
  std::optional<BallOnTableGeometry> unknown_radius;  ///< radius solved from z = r
};

/// What one image gave: the table pose, the ball on the table and the ball's circle.
struct TableScene {
  /// The table pose, or why there is none
  Result<TableMeasurement> table = Result<TableMeasurement>::fail(FailureReason::NotFound, "");
  Result<BallOnTableMeasurement> ball =  ///< the ball on the table (needs the table pose), or why there is none
      Result<BallOnTableMeasurement>::fail(FailureReason::NotFound, "");
  std::optional<Circle> ball_circle;  ///< the ball in the image, even without a table pose
};

/// [M]'s table-ball detector, production version: windowed, bit-exact masks, sub-pixel refinements.
class TableDetector {
public:
  /// Detector for `camera` (intrinsics and distortion) with this configuration (validated; throws core::InvalidInput).
  TableDetector(core::Camera camera, TableDetectorConfig config = {});

  /// Detect the table and the ball in a BGR CV_8UC3 image captured at `stamp`.
  TableScene detect(const cv::Mat& bgr, core::Timestamp stamp);

  /// Resolve the square's quarter-turn ambiguity with this pose (e.g. from the arm's
  /// kinematics); afterwards each frame uses the previous estimate.
  void setPrior(const Eigen::Isometry3d& c_M_t) { prior_ = c_M_t; }
  /// Forget the window and the prior (next frame searches the full image).
  void reset();

  /// The configuration in use.
  const TableDetectorConfig& config() const { return config_; }
  /// The camera in use.
  const core::Camera& camera() const { return camera_; }

private:
  bool processWindow(const cv::Mat& bgr, const cv::Rect& roi);

  core::Camera camera_;
  TableDetectorConfig config_;
  cv::Mat open_kernel_, close_kernel_, ball_kernel_;
  std::array<unsigned char, 256> lut_h_{}, lut_l_{}, lut_s_{};
  cv::Mat blurred_, hls_, red_, green_;
  std::vector<std::vector<cv::Point>> contours_, ball_contours_;
  std::vector<cv::Point> table_contour_;
  std::optional<Circle> ball_circle_;
  std::vector<cv::Point> ball_contour_;
  std::optional<cv::Rect> window_;
  std::optional<Eigen::Isometry3d> prior_;
};

/// The plain reference of [M]'s steps (speed baseline); see the file comment.
TableScene referenceTableScene(const cv::Mat& bgr, core::Timestamp stamp, const core::Camera& camera,
                               const TableDetectorConfig& config,
                               const std::optional<Eigen::Isometry3d>& prior = std::nullopt);

}  // namespace viewline::vision
