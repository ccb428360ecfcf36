#include "viewline/scenarios/pan_tilt/world.h"

#include <algorithm>
#include <utility>

#include "viewline/core/frames.h"

namespace viewline::scenarios {

using Eigen::Vector2d;
using Eigen::Vector3d;

Vector2d pathAmplitude(const sim::ScreenPath& path, double duration) {
  Vector2d lo = Vector2d::Constant(1e300), hi = Vector2d::Constant(-1e300);
  const int n = std::max(2, static_cast<int>(duration * 200.0));
  for (int i = 0; i <= n; ++i) {
    const Vector2d p = path.position(duration * i / n);
    lo = lo.cwiseMin(p);
    hi = hi.cwiseMax(p);
  }
  return 0.5 * (hi - lo);
}

namespace pan_tilt {

Eigen::Isometry3d screenPose(const PanTiltScenarioConfig& c) {
  Eigen::Isometry3d m = Eigen::Isometry3d::Identity();
  m.linear() << 0, 0, 1,   // screen x = −y_f, y = −z_f, z = +x_f (columns)
      -1, 0, 0,            //
      0, -1, 0;
  m.translation() = Vector3d(c.screen_distance, 0.0, c.screen_center_height);
  return m;
}

namespace {
sim::ScreenPathParams runPathParams(const PanTiltScenarioConfig& c) {
  sim::ScreenPathParams pp = c.path;
  pp.duration = c.duration + 10.0;
  return pp;
}
}  // namespace

sim::ScreenPath makePath(const PanTiltScenarioConfig& c, std::uint64_t seed) {
  core::Rng path_rng = core::makeRng(core::deriveSeed(seed, 1));
  return sim::ScreenPath(runPathParams(c), path_rng);
}

Vector2d noiseSigma(const PanTiltScenarioConfig& c, const sim::ScreenPath& path) {
  // Closed paths: over one full lap (independent of the run's length); random: over the run.
  const sim::ScreenPathParams& pp = c.path;
  double amplitude_span = c.duration;
  if (pp.shape == sim::PathShape::Rectangle) amplitude_span = 2.0 * (pp.width + pp.height) / pp.speed;
  if (pp.shape == sim::PathShape::Circle) amplitude_span = 2.0 * core::kPi * pp.radius / pp.speed;
  return c.noise_fraction * pathAmplitude(path, amplitude_span);
}

Eigen::Matrix2d noiseCovariance(const Vector2d& sigma) {
  Eigen::Matrix2d R = sigma.cwiseProduct(sigma).asDiagonal();
  if (R.determinant() <= 0.0) R += 1e-8 * Eigen::Matrix2d::Identity();
  return R;
}

void World::Occluded::dynamicObjects(double t, std::vector<sim::Primitive>& out) const {
  if (t >= t0_ && t < t1_) return;
  inner_.dynamicObjects(t, out);
}

namespace {
sim::ScreenAppearance appearance(const PanTiltScenarioConfig& c) {
  sim::ScreenAppearance look;
  look.width = c.screen_width;
  look.height = c.screen_height;
  look.disc_radius = c.disc_radius;
  return look;
}

robots::SimulatedPanTiltParams unitParams(const PanTiltScenarioConfig& c, const sim::ScreenPath& path,
                                          const Eigen::Isometry3d& f_M_screen, const robots::PanTiltKinematics& kin) {
  // Pointing at the start point plus the configured offset, within the limits.
  robots::SimulatedPanTiltParams up = c.unit;
  const Vector2d p0 = path.position(0.0);
  Vector2d q0 = kin.pointAt(f_M_screen * Vector3d(p0.x(), p0.y(), -0.001)) + c.initial_offset;
  up.q0 = q0.cwiseMax(up.limits.q_min).cwiseMin(up.limits.q_max);
  return up;
}

std::vector<sim::SimCamera> cameraOnUnit(const PanTiltScenarioConfig& c, robots::PanTiltUnit& unit,
                                         const robots::PanTiltKinematics& kin) {
  sim::SimCamera sc;
  sc.camera = panTiltTrueCamera(c);
  sc.clock.rate = c.fps;
  sc.effects.noise.sigma = c.sensor_noise;
  sc.effects.noise.pool_size = 1u << 20;
  sc.effects.blur.exposure = c.exposure;
  sc.effects.blur.samples = c.exposure > 0.0 ? 3 : 1;
  sc.pose_at = [&unit, &kin](double t) { return kin.c_M_f(unit.read(t).q); };
  return {sc};
}

sim::RenderSettings renderSettings() {
  sim::RenderSettings rs;
  rs.supersampling = 3;
  return rs;
}
}  // namespace

World::World(const PanTiltScenarioConfig& c, std::uint64_t seed, robots::PanTiltUnit* hardware)
    : path_rng_(core::makeRng(core::deriveSeed(seed, 1))),
      render_rng_(core::makeRng(core::deriveSeed(seed, 2))),
      noise_rng_(core::makeRng(core::deriveSeed(seed, 3))),
      path_(runPathParams(c), path_rng_),
      f_M_screen_(screenPose(c)),
      screen_(path_, f_M_screen_, sim::Scene{}, appearance(c)),
      occ0_(c.occlusion_start >= 0.0 ? c.occlusion_start : 1e300),
      occ1_(c.occlusion_start >= 0.0 ? c.occlusion_start + c.occlusion_duration : 1e300),
      occluded_(screen_, occ0_, occ1_),
      sigma_(noiseSigma(c, path_)),
      R_(noiseCovariance(sigma_)),
      kin_(c.true_e_M_c ? robots::PanTiltKinematics(*c.true_e_M_c) : robots::PanTiltKinematics()),
      kin_model_(c.calibrated_e_M_c ? robots::PanTiltKinematics(*c.calibrated_e_M_c) : robots::PanTiltKinematics()),
      unit_(unitParams(c, path_, f_M_screen_, kin_)),
      hardware_(hardware),
      rig_(cameraOnUnit(c, actuator(), kin_), render_rng_, renderSettings()),
      exposure_(c.exposure) {
  rig_.reset(0.0);
  const core::Camera& cam = rig_.cameras().front().camera;
  principal_ = Vector2d(cam.intrinsics.get_u0(), cam.intrinsics.get_v0());
}

Vector2d World::drawNoise() {
  // (the same expression as a hand loop's: both draws, x then y as the compiler orders them)
  const Vector2d n(core::gaussian(noise_rng_, sigma_.x()), core::gaussian(noise_rng_, sigma_.y()));
  return n;
}

FrameTruth World::truth(const core::Camera& cam, double tc) const {
  FrameTruth t;
  t.plane = path_.position(tc);
  const Vector3d truth_f = f_M_screen_ * Vector3d(t.plane.x(), t.plane.y(), 0.0);
  const Vector3d truth_c = cam.toCamera(truth_f);
  t.px = cam.normalizedToPixel(Vector2d(truth_c.x() / truth_c.z(), truth_c.y() / truth_c.z()));
  t.error_px = (t.px - principal_).norm();
  return t;
}

RendererSource::RendererSource(World& world, std::size_t frames) : world_(world), remaining_(frames) {}

std::optional<core::Timestamp> RendererSource::nextReadyTime() const {
  if (remaining_ == 0) return std::nullopt;
  return world_.rig().peek().capture_time + 0.5 * world_.exposure();
}

std::optional<runtime::Frame> RendererSource::grab() {
  if (remaining_ == 0) return std::nullopt;
  --remaining_;
  std::optional<sim::Frame> f = world_.rig().captureNext(world_.scene());
  if (!f) return std::nullopt;
  last_camera_ = f->camera;
  runtime::Frame out;
  out.camera = f->camera_index;
  out.sequence = f->sequence;
  out.capture_time = f->capture_time;
  out.stamp = f->stamp;
  out.image = std::move(f->image);
  return out;
}

}  // namespace pan_tilt
}  // namespace viewline::scenarios
