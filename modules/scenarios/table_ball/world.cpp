#include "viewline/scenarios/table_ball/world.h"

#include <cmath>

#include "viewline/core/frames.h"
#include "viewline/sim/renderer.h"

namespace viewline::scenarios {

namespace {

Eigen::Isometry3d translation(const Eigen::Vector3d& p) {
  Eigen::Isometry3d m = Eigen::Isometry3d::Identity();
  m.translation() = p;
  return m;
}

sim::TiltTable makeTable(const TableBallConfig& cfg) {
  sim::TiltTableParams tp;
  tp.side = cfg.table_side;
  tp.ball_radius = cfg.ball_radius;
  tp.max_angle = cfg.wrist.max_angle * (1.0 + 1e-9) + 1e-9;  // the wrist model owns the limits
  tp.max_rate = 1e4;                                         // ... and follows them within a tick
  tp.delay = 0.0;
  tp.substep = TableBallWorld::kTick;
  tp.history = 1.0;
  tp.w_M_base = translation(cfg.table_center);
  sim::TiltTableState s0;
  s0.p = cfg.initial_ball;
  s0.v = cfg.initial_velocity;
  return sim::TiltTable(tp, s0);
}

sim::Scene roomScene(core::Rng& room_rng) {
  sim::RoomParams room;
  room.floor_texture.resolution = 512;
  room.wall_texture.resolution = 512;
  return sim::makeRoom(room, room_rng);
}

sim::TableAppearance appearance(const TableBallConfig& cfg) {
  sim::TableAppearance look;
  look.tags = cfg.table_tags;
  look.tag_size = cfg.tag_size;
  look.border_height = cfg.border_height;
  return look;
}

/// `camera` renders (the truth); with a rig, the observer believes in the calibrated one.
core::Camera makeRenderCamera(const TableBallConfig& cfg) {
  if (cfg.rig) return cfg.rig->truth;
  core::Camera camera;
  camera.name = "head";
  camera.width = cfg.width;
  camera.height = cfg.height;
  camera.intrinsics = core::intrinsicsFromFov(cfg.hfov, cfg.width, cfg.height);
  if (cfg.cx || cfg.cy) {
    const vpCameraParameters k = camera.intrinsics;
    camera.intrinsics.initPersProjWithoutDistortion(k.get_px(), k.get_py(), cfg.cx.value_or(k.get_u0()),
                                                    cfg.cy.value_or(k.get_v0()));
  }
  camera.c_M_w = core::lookAt(cfg.camera_position, cfg.camera_look_at, Eigen::Vector3d::UnitZ());
  return camera;
}

sim::SimCamera simCamera(const TableBallConfig& cfg, const core::Camera& camera, const HeadSway& sway) {
  sim::SimCamera simcam;
  simcam.camera = camera;
  simcam.clock.rate = cfg.rate_hz;
  simcam.effects.noise.sigma = cfg.sensor_noise;
  simcam.effects.noise.pool_size = 1u << 20;
  simcam.effects.blur.exposure = cfg.exposure;
  simcam.effects.blur.samples = cfg.blur_samples;
  simcam.effects.faults.drop_probability = cfg.drop_probability;
  simcam.pose_at = [sway](double t) { return sway.at(t); };
  return simcam;
}

sim::RenderSettings renderSettings(const TableBallConfig& cfg) {
  sim::RenderSettings render;
  render.supersampling = cfg.supersampling;
  return render;
}

}  // namespace

Eigen::Isometry3d HeadSway::at(double t) const {
  const double w = 2.0 * core::kPi * f;
  const Eigen::Vector3d rot(amplitude * std::sin(w * t + phase[0]), amplitude * std::sin(1.37 * w * t + phase[1]),
                            0.5 * amplitude * std::sin(0.71 * w * t + phase[2]));
  const Eigen::Vector3d tr(translation * std::sin(1.13 * w * t + phase[3]),
                           translation * std::sin(0.89 * w * t + phase[4]),
                           translation * std::sin(1.51 * w * t + phase[5]));
  Eigen::Isometry3d d = Eigen::Isometry3d::Identity();
  d.linear() = core::rotation(Eigen::Vector3d::UnitX(), rot.x()) * core::rotation(Eigen::Vector3d::UnitY(), rot.y()) *
               core::rotation(Eigen::Vector3d::UnitZ(), rot.z());
  d.translation() = tr;
  return d * c_M_w0;  // perturbation expressed in the camera frame
}

std::vector<vision::TagOnTable> tableTagLayout(const sim::TableWorld& world) {
  const sim::TableAppearance& look = world.appearance();
  std::vector<vision::TagOnTable> layout;
  if (!look.tags) return layout;
  for (int i = 0; i < 4; ++i) layout.push_back({look.first_tag_id + i, look.tag_size, world.table_M_vispTag(i)});
  return layout;
}

// ---------------------------------------------------------------------------------------------

TableBallWorld::TableBallWorld(const TableBallConfig& config, std::uint64_t seed)
    : cfg_(config),
      rng_(core::makeRng(seed)),
      room_rng_(core::makeRng(core::deriveSeed(seed, 1))),
      rig_rng_(core::makeRng(core::deriveSeed(seed, 2))),
      imu_rng_(core::makeRng(core::deriveSeed(seed, 3))),
      table_(makeTable(cfg_)),
      wrist_(cfg_.wrist),
      scene_(table_, roomScene(room_rng_), appearance(cfg_)),
      camera_(makeRenderCamera(cfg_)),
      obs_camera_(cfg_.rig ? cfg_.rig->calibrated : camera_),
      sway_(makeSway()),
      rig_({simCamera(cfg_, camera_, sway_)}, rig_rng_, renderSettings(cfg_)) {
  rig_.reset(0.0);
}

HeadSway TableBallWorld::makeSway() {
  HeadSway sway{camera_.c_M_w, cfg_.sway, cfg_.sway_hz, cfg_.sway_translation, {}};
  for (double& ph : sway.phase) ph = core::uniform(rng_, 0.0, 2.0 * core::kPi);
  return sway;
}

void TableBallWorld::step() {
  ++ticks_;
  const double s = time();
  while (push_i_ < cfg_.pushes.size() && cfg_.pushes[push_i_].t <= s) table_.push(cfg_.pushes[push_i_++].dv);
  table_.command(s, wrist_.actual(s));
  table_.advanceTo(s);
}

Eigen::Isometry3d TableBallWorld::observerHeadPose(double t) const {
  // What the renderer used at t (sim::CameraRig: pose_at(capture_time)); with a rig, the same
  // sway D(t) = c_M_w_true(t) · c_M_w_true(0)⁻¹ on the calibrated rest pose.
  const Eigen::Isometry3d c_M_w = sway_.at(t);
  if (!cfg_.rig) return c_M_w;
  return c_M_w * camera_.c_M_w.inverse() * obs_camera_.c_M_w;
}

Eigen::Matrix3d TableBallWorld::groundRotationReading(const Eigen::Isometry3d& c_M_w) {
  Eigen::Matrix3d c_R_w = c_M_w.linear();
  if (cfg_.ground_rotation_noise > 0.0) {
    const Eigen::Vector3d e(core::gaussian(imu_rng_, cfg_.ground_rotation_noise),
                            core::gaussian(imu_rng_, cfg_.ground_rotation_noise),
                            core::gaussian(imu_rng_, cfg_.ground_rotation_noise));
    c_R_w = Eigen::AngleAxisd(e.norm(), e.norm() > 0 ? Eigen::Vector3d(e.normalized()) : Eigen::Vector3d::UnitX())
                .toRotationMatrix() * c_R_w;
  }
  return c_R_w;
}

TableBallObserverConfig TableBallWorld::observerConfig() const {
  TableBallObserverConfig o = cfg_.observer;
  o.detector.side_m = cfg_.table_side;
  o.detector.ball_radius_m = cfg_.ball_radius;
  o.tracker = cfg_.trackerConfig();
  o.border_height = cfg_.border_aware_pnp ? cfg_.border_height : 0.0;  // the table's known design
  if (o.table_pose == TablePoseSource::AprilTag) {
    o.tag_layout = tableTagLayout(scene_);  // in vpDetectorAprilTag's tag frame (z out of the tag)
    o.tag_detector.tag_size_m = cfg_.tag_size;
  }
  return o;
}

// ---------------------------------------------------------------------------------------------

RenderedHeadCamera::RenderedHeadCamera(TableBallWorld& world, double exposure, double end)
    : world_(world), exposure_(exposure), end_(end) {}

std::optional<core::Timestamp> RenderedHeadCamera::nextReadyTime() const {
  const sim::Capture& cap = world_.cameraRig().peek();
  if (cap.capture_time >= end_) return std::nullopt;
  return cap.capture_time + 0.5 * exposure_;
}

std::optional<runtime::Frame> RenderedHeadCamera::grab() {
  last_ = world_.cameraRig().peek();
  std::optional<sim::Frame> f = world_.cameraRig().captureNext(world_.scene());
  if (!f) return std::nullopt;
  runtime::Frame out;
  out.camera = 0;
  out.sequence = f->sequence;
  out.capture_time = f->capture_time;
  out.stamp = f->stamp;
  out.image = std::move(f->image);
  return out;
}

}  // namespace viewline::scenarios
