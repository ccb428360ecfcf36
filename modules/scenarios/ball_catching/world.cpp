#include "viewline/scenarios/ball_catching/world.h"

#include <algorithm>
#include <cmath>

#include "viewline/core/checks.h"
#include "viewline/core/error.h"
#include "viewline/core/frames.h"

namespace viewline::scenarios {

namespace {

Eigen::Vector3d endPoint(const Eigen::Vector3d& p0, const Eigen::Vector3d& v0, double T, double k) {
  sim::FlightState s{p0, v0};
  const int n = std::max(1, static_cast<int>(std::ceil(T / 1e-3)));
  const double h = T / n;
  for (int i = 0; i < n; ++i) s = sim::rk4Step(s, h, k, sim::gravityWorld());
  return s.p;
}

}  // namespace

Eigen::Vector3d solveLaunchVelocity(const Eigen::Vector3d& release, const Eigen::Vector3d& aim, double T,
                                    const sim::DragBody& body) {
  core::requirePositive(T, "solveLaunchVelocity: flight time");
  const double k = body.dragPerMass();
  Eigen::Vector3d v = (aim - release - 0.5 * sim::gravityWorld() * T * T) / T;
  for (int it = 0; it < 10; ++it) {
    const Eigen::Vector3d r = endPoint(release, v, T, k) - aim;
    if (r.norm() < 1e-9) break;
    Eigen::Matrix3d J;
    for (int i = 0; i < 3; ++i) {
      Eigen::Vector3d dv = Eigen::Vector3d::Zero();
      dv(i) = 1e-6;
      J.col(i) = (endPoint(release, v + dv, T, k) - aim - r) / 1e-6;
    }
    v -= J.partialPivLu().solve(r);
  }
  return v;
}

ThrowDraw drawThrow(const BallCatchingConfig& cfg, core::Rng& rng) {
  const ThrowDistribution& td = cfg.throws;
  const Eigen::Vector3d& n = cfg.box_normal;
  ThrowDraw d;
  for (int i = 0; i < 3; ++i) d.release(i) = core::uniform(rng, td.release_min(i), td.release_max(i));
  // sqrt of a uniform radius fraction: aim points uniform over the disc's area.
  const double rho = td.aim_radius * std::sqrt(core::uniform(rng, 0.0, 1.0));
  const double phi = core::uniform(rng, 0.0, 2.0 * core::kPi);
  const Eigen::Matrix3d Rb = boxRotation(n);
  d.aim = cfg.robot.home + rho * (std::cos(phi) * Rb.col(0) + std::sin(phi) * Rb.col(1));
  const double speed = core::uniform(rng, td.speed_min, td.speed_max);
  Eigen::Vector3d horizontal = d.aim - d.release;
  horizontal.z() = 0.0;
  d.distance = std::abs(n.dot(d.aim - d.release));
  d.flight_time = horizontal.norm() / speed;
  d.launch_velocity = solveLaunchVelocity(d.release, d.aim, d.flight_time, td.body);
  return d;
}

double crossingTime(const sim::DragFlight& flight, const Eigen::Vector3d& point, const Eigen::Vector3d& n) {
  auto h = [&](double t) { return n.dot(flight.state(t).p - point); };
  double ta = 0.0, tb = -1.0;
  for (double t = 1e-3; t <= flight.endTime(); t += 1e-3) {
    if (h(t) <= 0.0) {
      tb = t;
      break;
    }
    ta = t;
  }
  if (tb < 0.0) throw core::NumericalError("runThrow: the ball never crosses the box plane");
  for (int it = 0; it < 60; ++it) {
    const double m = 0.5 * (ta + tb);
    (h(m) > 0.0 ? ta : tb) = m;
  }
  return 0.5 * (ta + tb);
}

void appendBox(const BallCatchingConfig& cfg, const Eigen::Matrix3d& R, const Eigen::Vector3d& hole,
               std::vector<sim::Primitive>& out) {
  const Eigen::Vector3d& n = cfg.box_normal;
  Eigen::Isometry3d M = Eigen::Isometry3d::Identity();
  M.linear() = R;
  M.translation() = hole - n * (0.5 * cfg.box_size);
  out.push_back(sim::makeBox("box", M, Eigen::Vector3d::Constant(cfg.box_size), Eigen::Vector3d(0.7, 0.72, 0.7)));
  M.translation() = hole + n * 1e-3;  // 1 mm in front of the face: no depth fight with the box
  out.push_back(sim::makeDisc("hole", M, cfg.hole_radius, Eigen::Vector3d(0.04, 0.04, 0.04)));
  if (cfg.registration.enabled)
    out.push_back(sim::makeSphere("marker", hole + cfg.registration.marker_offset, cfg.registration.marker_radius,
                                  cfg.registration.marker_albedo_bgr));
}

void CatchWorld::dynamicObjects(double t, std::vector<sim::Primitive>& out) const {
  if (t >= flight_.startTime() && t <= flight_.endTime()) {
    const sim::FlightState s = flight_.state(t);
    if (cfg_.object == "dart") {
      for (auto& prim : sim::makeDart("dart", sim::dartPose(s.p, s.v), cfg_.ball_albedo_bgr)) out.push_back(prim);
    } else {
      out.push_back(sim::makeSphere("ball", s.p, cfg_.throws.body.reference_radius, cfg_.ball_albedo_bgr));
    }
  }
  if (cfg_.render_box) appendBox(cfg_, R_, robot_.read(t).p, out);
}

std::vector<sim::SimCamera> throwCameras(const BallCatchingConfig& cfg, core::Rng& rng) {
  std::vector<sim::SimCamera> sims;
  for (std::size_t i = 0; i < cfg.activeCameras(); ++i) {
    const CatchCameraConfig& c = cfg.cameras[i];
    sim::SimCamera sc;
    sc.camera = c.renderCamera();
    sc.clock.rate = cfg.throwRate(i);
    sc.clock.phase = core::uniform(rng, 0.0, 1.0 / sc.clock.rate);  // free-running: a new phase every throw
    sc.clock.drift = c.drift;
    sc.effects.noise.sigma = c.noise_sigma;
    sc.effects.blur.exposure = c.exposure_s;
    sc.effects.blur.samples = c.blur_samples;
    sc.effects.faults.drop_probability = c.drop_probability;
    sc.effects.faults.trigger_jitter = c.trigger_jitter_s;
    sc.effects.faults.stamp_jitter = c.stamp_jitter_s;
    sims.push_back(std::move(sc));
  }
  return sims;
}

RigFrameSource::RigFrameSource(std::vector<sim::SimCamera> cameras, core::Rng& rng, const sim::RenderSettings& render,
                               const sim::World& world, double t_end)
    : rig_(std::move(cameras), rng, render), world_(world), t_end_(t_end) {}

std::optional<core::Timestamp> RigFrameSource::nextReadyTime() const {
  const sim::Capture& cap = rig_.peek();
  if (cap.capture_time >= t_end_) return std::nullopt;
  return cap.capture_time + 0.5 * rig_.cameras()[cap.camera_index].effects.blur.exposure;
}

std::optional<runtime::Frame> RigFrameSource::grab() {
  std::optional<sim::Frame> f = rig_.captureNext(world_);
  if (!f) return std::nullopt;
  last_truth_ = std::move(f->truth);
  runtime::Frame out;
  out.camera = f->camera_index;
  out.sequence = f->sequence;
  out.capture_time = f->capture_time;
  out.stamp = f->stamp;
  out.image = f->image;  // shares the pixels
  return out;
}

const sim::ObjectTruth* RigFrameSource::lastTruthOf(const std::string& name) const {
  for (const auto& t : last_truth_)
    if (t.name == name) return &t;
  return nullptr;
}

}  // namespace viewline::scenarios
