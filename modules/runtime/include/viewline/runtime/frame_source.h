#pragma once
// Where images come from: one interface for the simulator's renderer, a live camera, a video
// file, a recording or a remote node (ViSP's grabbers play the same role: vpV4l2Grabber,
// vpVideoReader, vpDiskGrabber all open() then acquire()).
//
// A source is polled by the scheduler: nextReadyTime() says when its next frame can be taken
// (for a renderer: the end of the frame's exposure, when everything it shows has been
// simulated; for a live camera: now), grab() takes it. Frames carry two times: capture_time
// (mid-exposure, what a simulator knows to be true) and stamp (what the driver reports, with its
// jitter), and the estimator only ever sees the stamp.

#include <cstdint>
#include <optional>
#include <opencv2/core/mat.hpp>

#include "viewline/core/time.h"

namespace viewline::runtime {

/// One image from a camera of the rig, with its capture time and the driver's time stamp.
struct Frame {
  std::size_t camera = 0;             ///< index of the camera in its rig
  std::uint64_t sequence = 0;         ///< per-camera frame counter
  core::Timestamp capture_time = 0.0; ///< mid-exposure, s (true time in a simulator)
  core::Timestamp stamp = 0.0;        ///< the time stamp the driver reports, s
  cv::Mat image;                      ///< CV_8UC3 BGR or CV_8UC1
};

/// Where images come from (renderer, live camera, video, recording, remote node), polled by the scheduler.
class FrameSource {
public:
  virtual ~FrameSource() = default;
  /// Number of cameras behind the source (frames carry indices below it).
  virtual std::size_t cameraCount() const = 0;
  /// When the next frame can be grabbed, s; nullopt once the source has ended.
  virtual std::optional<core::Timestamp> nextReadyTime() const = 0;
  /// Takes the next frame. nullopt: the frame was lost (dropped by the camera or the link); the
  /// source has then moved past it all the same.
  virtual std::optional<Frame> grab() = 0;
};

}  // namespace viewline::runtime
