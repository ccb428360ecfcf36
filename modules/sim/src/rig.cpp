#include "viewline/sim/rig.h"

#include <algorithm>
#include <cmath>
#include <sstream>

#include "viewline/core/checks.h"
#include "viewline/core/frames.h"

namespace viewline::sim {

using core::InvalidInput;

const ObjectTruth* Frame::find(const std::string& name) const {
  for (const auto& t : truth) {
    if (t.name == name) return &t;
  }
  return nullptr;
}

CameraRig::CameraRig(std::vector<SimCamera> cameras, core::Rng& rng, const RenderSettings& render)
    : cameras_(std::move(cameras)), seed_(rng()), renderer_(render) {
  if (cameras_.empty()) throw InvalidInput("CameraRig: no cameras");
  for (std::size_t i = 0; i < cameras_.size(); ++i) {
    const SimCamera& c = cameras_[i];
    const std::string who = "CameraRig: camera " + std::to_string(i) + " ('" + c.camera.name + "') ";
    core::requirePositive(c.clock.rate, who + "clock.rate");
    core::requireFinite(c.clock.phase, who + "clock.phase");
    if (c.clock.phase < 0.0) throw InvalidInput(who + "clock.phase must be >= 0");
    core::requireFinite(c.clock.drift, who + "clock.drift");
    if (c.clock.drift <= -1.0) throw InvalidInput(who + "clock.drift must be > -1");
    if (c.camera.width == 0 || c.camera.height == 0) throw InvalidInput(who + "width/height must be > 0");
    try {
      validate(c.effects);
    } catch (const InvalidInput& e) {
      throw InvalidInput(who + e.what());
    }
    core::Rng pool_rng = core::makeRng(core::deriveSeed(seed_, 3 * i + 2));
    noise_.emplace_back(c.effects.noise, pool_rng);
  }
  reset(0.0);
}

void CameraRig::reset(double t_start) {
  core::requireFinite(t_start, "CameraRig::reset: t_start");
  t_start_ = t_start;
  streams_.clear();
  dropped_.assign(cameras_.size(), 0);
  for (std::size_t i = 0; i < cameras_.size(); ++i) {
    Stream s{core::makeRng(core::deriveSeed(seed_, 3 * i)), core::makeRng(core::deriveSeed(seed_, 3 * i + 1)), 0, {}};
    streams_.push_back(std::move(s));
    scheduleNext(i);
  }
}

void CameraRig::scheduleNext(std::size_t i) {
  Stream& s = streams_[i];
  const CameraClock& c = cameras_[i].clock;
  const FrameFaults& f = cameras_[i].effects.faults;
  const double period = (1.0 + c.drift) / c.rate;
  // Always three draws per frame, so each fault's stream does not depend on the others' settings.
  const double e_trigger = core::gaussian(s.clock_rng, 1.0);
  const double e_stamp = core::gaussian(s.clock_rng, 1.0);
  const double u_drop = core::uniform(s.clock_rng, 0.0, 1.0);
  const double jitter = std::clamp(f.trigger_jitter * e_trigger, -0.45 * period, 0.45 * period);
  s.next.camera_index = i;
  s.next.sequence = s.k;
  s.next.capture_time = t_start_ + c.phase + static_cast<double>(s.k) * period + jitter;
  s.next.stamp = s.next.capture_time + f.stamp_jitter * e_stamp;
  s.next.dropped = u_drop < f.drop_probability;
  ++s.k;
}

std::size_t CameraRig::nextIndex() const {
  std::size_t best = 0;
  for (std::size_t i = 1; i < streams_.size(); ++i) {
    if (streams_[i].next.capture_time < streams_[best].next.capture_time) best = i;
  }
  return best;
}

const Capture& CameraRig::peek() const { return streams_[nextIndex()].next; }

std::optional<Frame> CameraRig::captureNext(const World& world) {
  const std::size_t i = nextIndex();
  const Capture cap = streams_[i].next;
  scheduleNext(i);
  if (cap.dropped) {
    ++dropped_[i];
    return std::nullopt;
  }
  const SimCamera& sc = cameras_[i];
  Stream& s = streams_[i];
  Frame frame;
  frame.camera_index = i;
  frame.camera_name = sc.camera.name;
  frame.sequence = cap.sequence;
  frame.stamp = cap.stamp;
  frame.capture_time = cap.capture_time;
  frame.camera = sc.camera;
  if (sc.pose_at) {
    frame.camera.c_M_w = sc.pose_at(cap.capture_time);
    core::requireFinite(frame.camera.c_M_w.matrix(), "CameraRig: pose_at of camera '" + sc.camera.name + "'");
  }
  const ImagingEffects& fx = sc.effects;
  const double direction = fx.occlusion.random_direction ? core::uniform(s.effect_rng, -core::kPi, core::kPi)
                                                         : fx.occlusion.direction;
  std::vector<Primitive> extra;
  if (fx.occlusion.fraction > 0.0) {
    std::vector<Primitive> objs;
    world.dynamicObjects(cap.capture_time, objs);
    for (const auto& o : world.staticScene().primitives) objs.push_back(o);
    for (const auto& o : objs) {
      if (o.name != fx.occlusion.target) continue;
      if (auto occ = makeOccluder(describe(o, frame.camera), frame.camera, fx.occlusion, direction)) {
        extra.push_back(*occ);
      }
      break;
    }
  }
  ExposureSpec exposure;
  exposure.time = cap.capture_time;
  exposure.duration = fx.blur.exposure;
  exposure.blur_samples = fx.blur.samples;
  frame.image = renderer_.render(world, frame.camera, exposure, &frame.truth, extra);
  noise_[i].applyWithGain(frame.image, illuminationGain(fx.illumination, cap.capture_time), s.effect_rng);
  return frame;
}

std::size_t CameraRig::run(const World& world, double t0, double t1, const std::function<void(Frame&&)>& sink) {
  core::requireFinite(t0, "CameraRig::run: t0");
  core::requireFinite(t1, "CameraRig::run: t1");
  if (t1 < t0) throw InvalidInput("CameraRig::run: t1 < t0");
  reset(t0);
  std::size_t delivered = 0;
  while (peek().capture_time < t1) {
    if (auto f = captureNext(world)) {
      ++delivered;
      sink(std::move(*f));
    }
  }
  return delivered;
}

std::vector<Capture> CameraRig::schedule(double t0, double t1) {
  core::requireFinite(t0, "CameraRig::schedule: t0");
  core::requireFinite(t1, "CameraRig::schedule: t1");
  reset(t0);
  std::vector<Capture> out;
  while (peek().capture_time < t1) {
    const std::size_t i = nextIndex();
    out.push_back(streams_[i].next);
    scheduleNext(i);
  }
  reset(t0);
  return out;
}

}  // namespace viewline::sim
