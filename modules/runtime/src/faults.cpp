#include "viewline/runtime/faults.h"

#include <algorithm>
#include <cmath>
#include <iterator>
#include <limits>
#include <opencv2/core.hpp>

#include "viewline/core/error.h"

namespace viewline::runtime {

namespace {

constexpr const char* kKindNames[kFaultKinds] = {"freeze",     "stamp_repeat", "stamp_backwards", "blackout",
                                                 "corrupt",    "detect_nan",   "detect_inf",      "detect_outside",
                                                 "detector_throw", "late",     "robot_silent",    "robot_limit_error"};

// The kinds the source decorator acts on (the others act at FaultPlan's injection points).
bool isFrameKind(FaultKind k) {
  return k == FaultKind::Freeze || k == FaultKind::StampRepeat || k == FaultKind::StampBackwards ||
         k == FaultKind::Blackout || k == FaultKind::Corrupt;
}

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
    if (f.kind == FaultKind::Late && !(f.delay_s > 0.0 && std::isfinite(f.delay_s)))
      throw core::InvalidInput(what + ": delay_s must be > 0");
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
    const std::string kind = n.getChoice("kind", std::vector<std::string>(std::begin(kKindNames), std::end(kKindNames)));
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
    if (f.kind == FaultKind::Late) {
      f.delay_s = n.getOr<double>("delay_s", 0.1);
      if (!(f.delay_s > 0.0)) throw core::InvalidInput(n.location("delay_s") + ": must be > 0 s");
    }
    out.push_back(f);
  }
  return out;
}

std::vector<io::ConfigKeyDoc> faultConfigKeys() {
  return {
      {"faults", "", "injected camera faults (absent: none); runtime/faults.h"},
      {"faults[].kind", "",
       "freeze, stamp_repeat, stamp_backwards, blackout, corrupt, detect_nan, detect_inf, detect_outside, "
       "detector_throw, late, robot_silent or robot_limit_error"},
      {"faults[].camera", "", "the camera index it hits (absent: every camera; robot faults: ignored)"},
      {"faults[].from_s", "s", "start of the window of capture times (robot faults: command times)"},
      {"faults[].to_s", "s", "end of the window (excluded)"},
      {"faults[].step_s", "s", "stamp_backwards: how far before the previous stamp", "0.01"},
      {"faults[].delay_s", "s", "late: delivery after the frame is ready", "0.1"},
      {"frame_deadline_s", "s", "with a late fault: a frame delivered later than this is dropped", "0.05"},
  };
}

std::string faultConfigProbe() {
  return "faults:\n"
         "  - {kind: stamp_backwards, camera: 0, from_s: 0.1, to_s: 0.2, step_s: 0.01}\n"
         "  - {kind: late, from_s: 0.1, to_s: 0.2, delay_s: 0.1}\n"
         "frame_deadline_s: 0.05\n";
}

FaultConfig readFaultPlanConfig(const io::ConfigNode& root) {
  FaultConfig c;
  c.faults = readFaultConfig(root);
  const bool late = std::any_of(c.faults.begin(), c.faults.end(), [](const FaultSpec& f) { return f.kind == FaultKind::Late; });
  if (late) {
    c.frame_deadline_s = root.getOr<double>("frame_deadline_s", c.frame_deadline_s);
    if (!(c.frame_deadline_s > 0.0) || !std::isfinite(c.frame_deadline_s))
      throw core::InvalidInput(root.location("frame_deadline_s") + ": must be > 0 s");
  }
  return c;
}

bool usablePixel(const Eigen::Vector2d& px, int width, int height) {
  return px.allFinite() && px.x() >= -0.5 && px.y() >= -0.5 && px.x() <= width - 0.5 && px.y() <= height - 0.5;
}

void FaultReport::add(const FaultReport& other) {
  for (const auto& [k, n] : other.injected) injected[k] += n;
  for (const auto& [k, n] : other.outcome) outcome[k] += n;
}

std::uint64_t FaultReport::of(FaultKind kind) const {
  const auto it = injected.find(toString(kind));
  return it == injected.end() ? 0 : it->second;
}

std::uint64_t FaultReport::outcomeOf(const std::string& name) const {
  const auto it = outcome.find(name);
  return it == outcome.end() ? 0 : it->second;
}

nlohmann::json toJson(const FaultReport& r) {
  nlohmann::json j;
  j["injected"] = nlohmann::json::object();
  j["outcome"] = nlohmann::json::object();
  for (const auto& [k, n] : r.injected) j["injected"][k] = n;
  for (const auto& [k, n] : r.outcome) j["outcome"][k] = n;
  return j;
}

