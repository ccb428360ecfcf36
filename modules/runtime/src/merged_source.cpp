#include "viewline/runtime/merged_source.h"

#include <limits>

#include "viewline/core/error.h"
#include "viewline/runtime/v4l2_source.h"

namespace viewline::runtime {

std::string describeSource(const SourceConfig& s) {
  switch (s.kind) {
    case SourceKind::Images: return "images " + s.images.pattern;
    case SourceKind::Video: return "video " + s.video.path;
    case SourceKind::V4l2: return "v4l2 " + s.v4l2.device;
    case SourceKind::Recording: return "recording " + s.recording;
    case SourceKind::Sim: break;
  }
  return "sim";
}

SingleCameraFootage openSingleCameraFootage(const SourceConfig& config, WallClock* clock, const std::string& role) {
  const std::string name = describeSource(config);
  SingleCameraFootage f;
  try {
    f.source = makeFrameSource(config, clock);
  } catch (const core::InvalidInput& e) {
    throw core::InvalidInput(std::string("source: ") + e.what());
  }
  if (f.source->cameraCount() != 1)
    throw core::InvalidInput("source: " + name + " holds " + std::to_string(f.source->cameraCount()) +
                             " cameras, expected one (" + role + ")");
  const std::optional<core::Timestamp> first = f.source->nextReadyTime();
  if (!first) throw core::InvalidInput("source: " + name + ": the footage holds no frame");
  f.t0 = *first;
  f.live = dynamic_cast<LiveFrameSource*>(f.source.get());
  return f;
}

MergedFrameSource::MergedFrameSource(const std::vector<MergedCamera>& cameras, WallClock* clock) {
  for (const MergedCamera& c : cameras) {
    if (c.source.simulated() || c.source.kind == SourceKind::Recording)
      throw core::InvalidInput("cameras[" + c.name + "].source: expected footage (images, video or v4l2), got " +
                               toString(c.source.kind));
    Camera k;
    k.name = c.name;
    k.what = describeSource(c.source);
    k.width = c.width;
    k.height = c.height;
    try {
      k.source = makeFrameSource(c.source, clock);
    } catch (const core::InvalidInput& e) {
      throw core::InvalidInput("cameras[" + c.name + "].source: " + e.what());
    }
    if (k.source->cameraCount() != 1)
      throw core::InvalidInput("cameras[" + c.name + "].source: " + k.what + " holds " +
                               std::to_string(k.source->cameraCount()) + " cameras, expected one");
    cameras_.push_back(std::move(k));
  }
}

std::optional<core::Timestamp> MergedFrameSource::nextReadyTime() const {
  std::optional<core::Timestamp> t;
  for (const Camera& c : cameras_)
    if (const auto r = c.source->nextReadyTime(); r && (!t || *r < *t)) t = r;
  return t;
}

std::optional<Frame> MergedFrameSource::grab() {
  std::size_t best = cameras_.size();
  core::Timestamp t = std::numeric_limits<double>::infinity();
  // A V4L2 camera is always ready "now" (its grab waits for the driver's next frame), so the
  // earliest ready time would always be the first camera's: V4L2 cameras are taken in turn,
  // starting after the one grabbed last; footage goes by its stamps.
  for (std::size_t k = 0; k < cameras_.size(); ++k) {
    const std::size_t i = (last_ + 1 + k) % cameras_.size();
    const auto r = cameras_[i].source->nextReadyTime();
    if (!r) continue;
    if (dynamic_cast<const V4l2Source*>(cameras_[i].source.get())) {
      best = i;
      break;
    }
    if (*r < t || (*r == t && i < best)) {
      t = *r;
      best = i;
    }
  }
  if (best == cameras_.size()) return std::nullopt;
  last_ = best;
  Camera& c = cameras_[best];
  std::optional<Frame> f = c.source->grab();
  if (!f) {
    ++c.lost;
    return f;
  }
  if (f->image.type() != CV_8UC3)
    throw core::InvalidInput("cameras[" + c.name + "].source: " + c.what + ": frame " + std::to_string(f->sequence) +
                             " is not a colour (8-bit BGR) image: the ball detector segments colour");
  if (static_cast<unsigned>(f->image.cols) != c.width || static_cast<unsigned>(f->image.rows) != c.height)
    throw core::InvalidInput("cameras[" + c.name + "].source: " + c.what + ": frame " + std::to_string(f->sequence) +
                             " is " + std::to_string(f->image.cols) + "x" + std::to_string(f->image.rows) +
                             " px, the camera's calibration is " + std::to_string(c.width) + "x" +
                             std::to_string(c.height) + " px");
  f->camera = best;
  ++c.frames;
  return f;
}

bool MergedFrameSource::live() const {
  for (const Camera& c : cameras_)
    if (dynamic_cast<const LiveFrameSource*>(c.source.get())) return true;
  return false;
}

std::uint64_t MergedFrameSource::delivered() const {
  std::uint64_t n = 0;
  for (const Camera& c : cameras_) {
    const auto* l = dynamic_cast<const LiveFrameSource*>(c.source.get());
    n += l ? l->delivered() : c.frames + c.lost;
  }
  return n;
}

std::uint64_t MergedFrameSource::dropped() const {
  std::uint64_t n = 0;
  for (const Camera& c : cameras_)
    if (const auto* l = dynamic_cast<const LiveFrameSource*>(c.source.get())) n += l->dropped();
  return n;
}

std::uint64_t MergedFrameSource::queuedLate() const {
  std::uint64_t n = 0;
  for (const Camera& c : cameras_)
    if (const auto* l = dynamic_cast<const LiveFrameSource*>(c.source.get())) n += l->queuedLate();
  return n;
}

std::string MergedFrameSource::describe() const {
  std::string s;
  for (const Camera& c : cameras_) {
    if (!s.empty()) s += "; ";
    const auto* l = dynamic_cast<const LiveFrameSource*>(c.source.get());
    s += c.name + ": " + (l ? l->describe() : c.what);
  }
  return s;
}

}  // namespace viewline::runtime
