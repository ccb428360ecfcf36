#include "viewline/nodes/simulation.h"

#include <cstring>

#include "viewline/scenarios/ball_catching/world.h"

namespace viewline::nodes {

namespace {

struct Fnv1a {
  std::uint64_t h = 14695981039346656037ULL;
  void bytes(const void* p, std::size_t n) {
    const auto* b = static_cast<const unsigned char*>(p);
    for (std::size_t i = 0; i < n; ++i) h = (h ^ b[i]) * 1099511628211ULL;
  }
  void number(double x) { bytes(&x, sizeof x); }
};

}  // namespace

std::uint64_t rigHash(const scenarios::BallCatchingConfig& cfg) {
  Fnv1a f;
  for (std::size_t i = 0; i < cfg.activeCameras(); ++i) {
    const core::Camera c = cfg.cameras[i].estimatorCamera();
    f.bytes(c.name.data(), c.name.size());
    f.number(c.width);
    f.number(c.height);
    for (double x : {c.intrinsics.get_px(), c.intrinsics.get_py(), c.intrinsics.get_u0(), c.intrinsics.get_v0(),
                     c.intrinsics.get_kud(), c.intrinsics.get_kdu()})
      f.number(x);
    const Eigen::Matrix4d M = c.c_M_w.matrix();
    for (int k = 0; k < 16; ++k) f.number(M(k));
  }
  return f.h;
}

namespace {

sim::DragFlight throwFlight(const scenarios::BallCatchingConfig& cfg, std::uint64_t seed, int index) {
  // runThrow's first draws: its Rng seeded with deriveSeed(seed, index), the throw drawn first.
  core::Rng rng = core::makeRng(core::deriveSeed(seed, static_cast<std::uint64_t>(index)));
  const scenarios::ThrowDraw d = scenarios::drawThrow(cfg, rng);
  return sim::DragFlight({d.release, d.launch_velocity}, 0.0, d.flight_time + cfg.post_crossing_s + 0.3,
                         cfg.throws.body);
}

}  // namespace

WorldTruth::WorldTruth(const scenarios::BallCatchingConfig& cfg, std::uint64_t seed, double release_time, int index)
    : release_(release_time), flight_(throwFlight(cfg, seed, index)),
      t_cross_(release_time + scenarios::crossingTime(flight_, cfg.robot.home, cfg.box_normal)),
      t_end_(t_cross_ + cfg.post_crossing_s) {}

DetectionGenerator::DetectionGenerator(const scenarios::BallCatchingConfig& cfg, std::size_t index,
                                       std::uint64_t seed, double sigma_px, double clock_offset_s)
    : camera_(cfg.cameras.at(index).renderCamera()), index_(index), seed_(seed),
      period_((1.0 + cfg.cameras[index].drift) / cfg.throwRate(index)), sigma_(sigma_px), offset_(clock_offset_s) {
  core::Rng rng = core::makeRng(core::deriveSeed(seed, 0x100 + index));
  next_ = core::uniform(rng, 0.0, period_);
}

std::optional<GeneratedFrame> DetectionGenerator::onTick(core::Timestamp t,
                                                         const std::optional<Eigen::Vector3d>& p_true) {
  if (t < next_) return std::nullopt;
  while (next_ <= t) next_ += period_;  // a tick later than one period: the missed captures are skipped
  GeneratedFrame f;
  f.frame_number = frames_++;
  f.stamp = t + offset_;
  f.sigma_px = sigma_;
  if (!p_true) return f;
  const std::optional<Eigen::Vector2d> uv = camera_.project(*p_true);
  if (!uv || !camera_.inImage(*uv)) return f;
  // The noise of frame k has its own stream: it does not depend on which other frames were taken.
  core::Rng rng = core::makeRng(core::deriveSeed(core::deriveSeed(seed_, 0x200 + index_), f.frame_number));
  f.pixel = *uv + sigma_ * Eigen::Vector2d(core::gaussian(rng), core::gaussian(rng));
  return f;
}

}  // namespace viewline::nodes
