#pragma once
// Colour-blob ball detector: threshold in HSV, open/close, external contours,
// best round blob, sub-pixel centre, minimum enclosing circle.
//
// Centre: the first moments of the blob's outer contour polygon (Green's
// theorem, cv::moments on the contour). The contour runs through the centres
// of the boundary pixels of the thresholded mask, so it is symmetric about the
// true centre for a round blob: no bias, and the quantisation error averages
// over the whole boundary (holes such as a specular highlight do not matter).
//
// Pixel covariance. If the boundary is displaced radially by independent
// errors δ(θ) of std σe per boundary pixel (edge noise, quantisation), the
// centroid of a disc of radius R moves by δc_x = (1/π) ∫ cos θ δ(θ) dθ;
// with one independent sample per pixel of arc (Δθ = 1/R, 2πR samples)
//     var(c_x) = σe² / (π R)        (same for c_y, uncorrelated),
// plus a floor σ_min² for everything else. A blob that is not round
// (occluded, merged with clutter) is flagged Degraded and its variance grows
// by (R (1 - roundness))², the order of the centroid shift such a cut causes.
//
// Radius: cv::minEnclosingCircle of the contour points (pixel centres) plus
// edge_offset_px (0.5: the true edge lies half a pixel outside the outermost
// pixel centres).
//
// Sphere correction: the image of a sphere is an ellipse whose centre is not
// the image of the sphere's centre (perspective). When the detector knows the
// camera, it reports as `pixel` the image of the cone axis: with the blob
// centre c and radius ρ, the end points a, b = c ± ρ e of the major axis
// (e = unit vector from the principal point to c) back-project to rays va, vb
// and the sphere centre lies along va + vb (see table_geometry.h). Without a
// camera, `pixel` is the blob centre. `blob_center` always holds the latter.
//
// Speed: with a predicted position the detector works in a square window
// around it and only falls back to the full frame when the window shows no
// ball or cuts it; buffers are reused between calls (one detector per
// camera, not thread-safe).
//
// Full-frame search, coarse to fine: the colour test first runs on every
// s-th pixel of every s-th row only (coarse_step_px, s² fewer pixels to
// convert). Any s x s block of pixels holds exactly one sample, so every blob
// that holds an s x s block of ball-coloured pixels is hit; a hit is kept
// when its own neighbourhood holds such a block (which drops single noisy
// pixels, as the opening would), and the exact pipeline above then runs in a
// window around each group of kept hits, grown by the pixels between samples
// (s - 1) and the reach of the opening and closing. Such a blob is found and
// measured exactly as the exhaustive search would (same contour, same centre,
// bit for bit; test CoarseFullFrameSearchGivesTheExhaustiveAnswerBitForBit);
// only blobs with no s x s block of colour go unseen. With the default s = 2
// that is thin lines and isolated crosses, never a ball's disc; s = 3 also
// misses discs of radius under ~2 px whose anti-aliased edge fails the colour
// test (areas of 12-15 px), so raise it only for balls that stay larger. Clutter that gives many groups, or
// windows over half the frame, falls back to the exhaustive search, and so
// does a blob that reaches its window's edge.

#include <Eigen/Core>
#include <opencv2/core.hpp>
#include <optional>
#include <vector>

#include "viewline/core/camera.h"
#include "viewline/vision/color.h"
#include "viewline/vision/detection.h"

namespace viewline::vision {

/// Configuration of the colour-blob ball detector (HSV range, morphology, size and roundness gates, noise model).
struct BallDetectorConfig {
  ColorRange hsv{35, 85, 80, 255, 30, 255};  ///< HSV range of the ball (default: green)
  int open_kernel_px = 3;      ///< elliptic opening kernel size (odd, 0 or 1 = none)
  int close_kernel_px = 5;     ///< elliptic closing kernel size (odd, 0 or 1 = none)
  double min_area_px = 12.0;   ///< blobs with fewer pixels are "too small"
  double noise_area_px = 3.0;  ///< blobs below this are ignored altogether
  double min_roundness = 0.45;   ///< area / (π ρ²) below which a blob is no ball
  double good_roundness = 0.80;  ///< below: Quality::Degraded
  double ambiguity_ratio = 0.7;  ///< runner-up score >= ratio * best score -> Ambiguous
  double roi_half_size_px = 48.0;  ///< half side of the window around a predicted position
  bool fallback_full_frame = true;  ///< search the full frame when the window fails
  double edge_noise_px = 0.5;    ///< σe in var = σe² / (π R)
  double min_sigma_px = 0.05;    ///< σ floor of the centre
  double edge_offset_px = 0.5;   ///< added to the minEnclosingCircle radius
  int coarse_step_px = 2;        ///< full-frame search: colour test on every k-th pixel first (1 = every pixel)

