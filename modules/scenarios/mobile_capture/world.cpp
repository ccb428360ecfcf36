#include "viewline/scenarios/mobile_capture/world.h"

#include <algorithm>
#include <cmath>

#include "viewline/estimation/models/unicycle_predictor.h"
#include "viewline/robots/mobile_ground_localization.h"
#include "viewline/sim/effects.h"
#include "viewline/sim/renderer.h"
#include "viewline/sim/worlds.h"

namespace viewline::scenarios::mobile_capture {

using Eigen::Vector2d;
using Eigen::Vector3d;

Streams::Streams(std::uint64_t seed)
    : object(core::makeRng(core::deriveSeed(seed, 1))),
      room(core::makeRng(core::deriveSeed(seed, 2))),
      render(core::makeRng(core::deriveSeed(seed, 3))),
      drive(core::makeRng(core::deriveSeed(seed, 4))) {}

core::Camera renderCamera(const MobileCaptureConfig& cfg) {
  if (cfg.rig) return cfg.rig->truth;
  core::Camera cam;
  cam.name = "head";
  cam.width = cfg.width;
  cam.height = cfg.height;
  const double px = 0.5 * cfg.width / std::tan(0.5 * cfg.hfov);
  const double py = 0.5 * cfg.height / std::tan(0.5 * cfg.vfov);
  cam.intrinsics = vpCameraParameters(px, py, 0.5 * cfg.width, 0.5 * cfg.height);
  return cam;
}

core::Camera estimatorCamera(const MobileCaptureConfig& cfg) {
  return cfg.rig ? cfg.rig->calibrated : renderCamera(cfg);
}

Eigen::Isometry3d trueCamera_c_M_w(const robots::MobilePanTilt& head, const robots::PanTiltJoints& q, double x,
                                   double y, double theta) {
  return robots::headCamera_c_M_w(head, q, x, y, theta);
}

Eigen::Isometry3d estimatorCamera_c_M_w(const MobileCaptureConfig& cfg, const Eigen::Isometry3d& true_c_M_w) {
  return cfg.rig ? Eigen::Isometry3d(cfg.rig->cal_M_c * true_c_M_w) : true_c_M_w;
}

Eigen::Isometry3d estimatorCamera_c_M_w(const MobileCaptureConfig& cfg, const robots::MobilePanTilt& head,
                                        const HeadReading& r) {
  return estimatorCamera_c_M_w(cfg, trueCamera_c_M_w(head, r.q, r.base.x, r.base.y, r.base.theta));
}

sim::GroundTargetParams targetParams(const MobileCaptureConfig& cfg, sim::GroundProfile profile, double duration) {
  sim::GroundTargetParams p;
  p.profile = profile;
  p.profile_period = cfg.vision_period;
  p.start = cfg.object_start;
  p.heading = cfg.object_heading;
  p.duration = duration;
  p.substep = cfg.controlPeriod();
  p.noise = cfg.object_noise;
  return p;
}

double targetDuration(const MobileCaptureConfig& cfg) {
  return cfg.max_time + (cfg.horizon_steps + 2) * cfg.vision_period + 1.0;
}

std::optional<Vector2d> detectScreened(vision::BallDetector& detector, runtime::FaultPlan& faults,
                                       const runtime::Frame& frame, double t,
                                       const std::optional<Vector2d>& predicted_px) {
  const auto det = runtime::guardedDetect(faults, frame.camera, frame.capture_time,
                                          [&] { return detector.detect(frame.image, t, predicted_px); });
  std::optional<Vector2d> px;
  if (det && det->ok())
    px = faults.detected(frame.camera, frame.capture_time, det->value().blob_center, frame.image.cols, frame.image.rows);
  if (px && !runtime::usablePixel(*px, frame.image.cols, frame.image.rows)) {
    faults.note("detections_rejected");
    px.reset();
  }
  return px;
}

Vector2d toRobot(const robots::BasePose& pose, const Vector2d& p_w) {
  const Vector2d d = p_w - Vector2d(pose.x, pose.y);
  const double c = std::cos(pose.theta), s = std::sin(pose.theta);
  return {c * d.x() + s * d.y(), -s * d.x() + c * d.y()};
}

TickClock TickClock::of(const MobileCaptureConfig& cfg) {
  return {cfg.controlPeriod(), std::lround(cfg.max_time / cfg.controlPeriod())};
}

long TickClock::visionEvery(const MobileCaptureConfig& cfg) { return std::lround(cfg.vision_period / cfg.controlPeriod()); }

RobotSim::RobotSim(const MobileCaptureConfig& c)
    : cfg(c), head(c.head), base(c.base, {c.robot_start.x(), c.robot_start.y(), c.robot_heading}) {
  q = head.pointAtBest(Vector3d(2.0, 0.0, 0.0));
}

void RobotSim::stepHead(const robots::PanTiltJoints& target) {
  const auto t = head.clampToLimits(target);
  q.tilt = robots::JointRateLimiter::step(q.tilt, t.tilt, cfg.head.tilt_rate_max, cfg.controlPeriod());
  q.pan = robots::JointRateLimiter::step(q.pan, t.pan, cfg.head.pan_rate_max, cfg.controlPeriod());
}

// ------------------------------------------------------------------------------------------------

struct RenderedHeadCamera::Impl {
  const MobileCaptureConfig& cfg;
  core::Rng& rng;
  PoseProvider camera_pose;
  sim::GroundWorld world;
  sim::Renderer renderer;
  std::optional<sim::NoisePool> noise;
  core::Camera camera;
  TickClock clock;
  long every;
  std::uint64_t next = 0;  // index of the next frame

