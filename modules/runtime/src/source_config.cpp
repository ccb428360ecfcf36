#include "viewline/runtime/source_config.h"

#include "viewline/core/error.h"
#include "viewline/runtime/recording.h"

namespace viewline::runtime {

const char* toString(SourceKind kind) {
  switch (kind) {
    case SourceKind::Sim: return "sim";
    case SourceKind::Images: return "images";
    case SourceKind::Video: return "video";
    case SourceKind::V4l2: return "v4l2";
    case SourceKind::Recording: return "recording";
  }
  return "?";
}

SourceConfig readSourceConfig(const io::ConfigNode& root) {
  SourceConfig c;
  if (!root.has("source")) return c;
  const io::ConfigNode s = root.child("source");
  const std::string kind = s.getChoiceOr("kind", {"sim", "images", "video", "v4l2", "recording"}, "sim");
  if (kind == "images") {
    c.kind = SourceKind::Images;
    c.images.pattern = s.getPath("pattern");
    c.images.first = s.getOr<long long>("first", 0);
    if (s.has("stamps")) c.images.stamps_file = s.getPath("stamps");
    c.images.rate = s.getOr<double>("rate_hz", 30.0);
    if (!(c.images.rate > 0.0)) throw core::InvalidInput(s.location("rate_hz") + ": must be > 0 Hz");
    c.images.count = s.getOr<long long>("count", -1);
    c.pace = s.getOr<bool>("pace", false);
    formatFramePattern(c.images.pattern, c.images.first);  // checks the pattern now
  } else if (kind == "video") {
    c.kind = SourceKind::Video;
    c.video.path = s.getPath("path");
    if (s.has("stamps")) c.video.stamps_file = s.getPath("stamps");
    c.video.count = s.getOr<long long>("count", -1);
    c.pace = s.getOr<bool>("pace", false);
  } else if (kind == "v4l2") {
    c.kind = SourceKind::V4l2;
    c.v4l2.device = s.getOr<std::string>("device", "/dev/video0");
    c.v4l2.width = s.getOr<int>("width", 0);
    c.v4l2.height = s.getOr<int>("height", 0);
    c.v4l2.rate = s.getOr<double>("rate_hz", 0.0);
    c.v4l2.exposure = s.getOr<double>("exposure", -1.0);
    c.v4l2.count = s.getOr<long long>("count", -1);
    if (c.v4l2.width < 0 || c.v4l2.height < 0 || c.v4l2.rate < 0.0)
      throw core::InvalidInput(s.location() + ": width, height and rate_hz must be >= 0 (0: the driver's)");
  } else if (kind == "recording") {
    c.kind = SourceKind::Recording;
    c.recording = s.getPath("path");
  }
  return c;
}

std::unique_ptr<FrameSource> makeFrameSource(const SourceConfig& c, WallClock* clock) {
  switch (c.kind) {
    case SourceKind::Images: {
      auto images = std::make_unique<ImageSequenceSource>(c.images);
      if (!c.pace) return images;
      return std::make_unique<PacedSource>(std::move(images), 1.0, "images " + c.images.pattern, clock);
    }
    case SourceKind::Video: {
      auto video = std::make_unique<VideoSource>(c.video);
      if (!c.pace) return video;
      return std::make_unique<PacedSource>(std::move(video), 1.0, "video " + c.video.path, clock);
    }
    case SourceKind::V4l2: return std::make_unique<V4l2Source>(c.v4l2);
    case SourceKind::Recording: return std::make_unique<RecordingSource>(c.recording);
    case SourceKind::Sim: break;
  }
  throw core::InvalidInput("makeFrameSource: kind sim is the scenario's own renderer");
}

std::vector<io::ConfigKeyDoc> sourceConfigKeys() {
  return {
      {"source", "", "where the frames come from (absent: the simulator)"},
      {"source.kind", "", "sim (the scenario's renderer), images, video, v4l2 or recording"},
      {"source.pattern", "", "images: printf pattern of the files, one integer conversion (image.%04d.pgm)"},
      {"source.first", "", "images: index of the first file"},
      {"source.stamps", "", "images, video: CSV of `index,stamp` lines (s); absent: rate_hz (images), the container's times (video)"},
      {"source.rate_hz", "Hz", "images: frame rate without a stamps file; v4l2: requested rate (0: the driver's)",
       "images 30, v4l2 0"},
      {"source.count", "", "images, video, v4l2: at most this many frames (-1: all)"},
      {"source.pace", "", "images, video: play the footage as a live camera at its stamps' rate (frames the loop is too busy "
                          "for are dropped and counted; the summary reports processing times and deadline misses)",
       "false"},
      {"source.path", "", "video: the file; recording: the folder written by --record"},
      {"source.device", "", "v4l2: the device node"},
      {"source.width", "px", "v4l2: requested width (0: the driver's)"},
      {"source.height", "px", "v4l2: requested height (0: the driver's)"},
      {"source.exposure", "100 µs", "v4l2: manual exposure (V4L2 exposure_absolute units; -1: the driver's setting)"},
  };
}

std::vector<std::string> sourceConfigProbes(const std::string& prefix) {
  return {prefix + "source: {kind: images, pattern: seq/image.%04d.pgm, first: 1, rate_hz: 25, stamps: s.csv, count: 10, pace: true}\n",
          prefix + "source: {kind: video, path: run.mp4, stamps: s.csv, count: 10, pace: true}\n",
          prefix + "source: {kind: v4l2, device: /dev/video0, width: 640, height: 480, rate_hz: 30, exposure: 100, count: 5}\n",
          prefix + "source: {kind: recording, path: rec}\n"};
}

}  // namespace viewline::runtime
