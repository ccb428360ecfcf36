#pragma once
// A live camera through Video4Linux2, as a frame source.
//
// Back end: OpenCV's V4L2 capture (cv::VideoCapture with cv::CAP_V4L2), not ViSP's
// vpV4l2Grabber, because (1) it reports each frame's driver buffer time stamp
// (CAP_PROP_POS_MSEC = v4l2_buffer.timestamp, taken by the driver when the frame was captured,
// on CLOCK_MONOTONIC for UVC cameras), (2) it sets exposure (CAP_PROP_AUTO_EXPOSURE,
// CAP_PROP_EXPOSURE) besides resolution and rate, which vpV4l2Grabber does not, and (3) it
// delivers a cv::Mat, our Frame's type, with no copy through vpImage.
//
// Capture stamp: the buffer's time stamp when the driver gives one on the monotonic clock
// (checked on every frame: not zero, not in the future, not more than a second old); otherwise
// the time of the grab, stampMethod() says which. Stamps are seconds since the source was opened.
// A camera that skipped frames shows a stamp gap: a gap of g nominal periods counts round(g) − 1
// dropped frames; a frame delivered more than one period after its stamp counts as late.
//
// As a LiveFrameSource it paces the loop itself (grab() blocks until the driver has a frame) and
// its drops and late frames go into the loop's live report (live.h).
//
// Not tested on hardware (the build machine has no camera): tests cover the errors (a missing
// device, a file that is not a device), each naming the device.

#include <chrono>
#include <cstdint>
#include <memory>
#include <optional>
#include <string>

#include "viewline/runtime/live.h"

namespace cv {
class VideoCapture;
}  // namespace cv

namespace viewline::runtime {

/// Device and settings of a V4L2 camera (0 or < 0: leave the driver's value).
struct V4l2Options {
  std::string device = "/dev/video0";  ///< the device node
  int width = 0;                       ///< requested image width, px (0: the driver's)
  int height = 0;                      ///< requested image height, px (0: the driver's)
  double rate = 0.0;                   ///< requested frame rate, Hz (0: the driver's)
  double exposure = -1.0;              ///< manual exposure in the driver's units (V4L2 exposure_absolute: 100 µs); < 0: the driver's setting
  std::int64_t count = -1;             ///< stop after this many frames (< 0: never)
};

/// A live V4L2 camera (one camera), stamped by the driver where it can be.
class V4l2Source : public LiveFrameSource {
public:
  /// Opens and configures the device; throws core::InvalidInput naming the device when it does
  /// not exist, is not a character device, or cannot be opened as a V4L2 camera.
  explicit V4l2Source(V4l2Options options);
  ~V4l2Source() override;
  V4l2Source(const V4l2Source&) = delete;
  V4l2Source& operator=(const V4l2Source&) = delete;
  std::size_t cameraCount() const override { return 1; }
  /// Now (s since open): a live camera is polled; grab() blocks until the next frame.
  std::optional<core::Timestamp> nextReadyTime() const override;
  /// Waits for the next frame; nullopt when the driver returned none (counted as dropped).
  std::optional<Frame> grab() override;
  /// "driver buffer time stamps" or "time of grab (the driver gave no usable buffer time stamp)".
  std::string stampMethod() const;
  /// Frames the camera skipped (stamp gaps) or the driver failed to deliver.
  std::uint64_t dropped() const override { return dropped_; }
  /// Frames delivered more than one period after their capture stamp.
  std::uint64_t late() const { return late_; }
  /// Frames the camera captured: read (or failed to read) plus the gaps in the stamps.
  std::uint64_t delivered() const override { return sequence_ + gaps_; }
  /// late(): frames that waited in the driver's queue for over a period.
  std::uint64_t queuedLate() const override { return late_; }
  /// "v4l2 camera DEVICE at RATE fps (STAMP METHOD)".
  std::string describe() const override;
  /// The frame rate in force (the driver's answer to the request), Hz.
  double rate() const { return rate_; }

private:
  double now() const;  ///< s since open
  V4l2Options opt_;
  std::unique_ptr<cv::VideoCapture> cap_;
  std::chrono::steady_clock::time_point t0_;
  double rate_ = 0.0;
  bool buffer_stamps_ = true;
  std::optional<double> last_stamp_;
  std::uint64_t sequence_ = 0, dropped_ = 0, late_ = 0, gaps_ = 0;
};

}  // namespace viewline::runtime