std::string summaryLine(const FaultReport& r) {
  std::string s = "faults injected:";
  const auto list = [&s](const std::map<std::string, std::uint64_t>& m) {
    bool first = true;
    for (const auto& [k, n] : m) {
      s += (first ? " " : ", ") + k + " " + std::to_string(n);
      first = false;
    }
    if (m.empty()) s += " none";
  };
  list(r.injected);
  s += "; outcome:";
  list(r.outcome);
  return s;
}

FaultPlan::FaultPlan(FaultConfig config, std::uint64_t seed) : cfg_(std::move(config)), seed_(seed) {
  for (std::size_t i = 0; i < cfg_.faults.size(); ++i) {
    const FaultSpec& f = cfg_.faults[i];
    if (!std::isfinite(f.from_s) || !std::isfinite(f.to_s) || f.from_s < 0.0 || !(f.to_s > f.from_s))
      throw core::InvalidInput("faults[" + std::to_string(i) + "] (" + toString(f.kind) +
                               "): the window needs 0 <= from_s < to_s");
  }
  if (!(cfg_.frame_deadline_s > 0.0)) throw core::InvalidInput("frame_deadline_s: must be > 0 s");
}

FrameSource& FaultPlan::wrap(FrameSource& inner) {
  std::vector<FaultSpec> frame_faults;
  for (const FaultSpec& f : cfg_.faults)
    if (isFrameKind(f.kind)) frame_faults.push_back(f);
  if (frame_faults.empty()) return inner;
  source_ = std::make_unique<FaultInjectingSource>(inner, std::move(frame_faults), core::deriveSeed(seed_, 0xFA17));
  return *source_;
}

const FaultSpec* FaultPlan::activeOf(FaultKind kind, std::optional<std::size_t> camera, core::Timestamp t) const {
  for (const FaultSpec& f : cfg_.faults) {
    if (f.kind != kind || t < f.from_s || t >= f.to_s) continue;
    if (f.camera && camera && *f.camera != *camera) continue;
    return &f;
  }
  return nullptr;
}

void FaultPlan::beforeDetect(std::size_t camera, core::Timestamp capture_time) {
  if (cfg_.faults.empty() || !activeOf(FaultKind::DetectorThrow, camera, capture_time)) return;
  count(FaultKind::DetectorThrow);
  throw InjectedFault(FaultKind::DetectorThrow, "injected fault: detector of camera " + std::to_string(camera) +
                                                    " throws at " + std::to_string(capture_time) + " s");
}

Eigen::Vector2d FaultPlan::detected(std::size_t camera, core::Timestamp capture_time, const Eigen::Vector2d& px,
                                    int width, int height) {
  if (cfg_.faults.empty()) return px;
  if (activeOf(FaultKind::DetectNan, camera, capture_time)) {
    count(FaultKind::DetectNan);
    return Eigen::Vector2d::Constant(std::numeric_limits<double>::quiet_NaN());
  }
  if (activeOf(FaultKind::DetectInf, camera, capture_time)) {
    count(FaultKind::DetectInf);
    return Eigen::Vector2d(std::numeric_limits<double>::infinity(), px.y());
  }
  if (activeOf(FaultKind::DetectOutside, camera, capture_time)) {
    count(FaultKind::DetectOutside);
    // Half an image beyond the right and bottom edges: outside whatever margin a consumer allows.
    return Eigen::Vector2d(1.5 * width, 1.5 * height);
  }
  return px;
}

bool FaultPlan::missesDeadline(const Frame& frame) {
  if (cfg_.faults.empty()) return false;
  const FaultSpec* f = activeOf(FaultKind::Late, frame.camera, frame.capture_time);
  if (!f) return false;
  count(FaultKind::Late);
  return f->delay_s > cfg_.frame_deadline_s;
}

void FaultPlan::beforeCommand(core::Timestamp t) {
  if (cfg_.faults.empty()) return;
  for (const FaultKind k : {FaultKind::RobotSilent, FaultKind::RobotLimitError}) {
    if (!activeOf(k, std::nullopt, t)) continue;
    count(k);
    throw InjectedFault(k, std::string("injected fault: robot ") +
                               (k == FaultKind::RobotSilent ? "does not answer" : "reports a limit error") + " at " +
                               std::to_string(t) + " s");
  }
}

void FaultPlan::note(const std::string& outcome, std::uint64_t n) { outcome_[outcome] += n; }

FaultReport FaultPlan::report() const {
  FaultReport r;
  for (const FaultSpec& f : cfg_.faults) {
    const auto k = static_cast<std::size_t>(f.kind);
    const std::uint64_t n = isFrameKind(f.kind) ? (source_ ? source_->counters().frames[k] : 0) : counts_[k];
    r.injected[toString(f.kind)] = n;
  }
  r.outcome = outcome_;
  return r;
}

}  // namespace viewline::runtime
