#pragma once
// The `source:` block of a scenario config: where the frames come from.
//
//   source: {kind: sim}                                            # the default: the scenario renders its own
//   source: {kind: images, pattern: seq/image.%04d.pgm, first: 1, rate_hz: 25}   # or stamps: seq/stamps.csv
//   source: {kind: video, path: run.mp4}                           # stamps from the container, or stamps: FILE
//   source: {kind: video, path: run.mp4, pace: true}               # played as a live camera (live.h)
//   source: {kind: v4l2, device: /dev/video0, width: 640, height: 480, rate_hz: 30, exposure: 100}
//   source: {kind: recording, path: rec/}                          # a folder written by --record
//
// Only the keys of the chosen kind are read, so a key of another kind is refused as unknown
// (io::ConfigNode::finish). Paths are resolved against the config file's folder. Reading the
// block opens nothing: makeFrameSource() does, and names the file or device when it fails.

#include <cstdint>
#include <memory>
#include <string>
#include <vector>

#include "viewline/io/config.h"
#include "viewline/io/config_reference.h"
#include "viewline/runtime/file_sources.h"
#include "viewline/runtime/frame_source.h"
#include "viewline/runtime/live.h"
#include "viewline/runtime/v4l2_source.h"

namespace viewline::runtime {

/// Which kind of frame source a scenario runs on.
enum class SourceKind {
  Sim,        ///< the scenario's own renderer (simulated world, with truth)
  Images,     ///< an image sequence (ImageSequenceSource)
  Video,      ///< a video file (VideoSource)
  V4l2,       ///< a live V4L2 camera (V4l2Source)
  Recording,  ///< a viewline recording folder (RecordingSource)
};

/// "sim", "images", "video", "v4l2", "recording".
const char* toString(SourceKind kind);

/// The `source:` block, read and checked (files are not opened).
struct SourceConfig {
  SourceKind kind = SourceKind::Sim;  ///< which source
  ImageSequenceOptions images;        ///< kind images
  VideoOptions video;                 ///< kind video
  V4l2Options v4l2;                   ///< kind v4l2
  std::string recording;              ///< kind recording: the folder
  /// Kinds images and video: play the footage on the wall clock as a live camera at its stamps'
  /// rate (runtime::PacedSource: frames the loop is too busy to take are dropped and counted).
  bool pace = false;
  /// True when the source runs at its own pace, not the loop's: a V4L2 camera, or paced footage.
  bool live() const { return kind == SourceKind::V4l2 || pace; }
  /// True for the simulator (the scenario renders and knows the truth).
  bool simulated() const { return kind == SourceKind::Sim; }
};

/// Reads `source:` from a scenario's root (absent: kind sim); throws core::InvalidInput naming
/// file:line and key on a bad kind or value.
SourceConfig readSourceConfig(const io::ConfigNode& root);

/// Opens the source of a non-sim config; throws core::InvalidInput naming the file or device
/// (kind sim: the scenario builds its renderer itself, and this throws). A live() config gives a
/// LiveFrameSource (paced footage on `clock`, null: steadyWallClock()).
std::unique_ptr<FrameSource> makeFrameSource(const SourceConfig& config, WallClock* clock = nullptr);

/// The key table of the `source:` block (for a scenario's config_keys.cpp).
std::vector<io::ConfigKeyDoc> sourceConfigKeys();
/// YAML probes that read every `source:` key (one per kind), each `prefix` + a source block.
std::vector<std::string> sourceConfigProbes(const std::string& prefix);

}  // namespace viewline::runtime
