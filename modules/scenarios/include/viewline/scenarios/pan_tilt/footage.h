#pragma once
// The pan-tilt scenario's perception on real footage: [T]'s disc detector
// (vision::ScreenTargetDetector) inside a search window, and the pan-tilt target filter
// (tracking::PlanarTargetFilter) run in image coordinates to place the window and to predict the
// disc one frame ahead. What a pan-tilt unit pointed at a real target would run before its
// control law; here it tracks a recorded sequence (runtime::ImageSequenceSource, VideoSource).
//
// A real scene is cluttered, so the detector (which takes the centroid of everything its
// threshold separates) only sees a window: the last blob's bounding box (the component of the
// binarised window at the detector's own threshold that holds the centroid), grown by
// window_growth and window_margin_px, centred at the filter's prediction at the frame's stamp,
// the way ViSP's vpDot2 searches around its last blob. When that window fails, the same window at
// the last measured centre is tried (a jerk the motion model did not foresee), then windows at
// the prediction grown by window_growth each time while the blob is clipped, up to max_retries.
//
// The filter works in pixels: its plane is the image (p in px, v in px/s; q in px²/s³). Its
// measurement covariance is the detector's (var σe²/(πR) + floor, screen_target_detector.h).

#include <Eigen/Core>
#include <opencv2/core/types.hpp>
#include <cmath>
#include <functional>
#include <optional>
#include <string>
#include <vector>

#include "viewline/runtime/frame_source.h"
#include "viewline/runtime/live.h"
#include "viewline/tracking/planar_target/filter.h"
#include "viewline/vision/screen_target_detector.h"

namespace viewline::scenarios::pan_tilt {

/// Detector, filter and search window of the footage tracker.
struct FootageTrackerConfig {
  vision::ScreenTargetDetectorConfig detector;  ///< crop is set per frame (the window); the rest is used as given
  tracking::TargetFilterConfig filter;          ///< in pixels: q in px²/s³, init_velocity_sigma in px/s
  Eigen::Vector2d initial_px = Eigen::Vector2d::Zero();  ///< the disc's centre on the first frame, px (a click)
  Eigen::Vector2d initial_half_size = Eigen::Vector2d(40.0, 30.0);  ///< first window's half-size, px
  double window_growth = 1.2;     ///< window half-size = this x the last blob's half-size + margin
  double window_margin_px = 4.0;  ///< px added to each half-size
  int max_retries = 3;            ///< window growths after a clipped blob before the frame counts as lost
  void validate() const;          ///< throws core::InvalidInput naming the field
};

/// Settings for a bright disc on a dark target (ViSP's mire sequences), starting at `initial_px`:
/// full resolution (scale 1), Otsu threshold, 3x3 median, a constant-velocity filter in pixels
/// (q = 2e4 px²/s³, 200 px/s initial velocity std).
FootageTrackerConfig brightDiscTrackerConfig(const Eigen::Vector2d& initial_px);

/// What the tracker did on one frame.
struct FootageStep {
  double stamp = 0.0;      ///< the frame's stamp, s
  bool detected = false;   ///< the detector found the disc in the window
  Eigen::Vector2d measured_px = Eigen::Vector2d::Zero();   ///< the detector's centroid, px (when detected)
  bool has_prediction = false;  ///< the filter had a track before this frame (predicted_px is set)
  Eigen::Vector2d predicted_px = Eigen::Vector2d::Zero();  ///< the filter's prediction at this stamp, before the update, px
  Eigen::Vector2d filtered_px = Eigen::Vector2d::Zero();   ///< the filter's estimate after the update, px
  cv::Rect window;                                         ///< the search window used last, px
  bool accepted = false;   ///< the filter's gate fused the measurement
};

/// [T]'s detector in a moving window, placed by the pan-tilt target filter run in pixels.
class FootageTracker {
public:
  /// Tracker with this configuration (validated).
  explicit FootageTracker(FootageTrackerConfig config);
  /// Detects the disc in `frame` (grey or BGR) and updates the filter.
  FootageStep track(const runtime::Frame& frame);
  /// The filter (pixel coordinates).
  const tracking::PlanarTargetFilter& filter() const { return filter_; }

private:
  FootageTrackerConfig config_;
  tracking::PlanarTargetFilter filter_;
  Eigen::Vector2d half_size_;  ///< the last blob's half-size, px
  Eigen::Vector2d last_px_;    ///< the last measured centre (before the filter has a track), px
};

/// Figures of a FootageTracker run over a whole source, optionally against ViSP's vpDot2.
struct FootageReport {
  std::size_t frames = 0;     ///< frames grabbed
  std::size_t lost = 0;       ///< frames the tracker did not detect the disc in (or the source lost)
  std::size_t compared = 0;   ///< frames detected by both trackers
  double vpdot2_rms_px = std::nan("");  ///< RMS distance between our centre and vpDot2's centre of gravity, px
  double vpdot2_max_px = std::nan("");  ///< its maximum, px
  std::size_t predicted = 0;  ///< frames with a one-frame-ahead prediction and a detection on this and the previous frame
  double predicted_rms_px = std::nan("");  ///< RMS of (filter prediction at the stamp − measured centre), px
  double hold_rms_px = std::nan("");       ///< RMS of (previous measured centre − measured centre), px
  std::vector<FootageStep> steps;          ///< every frame's step
  /// A live source (runtime::LiveFrameSource: a camera, paced footage): the frames missed and the
  /// per-frame processing times; unset otherwise.
  std::optional<runtime::LiveReport> live;
};

/// How trackFootage runs beyond the tracker's own settings.
struct FootageRunOptions {
  bool vpdot2 = false;  ///< also run ViSP's vpDot2 on the same frames and compare the centres
  /// Live source: a frame's processing (grab, track, on_frame) must take at most this long, s
  /// (one frame period of the camera).
  double deadline_s = 1.0 / 30.0;
  std::string deadline_origin = "one frame period at 30 fps";  ///< why that deadline, for the report
  runtime::WallClock* clock = nullptr;  ///< live source: the clock of the processing times (null: steady)
  /// Called after each frame is tracked (a display), with the live status line ("" unless live);
  /// part of the frame's processing. Returns false to end the run (a viewer's quit key).
  std::function<bool(const runtime::Frame&, const FootageStep&, const std::string& live_status)> on_frame;
};

/// Runs `tracker` on every frame of `source` (until it ends). With options.vpdot2, also runs ViSP's
/// vpDot2 blob tracker (initTracking at config.initial_px, then track()) on the same grey frames
/// and compares the centres. On a live source each frame's processing is timed against
/// options.deadline_s and the report's `live` says how many frames were missed.
FootageReport trackFootage(runtime::FrameSource& source, const FootageTrackerConfig& config,
                           const FootageRunOptions& options);
/// trackFootage with only the vpDot2 comparison chosen.
FootageReport trackFootage(runtime::FrameSource& source, const FootageTrackerConfig& config, bool vpdot2);

}  // namespace viewline::scenarios::pan_tilt
