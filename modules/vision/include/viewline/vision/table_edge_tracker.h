#pragma once
// Frame-to-frame tracking of the table's four sides and of the ball between full detections
// (the observer's fast path; [M]'s full pipeline, vision::TableDetector, acquires the table and
// takes over whenever tracking fails).
//
// Sides: from the previous frame's corners P0..P3 (pixels), `samples_per_side` points are
// spread over the middle 70 % of each side; at each, the red feature f = R − max(G, B) of the
// raw image is sampled bilinearly along the outward normal over ±search_px (0.25 px steps) and
// the edge is the crossing of the level half-way between the inside and outside plateaus
// (needs contrast >= min_contrast). A total-least-squares line is fitted to each side's edge
// points, refitted without the points farther than 1 px (the ball, clutter); adjacent lines
// intersect in the new corners. Fails (nullopt) when a side keeps fewer than min_points points
// or a corner moved more than search_px.
// Ball: [M]'s ball steps (blur, HLS, green threshold, opening, largest contour) in a window
// around the previous circle; the circle is the least-squares ellipse's centre and semi-major
// axis (cv::fitEllipse) when the contour has enough points, else cv::minEnclosingCircle.

#include <Eigen/Core>
#include <array>
#include <opencv2/core.hpp>
#include <optional>
#include <vector>

#include "viewline/vision/table_detector.h"

namespace viewline::vision {

/// Settings of TableEdgeTracker (pixels of the raw image).
struct TableEdgeTrackerConfig {
  int samples_per_side = 14;   ///< edge samples spread over the middle 70 % of each side
  double search_px = 5.0;      ///< px, search along the outward normal (and largest corner motion)
  double min_contrast = 40.0;  ///< grey levels of R − max(G, B)
  int min_points = 7;          ///< fewer edge points kept on a side: tracking fails
  double ball_window_factor = 2.2;  ///< window half size = factor · radius + motion margin
  double ball_margin_px = 6.0;  ///< px, the motion margin of the ball window
};

/// cv::GaussianBlur(bgr(roi), dst, Size(ksize, ksize), 0) value for value (its default border:
/// the pixels around the window from the image, reflected at the image's edges), for a BGR 8-bit
/// image; ksize 3 and 5 by exact integer sums and OpenCV 4.6's rounding, without its per-call
/// set-up; other sizes, other types and submatrix images by OpenCV. `roi` must lie inside the image.
void gaussianBlurWindow(const cv::Mat& bgr, const cv::Rect& roi, int ksize, cv::Mat& dst);

/// The observer's fast path: the table's sides and the ball followed from the previous frame.
class TableEdgeTracker {
public:
  /// `detector`: [M]'s ball steps and thresholds (shared with TableDetector); both are copied.
  TableEdgeTracker(const TableDetectorConfig& detector, const TableEdgeTrackerConfig& config = {});

  /// New corners (order P0..P3 kept) from the previous ones, or nullopt.
  std::optional<std::array<Eigen::Vector2d, 4>> trackCorners(const cv::Mat& bgr,
                                                             const std::array<Eigen::Vector2d, 4>& previous) const;
  /// The ball circle in a window around the previous one, or nullopt.
  std::optional<Circle> trackBall(const cv::Mat& bgr, const Circle& previous);

private:
  TableDetectorConfig detector_;
  TableEdgeTrackerConfig config_;
  cv::Mat kernel_, blurred_, hls_, mask_, eroded_;
  std::vector<std::vector<cv::Point>> contours_;
};

}  // namespace viewline::vision
