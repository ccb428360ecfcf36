#pragma once
// The footage of a multi-camera rig, one source per camera, merged into one source in stamp order.
//
//   std::vector<runtime::MergedCamera> cams = {{"side", side_source, 656, 480}, {"rear", rear_source, 656, 480}};
//   runtime::MergedFrameSource footage(cams);
//   while (auto t = footage.nextReadyTime()) { auto frame = footage.grab(); ... frame->camera ... }
//
// Each camera's `source:` (images, video or v4l2; runtime/source_config.h) is opened by
// makeFrameSource, so a live camera goes the same way as a file. The cameras' stamps must share
// one clock (stamps files written by the capture, or V4L2's CLOCK_MONOTONIC); a video's container
// times start at 0 per file and suit one camera only. Every frame must be a colour image of the
// camera's calibrated size (the colour detectors segment the calibrated image).

#include <cstdint>
#include <memory>
#include <optional>
#include <string>
#include <vector>

#include "viewline/runtime/frame_source.h"
#include "viewline/runtime/live.h"
#include "viewline/runtime/source_config.h"

namespace viewline::runtime {

/// "images <pattern>", "video <path>", "v4l2 <device>" or "recording <folder>": a source named for messages.
std::string describeSource(const SourceConfig& source);

/// One camera's footage opened for a session (openSingleCameraFootage).
struct SingleCameraFootage {
  std::unique_ptr<FrameSource> source;  ///< the footage
  core::Timestamp t0 = 0.0;             ///< s, the ready time of its first frame
  LiveFrameSource* live = nullptr;      ///< `source` when it runs at its own pace (V4L2, pace: true), else null
};

/// Opens `config` (makeFrameSource with `clock`; null: the steady clock) as the footage of one
/// camera. Throws core::InvalidInput starting "source: " when it cannot be opened, holds more than
/// one camera (`role` names the one it should be, e.g. "the head camera") or holds no frame.
SingleCameraFootage openSingleCameraFootage(const SourceConfig& config, WallClock* clock, const std::string& role);

/// One camera of a merged source: its name in the rig, its footage and its calibrated image size.
struct MergedCamera {
  std::string name;     ///< the rig's camera name (messages name it as cameras[name].source)
  SourceConfig source;  ///< images, video or v4l2
  unsigned width = 0,   ///< calibrated image width, px
           height = 0;  ///< calibrated image height, px
};

/// The cameras' sources merged in stamp order: the next frame is the camera's whose next frame is
/// ready first (ties: the lower index; V4L2 cameras, always ready, in turn), handed out with
/// `camera` set to its index in the list.
class MergedFrameSource : public LiveFrameSource {
public:
  /// Opens every camera's source (makeFrameSource; throws core::InvalidInput naming the camera and
  /// its file or device, or a sim or recording kind) with `clock` for paced footage (null: the steady clock).
  explicit MergedFrameSource(const std::vector<MergedCamera>& cameras, WallClock* clock = nullptr);
  std::size_t cameraCount() const override { return cameras_.size(); }
  /// The earliest next ready time over the cameras, s; nullopt once every camera has ended.
  std::optional<core::Timestamp> nextReadyTime() const override;
  /// The next frame of the camera ready first (nullopt: that camera lost it). Throws
  /// core::InvalidInput naming the camera and its source when a frame is not a colour image of
  /// the camera's calibrated size.
  std::optional<Frame> grab() override;
  /// Frames delivered over the cameras (a live camera's own count; a file's frames grabbed).
  std::uint64_t delivered() const override;
  /// Frames a live camera delivered but the loop never took (0 for unpaced files).
  std::uint64_t dropped() const override;
  /// Frames handed out more than a frame period after capture (live cameras).
  std::uint64_t queuedLate() const override;
  /// Each camera's source and pacing, "; "-separated.
  std::string describe() const override;
  /// True when a camera runs at its own pace (V4L2, or footage with pace: true).
  bool live() const;
  /// Frames camera i handed out.
  std::uint64_t frames(std::size_t i) const { return cameras_[i].frames; }
  /// Grabs of camera i that lost their frame.
  std::uint64_t lost(std::size_t i) const { return cameras_[i].lost; }
  /// Camera i's source, as describeSource() names it.
  const std::string& sourceName(std::size_t i) const { return cameras_[i].what; }

private:
  struct Camera {
    std::unique_ptr<FrameSource> source;
    std::string name, what;  // the rig's camera name, describeSource()
    unsigned width = 0, height = 0;  // the calibrated image size, px
    std::uint64_t frames = 0, lost = 0;
  };
  std::vector<Camera> cameras_;
  std::size_t last_ = 0;  // the camera grabbed last (V4L2 cameras are taken in turn)
};

}  // namespace viewline::runtime
