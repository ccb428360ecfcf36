#pragma once
// Frame sources that read footage from disk: an image sequence (one file per frame, named by a
// printf pattern as ViSP's vpVideoReader / vpDiskGrabber expect, e.g. `image.%04d.pgm`) and a video
// file decoded by OpenCV's FFmpeg back end (cv::VideoCapture with cv::CAP_FFMPEG).
//
// Both are offline: nextReadyTime() is the next frame's stamp, so a batch run goes as fast as the
// loop can and a paced run (runtime::Pacing) replays the footage at its recorded rate. There is
// no truth behind a file: capture_time = stamp. Stamps come from, in order of preference, a stamps
// file (stamps.h: `index,stamp` lines), the video container's presentation times
// (CAP_PROP_POS_MSEC), or a nominal rate (frame i at (i − first) / rate); stampMethod() says which.
//
// Errors name the file: a missing first image, an image or video that cannot be decoded, a stamps
// file that does not fit the frames; all are core::InvalidInput.

#include <cstdint>
#include <memory>
#include <optional>
#include <string>
#include <vector>

#include "viewline/runtime/frame_source.h"
#include "viewline/runtime/stamps.h"

namespace cv {
class VideoCapture;
}  // namespace cv

namespace viewline::runtime {

/// Fills a printf-style file pattern with one integer conversion (%d, %4d, %04d; "%%" is a literal
/// '%'). Throws core::InvalidInput naming the pattern when it has no or several conversions, or
/// any other conversion (the pattern is user input: it never reaches printf).
std::string formatFramePattern(const std::string& pattern, std::int64_t index);

/// Where an image sequence is and how its frames are stamped.
struct ImageSequenceOptions {
  std::string pattern;      ///< printf pattern of the files, e.g. `/data/seq/image.%04d.pgm`
  std::int64_t first = 0;   ///< index of the first frame (ignored with a stamps file: its indices are used)
  double rate = 30.0;       ///< frames per second when there is no stamps file, Hz (stamp (i − first) / rate)
  std::string stamps_file;  ///< `index,stamp` CSV ("" : stamps from the rate)
  std::int64_t count = -1;  ///< at most this many frames (< 0: until the first missing file or the stamps' end)
};

/// An image sequence on disk as a one-camera frame source (grey images stay CV_8UC1, colour ones
/// are CV_8UC3 BGR).
class ImageSequenceSource : public FrameSource {
public:
  /// Checks the pattern, the stamps file and that the first image exists (InvalidInput naming it).
  explicit ImageSequenceSource(ImageSequenceOptions options);
  std::size_t cameraCount() const override { return 1; }
  /// The next frame's stamp, s; nullopt after the last frame.
  std::optional<core::Timestamp> nextReadyTime() const override;
  /// Reads the next image; throws InvalidInput naming the file when it cannot be decoded.
  std::optional<Frame> grab() override;
  /// "stamps file <path>" or "rate <Hz> Hz".
  std::string stampMethod() const;
  /// The file of the next frame ("" after the last).
  std::string nextFile() const;
  /// Frames delivered so far.
  std::uint64_t delivered() const { return sequence_; }

private:
  void advance();  ///< finds the next frame (index and stamp) or marks the end
  ImageSequenceOptions opt_;
  std::vector<StampEntry> stamps_;
  std::size_t stamp_pos_ = 0;
  std::optional<StampEntry> next_;
  std::uint64_t sequence_ = 0;
};

/// A video file and how its frames are stamped.
struct VideoOptions {
  std::string path;         ///< the video file (any container/codec Debian's FFmpeg decodes)
  std::string stamps_file;  ///< `index,stamp` CSV, index = frame number from 0 ("" : the container's times)
  std::int64_t count = -1;  ///< at most this many frames (< 0: all)
};

/// A video file decoded with OpenCV's FFmpeg back end as a one-camera frame source (CV_8UC3 BGR).
/// One frame is decoded ahead, so nextReadyTime() knows the next stamp and the end of the file.
class VideoSource : public FrameSource {
public:
  /// Opens the file (InvalidInput naming it when missing or not decodable) and decodes frame 0.
  explicit VideoSource(VideoOptions options);
  ~VideoSource() override;
  VideoSource(const VideoSource&) = delete;
  VideoSource& operator=(const VideoSource&) = delete;
  std::size_t cameraCount() const override { return 1; }
  /// The stamp of the decoded-ahead frame, s; nullopt at the end of the file.
  std::optional<core::Timestamp> nextReadyTime() const override;
  /// The decoded-ahead frame; decodes the one after it.
  std::optional<Frame> grab() override;
  /// "stamps file <path>", "container time stamps (CAP_PROP_POS_MSEC)" or "nominal rate <Hz> Hz (...)".
  std::string stampMethod() const;
  /// The container's nominal frame rate (CAP_PROP_FPS), Hz; 0 when unknown.
  double nominalRate() const { return nominal_rate_; }

private:
  void decodeNext();
  VideoOptions opt_;
  std::unique_ptr<cv::VideoCapture> cap_;
  std::vector<StampEntry> stamps_;
  std::optional<Frame> next_;
  std::uint64_t decoded_ = 0;
  double nominal_rate_ = 0.0;
  bool container_stamps_ = true;
};

}  // namespace viewline::runtime