  static sim::Scene makeFloor(const MobileCaptureConfig& cfg, core::Rng& room_rng) {
    sim::RoomParams room;
    room.floor_size = cfg.floor_size;
    room.walls = false;
    room.floor_texture.resolution = 2048;
    room.floor_texture.base_cells = 12;
    return sim::makeRoom(room, room_rng);
  }
  static sim::RenderSettings settings(const MobileCaptureConfig& cfg) {
    sim::RenderSettings rs;
    rs.supersampling = cfg.supersampling;
    rs.max_cached_cameras = 1;
    return rs;
  }
  Impl(const MobileCaptureConfig& c, const sim::GroundTarget& target, Streams& streams, PoseProvider pose)
      : cfg(c),
        rng(streams.render),
        camera_pose(std::move(pose)),
        world(target, makeFloor(c, streams.room)),
        renderer(settings(c)),
        camera(renderCamera(c)),
        clock(TickClock::of(c)),
        every(TickClock::visionEvery(c)) {
    if (cfg.sensor_noise > 0.0) noise.emplace(sim::SensorNoise{cfg.sensor_noise, 1u << 18}, rng);
  }
  long tick() const { return static_cast<long>(next) * every; }
};

RenderedHeadCamera::RenderedHeadCamera(const MobileCaptureConfig& cfg, const sim::GroundTarget& target, Streams& rng,
                                       PoseProvider camera_pose)
    : impl_(std::make_unique<Impl>(cfg, target, rng, std::move(camera_pose))) {}

RenderedHeadCamera::~RenderedHeadCamera() = default;

std::optional<core::Timestamp> RenderedHeadCamera::nextReadyTime() const {
  if (impl_->tick() > impl_->clock.last) return std::nullopt;
  return impl_->clock.time(impl_->tick());
}

std::optional<runtime::Frame> RenderedHeadCamera::grab() {
  Impl& m = *impl_;
  if (m.tick() > m.clock.last) return std::nullopt;
  runtime::Frame f;
  f.sequence = m.next;
  f.capture_time = f.stamp = m.clock.time(m.tick());
  ++m.next;
  m.camera.c_M_w = m.camera_pose();
  f.image = m.renderer.render(m.world, m.camera, sim::ExposureSpec{f.capture_time, 0.0, 1});
  if (m.noise) m.noise->apply(f.image, m.rng);
  const bool blackout = m.cfg.blackout_start >= 0.0 && f.capture_time >= m.cfg.blackout_start &&
                        f.capture_time < m.cfg.blackout_start + m.cfg.blackout_duration;
  if (blackout) f.image.setTo(cv::Scalar(0, 0, 0));  // the lens is covered
  return f;
}

// ------------------------------------------------------------------------------------------------

std::vector<Vector2d> predictPath(const tracking::UnicycleTracker& track, const MobileCaptureConfig& cfg) {
  const auto& pred = track.predictor();
  estimation::UnicycleTrajectoryPredictor::Accelerations acc;
  if (pred.size() >= pred.window()) {
    acc = pred.fitAccelerations();
    acc.a_v = std::clamp(acc.a_v, -cfg.max_accel_v, cfg.max_accel_v);
    acc.a_omega = std::clamp(acc.a_omega, -cfg.max_accel_omega, cfg.max_accel_omega);
  }
  return estimation::UnicycleTrajectoryPredictor::rollForward(track.state().x(), acc, cfg.vision_period,
                                                              cfg.horizon_steps);
}

std::vector<Vector2d> truePath(const sim::GroundTarget& target, double t, double T, int M) {
  std::vector<Vector2d> out;
  out.reserve(static_cast<std::size_t>(M));
  const double end = target.params().duration;
  for (int m = 1; m <= M; ++m) {
    const auto s = target.state(std::min(end, t + m * T));
    out.emplace_back(s.x, s.y);
  }
  return out;
}

std::optional<FloorMeasurement> floorMeasurement(const MobileCaptureConfig& cfg, const core::Camera& camera,
                                                 const Vector2d& uv, double plane_z) {
  // The exact back-projection of a pixel from a camera centre c along the world ray r, with the
  // ray turned by a small rotation `rot` (world axes, through c) and c raised by dh.
  const Vector3d c0 = camera.center_w();
  const Vector3d r0 = camera.rayThroughPixel_w(uv);
  auto project = [&](const Vector3d& r, double dh) -> std::optional<Vector2d> {
    const Vector3d c = c0 + Vector3d(0.0, 0.0, dh);
    if (!(r.z() < -1e-9) || !(c.z() > plane_z)) return std::nullopt;
    return (c + (plane_z - c.z()) / r.z() * r).head<2>().eval();
  };
  FloorMeasurement m;
  const auto z = project(r0, 0.0);
  if (!z) return std::nullopt;
  m.z = *z;
  // White part: J = ∂z/∂(u, v), central differences over ±0.5 px.
  Eigen::Matrix2d J;
  for (int i = 0; i < 2; ++i) {
    Vector2d d = Vector2d::Zero();
    d[i] = 0.5;
    const auto a = project(camera.rayThroughPixel_w(uv + d), 0.0), b = project(camera.rayThroughPixel_w(uv - d), 0.0);
    if (!a || !b) return std::nullopt;
    J.col(i) = *a - *b;
  }
  m.unit_pixel_cov = J * J.transpose();
  // Bias part: ∂z/∂(rotation about world x, y, z) and ∂z/∂h, central differences over ±1 mrad and
  // ±1 mm (the ground projection is smooth there; its curvature at grazing rays is the reason
  // not to use the σ itself as the step).
  m.bias_cov = cfg.floor_sigma * cfg.floor_sigma * Eigen::Matrix2d::Identity();
  constexpr double kAngle = 1e-3, kHeight = 1e-3;
  const double sa2 = cfg.calibration_angle_sigma * cfg.calibration_angle_sigma;
  const double sh2 = cfg.calibration_height_sigma * cfg.calibration_height_sigma;
  for (int axis = 0; axis < 3 && sa2 > 0.0; ++axis) {
    const Eigen::Matrix3d Rp(Eigen::AngleAxisd(kAngle, Vector3d::Unit(axis)));
    const Eigen::Matrix3d Rm(Eigen::AngleAxisd(-kAngle, Vector3d::Unit(axis)));
    const auto a = project(Rp * r0, 0.0), b = project(Rm * r0, 0.0);
    if (!a || !b) return std::nullopt;
    const Vector2d Jk = (*a - *b) / (2.0 * kAngle);
    m.bias_cov += sa2 * Jk * Jk.transpose();
  }
  if (sh2 > 0.0) {
    const auto a = project(r0, kHeight), b = project(r0, -kHeight);
    if (!a || !b) return std::nullopt;
    const Vector2d Jh = (*a - *b) / (2.0 * kHeight);
    m.bias_cov += sh2 * Jh * Jh.transpose();
  }
  return m;
}

}  // namespace viewline::scenarios::mobile_capture
