#include "viewline/runtime/faults.h"

#include <cmath>
#include <opencv2/core.hpp>

#include "viewline/core/error.h"

namespace viewline::runtime {

namespace {

constexpr const char* kKindNames[kFaultKinds] = {"freeze", "stamp_repeat", "stamp_backwards", "blackout", "corrupt"};

bool active(const FaultSpec& f, const Frame& frame) {
  return (!f.camera || *f.camera == frame.camera) && frame.capture_time >= f.from_s && frame.capture_time < f.to_s;
}

}  // namespace

const char* toString(FaultKind kind) { return kKindNames[static_cast<std::size_t>(kind)]; }

FaultInjectingSource::FaultInjectingSource(FrameSource& inner, std::vector<FaultSpec> faults, std::uint64_t seed)
    : inner_(inner), faults_(std::move(faults)), rng_(core::makeRng(seed)), memory_(inner.cameraCount()) {
  for (std::size_t i = 0; i < faults_.size(); ++i) {
    const FaultSpec& f = faults_[i];
    const std::string what = "faults[" + std::to_string(i) + "] (" + toString(f.kind) + ")";
    if (!std::isfinite(f.from_s) || !std::isfinite(f.to_s) || f.from_s < 0.0 || !(f.to_s > f.from_s))
      throw core::InvalidInput(what + ": the window needs 0 <= from_s < to_s (got " + std::to_string(f.from_s) + ", " +
                               std::to_string(f.to_s) + ")");
    if (f.kind == FaultKind::StampBackwards && !(f.step_s > 0.0 && std::isfinite(f.step_s)))
      throw core::InvalidInput(what + ": step_s must be > 0");
    freezes_ = freezes_ || f.kind == FaultKind::Freeze;
    if (f.camera && *f.camera >= inner_.cameraCount())
      throw core::InvalidInput(what + ": camera " + std::to_string(*f.camera) + " but the source has " +
                               std::to_string(inner_.cameraCount()) + " cameras");
  }
}

std::optional<Frame> FaultInjectingSource::grab() {
  std::optional<Frame> frame = inner_.grab();
  if (!frame) return frame;
  if (frame->camera >= memory_.size()) memory_.resize(frame->camera + 1);  // a source that grew
  CameraMemory& mem = memory_[frame->camera];
  bool touched = false;
  auto count = [&](FaultKind k) {
    ++counters_.frames[static_cast<std::size_t>(k)];
    touched = true;
  };
  // Order: a lost frame is lost whatever else applies; the image faults, then the stamp faults
  // (which act on the stamp of the previous frame handed out).
  for (const FaultSpec& f : faults_) {
    if (f.kind != FaultKind::Blackout || !active(f, *frame)) continue;
    count(FaultKind::Blackout);
    ++counters_.touched;
    return std::nullopt;
  }
  bool image_faulted = false;
  for (const FaultSpec& f : faults_) {
    if (!active(f, *frame)) continue;
    if (f.kind == FaultKind::Freeze && !mem.last_good.empty()) {
      frame->image = mem.last_good.clone();
      image_faulted = true;
      count(FaultKind::Freeze);
    } else if (f.kind == FaultKind::Corrupt) {
      cv::Mat noise(frame->image.size(), frame->image.type());
      cv::theRNG().state = rng_();  // seeded: the same garbage on every run
      cv::randu(noise, cv::Scalar::all(0), cv::Scalar::all(256));
      frame->image = noise;
      image_faulted = true;
      count(FaultKind::Corrupt);
    }
  }
  for (const FaultSpec& f : faults_) {
    if (!active(f, *frame) || !mem.last_stamp) continue;
    if (f.kind == FaultKind::StampRepeat) {
      frame->stamp = *mem.last_stamp;
      count(FaultKind::StampRepeat);
    } else if (f.kind == FaultKind::StampBackwards) {
      frame->stamp = *mem.last_stamp - f.step_s;
      count(FaultKind::StampBackwards);
    }
  }
  // A copy: a source may hand out the same buffer again (a driver's ring of buffers).
  if (!image_faulted && freezes_) mem.last_good = frame->image.clone();
  mem.last_stamp = frame->stamp;
  if (touched) ++counters_.touched;
  return frame;
}

std::vector<FaultSpec> readFaultConfig(const io::ConfigNode& root) {
  std::vector<FaultSpec> out;
  if (!root.has("faults")) return out;
  for (const io::ConfigNode& n : root.childList("faults")) {
    FaultSpec f;
    const std::string kind = n.getChoice("kind", {kKindNames[0], kKindNames[1], kKindNames[2], kKindNames[3], kKindNames[4]});
    for (std::size_t k = 0; k < kFaultKinds; ++k)
      if (kind == kKindNames[k]) f.kind = static_cast<FaultKind>(k);
    if (n.has("camera")) {
      const int c = n.get<int>("camera");
      if (c < 0) throw core::InvalidInput(n.location("camera") + ": must be >= 0");
      f.camera = static_cast<std::size_t>(c);
    }
    f.from_s = n.get<double>("from_s");
    f.to_s = n.get<double>("to_s");
    if (!(f.from_s >= 0.0) || !(f.to_s > f.from_s))
      throw core::InvalidInput(n.location("to_s") + ": the window needs 0 <= from_s < to_s");
    if (f.kind == FaultKind::StampBackwards) {
      f.step_s = n.getOr<double>("step_s", 0.01);
      if (!(f.step_s > 0.0)) throw core::InvalidInput(n.location("step_s") + ": must be > 0 s");
    }
    out.push_back(f);
  }
  return out;
}

std::vector<io::ConfigKeyDoc> faultConfigKeys() {
  return {
      {"faults", "", "injected camera faults (absent: none); runtime/faults.h"},
      {"faults[].kind", "", "freeze, stamp_repeat, stamp_backwards, blackout or corrupt"},
      {"faults[].camera", "", "the camera index it hits (absent: every camera)"},
      {"faults[].from_s", "s", "start of the window of capture times"},
      {"faults[].to_s", "s", "end of the window (excluded)"},
      {"faults[].step_s", "s", "stamp_backwards: how far before the previous stamp", "0.01"},
  };
}

}  // namespace viewline::runtime