  /// Throws core::InvalidInput naming the field.
  void validate() const;
};

/// A detected ball: centre pixel (sphere-corrected with a camera) with covariance, radius and blob shape.
struct BallMeasurement : Measurement {
  double radius_px = 0.0;  ///< minEnclosingCircle radius + edge offset
  Eigen::Vector2d circle_center = Eigen::Vector2d::Zero();  ///< minEnclosingCircle centre (px)
  double area_px = 0.0;    ///< blob area (contour polygon area + half its perimeter)
  double roundness = 0.0;  ///< area / (π radius²)
  bool used_roi = false;   ///< found in the window around the prediction
  Eigen::Vector2d blob_center = Eigen::Vector2d::Zero();  ///< contour centroid (px)
};

/// One step of a morphological opening or closing: the erosion (erode = true) or dilation of a
/// single-channel 8-bit image `src` by the non-zero entries of `kernel` (anchor at its centre),
/// the outside of the image neutral (255 for the erosion, 0 for the dilation): cv::erode /
/// cv::dilate with their default border, value for value, into `dst` (not `src`), with no heap
/// allocation once `dst` has src's size (OpenCV builds a filter engine on every call).
void morphologyStep(const cv::Mat& src, cv::Mat& dst, const cv::Mat& kernel, bool erode);

/// Colour-blob ball detector with sub-pixel centre, covariance from the edge noise and an optional search window.
class BallDetector {
public:
  /// With a camera, `pixel` is corrected to the image of the sphere centre (see above).
  explicit BallDetector(BallDetectorConfig config = {}, std::optional<core::Camera> camera = std::nullopt);

  /// Detect in a BGR CV_8UC3 image captured at `stamp`. With `predicted` (pixel) the search
  /// starts in a window of half size config.roi_half_size_px around it.
  Result<BallMeasurement> detect(const cv::Mat& bgr, core::Timestamp stamp,
                                 const std::optional<Eigen::Vector2d>& predicted = std::nullopt);

  /// The configuration in use.
  const BallDetectorConfig& config() const { return config_; }

private:
  // One search: the windows it looks in (the whole frame, a tracking window, or the coarse
  // search's windows), then the best candidate of all of them.
  Result<BallMeasurement> search(const cv::Mat& bgr, const std::vector<cv::Rect>& windows, bool whole_frame,
                                 core::Timestamp stamp, const std::optional<Eigen::Vector2d>& predicted,
                                 bool& cut_by_window);
  // Fills windows_ from the coarse colour test; false when the exhaustive search is the better one.
  bool coarseWindows(const cv::Mat& bgr);
  // Adds the candidates of one window to the candidate list (contours copied into kept_).
  void collect(const cv::Mat& bgr, const cv::Rect& window, const std::optional<Eigen::Vector2d>& predicted);

  BallDetectorConfig config_;
  std::optional<core::Camera> camera_;
  cv::Mat open_kernel_, close_kernel_;
  cv::Mat hsv_, mask_, morph_;  // reused buffers (morph_: between the opening's / closing's two steps)
  std::vector<std::vector<cv::Point>> contours_;
  std::vector<std::vector<cv::Point>> kept_;  // candidates' contours (capacity reused)
  std::size_t kept_count_ = 0;
  double largest_tiny_ = 0.0;                   // largest blob under min_area_px of this search
  cv::Mat coarse_bgr_, coarse_hsv_, coarse_mask_;  // the coarse search's samples
  std::vector<cv::Point> hits_;  // the coarse search's samples that passed (full-resolution pixels)
  std::vector<cv::Rect> windows_;
};

}  // namespace viewline::vision
