#include "viewline/scenarios/pan_tilt_scenario.h"

#include <algorithm>
#include <optional>
#include <chrono>
#include <cmath>
#include <cstdlib>
#include <fstream>
#include <memory>
#include <sstream>
#include <tuple>
#include <utility>

#include "viewline/core/checks.h"
#include "viewline/core/error.h"
#include "viewline/core/frames.h"
#include "viewline/core/random.h"
#include "viewline/control/waypoint_particle_filter.h"
#include "viewline/io/rig.h"
#include "viewline/robots/pan_tilt_kinematics.h"
#include "viewline/sim/rig.h"
#include "viewline/sim/worlds.h"
#include "viewline/scenarios/simulated_rig.h"

namespace viewline::scenarios {

using Eigen::Vector2d;
using Eigen::Vector3d;

namespace {
constexpr const char* kRigCamera = "ptu_camera";  ///< the camera's name in a pan-tilt rig folder

/// The filter's corner settings in force (its configured values or what "auto" made of them);
/// (0, 0) for the particle filter and without jump detection, where they do not apply.
std::pair<int, double> cornerSettings(const control::PlanarTargetFilter& f) {
  if (f.config().model == control::TargetModel::WaypointParticles || !(f.config().jump_window > 0.0)) return {0, 0.0};
  return {f.minSamples(), f.cornerSigma()};
}
}  // namespace

// ---------------------------------------------------------------------------------------------
// Config

void PanTiltScenarioConfig::validate() const {
  core::requirePositive(path.speed, "path.speed");
  if (!(path.corner_radius >= 0.0) || !std::isfinite(path.corner_radius))
    throw core::InvalidInput("path.corner_radius must be >= 0 (m)");
  if (path.corner_radius > 0.0 && path.shape != sim::PathShape::Random)
    throw core::InvalidInput("path.corner_radius is for shape: random (the rectangle's corners are [T]'s)");
  core::requirePositive(screen_distance, "screen.distance");
  core::requireFinite(screen_center_height, "screen.center_height");
  core::requirePositive(screen_width, "screen.width");
  core::requirePositive(screen_height, "screen.height");
  core::requirePositive(disc_radius, "screen.disc_radius");
  if (image_width < 64 || image_height < 64) throw core::InvalidInput("camera.width/height must be >= 64");
  core::requirePositive(fx, "camera.fx");
  core::requirePositive(fy, "camera.fy");
  core::requirePositive(fps, "camera.fps");
  if (!(sensor_noise >= 0.0)) throw core::InvalidInput("camera.sensor_noise must be >= 0");
  if (!(exposure >= 0.0)) throw core::InvalidInput("camera.exposure must be >= 0");
  if (!(noise_fraction >= 0.0)) throw core::InvalidInput("measurement_noise_fraction must be >= 0");
  unit.limits.validate();
  if (!(unit.latency >= 0.0)) throw core::InvalidInput("unit.latency must be >= 0");
  if (!(processing_delay >= 0.5 * exposure)) throw core::InvalidInput("processing_delay must be >= exposure / 2");
  if (!(processing_delay < 1.0 / fps)) throw core::InvalidInput("processing_delay must be shorter than a frame period");
  detector.validate();
  control.validate();
  core::requirePositive(duration, "run.duration");
  if (!(metrics_start >= 0.0 && metrics_start < duration)) throw core::InvalidInput("run.metrics_start must be in [0, duration)");
  if (occlusion_start >= 0.0) core::requirePositive(occlusion_duration, "run.occlusion_duration");
  const bool any_rig = true_camera || calibrated_camera || true_e_M_c || calibrated_e_M_c;
  if (any_rig && !(true_camera && calibrated_camera && true_e_M_c && calibrated_e_M_c)) {
    throw core::InvalidInput("rig: the true and calibrated cameras and camera mounts are set together");
  }
  if (true_camera && (true_camera->width != calibrated_camera->width || true_camera->height != calibrated_camera->height)) {
    throw core::InvalidInput("rig: true and calibrated cameras of different image sizes");
  }
}

PanTiltScenarioConfig loadPanTiltScenarioConfig(const io::ConfigNode& root) {
  PanTiltScenarioConfig c;
  {
    const auto p = root.child("path");
    const std::string shape = p.getChoice("shape", {"rectangle", "circle", "random"});
    c.path.shape = shape == "rectangle" ? sim::PathShape::Rectangle
                                        : (shape == "circle" ? sim::PathShape::Circle : sim::PathShape::Random);
    c.path.speed = p.get<double>("speed");
    c.path.center = p.getOr<Vector2d>("center", Vector2d::Zero());
    c.path.width = p.getOr<double>("width", c.path.width);
    c.path.height = p.getOr<double>("height", c.path.height);
    c.path.radius = p.getOr<double>("radius", c.path.radius);
    c.path.corner_radius = p.getOr<double>("corner_radius", c.path.corner_radius);
  }
  {
    const auto s = root.child("screen");
    c.screen_distance = s.get<double>("distance");
    c.screen_center_height = s.get<double>("center_height");
    c.screen_width = s.getOr<double>("width", c.screen_width);
    c.screen_height = s.getOr<double>("height", c.screen_height);
    c.disc_radius = s.get<double>("disc_radius");
  }
  if (root.has("rig")) {
    // Default simulated rig (issue 9): truth for the simulator, calibration for the controllers.
    const SimulatedRig rig = loadSimulatedRig(root, "rig");
    const auto where = [&](const std::string& what) {
      return root.location("rig") + ": key '" + root.keyPath("rig") + "': " + what;
    };
    if (!rig.truth.e_M_c) throw core::InvalidInput(where(rig.folder + "/truth.yaml has no hand_eye section (not a pan-tilt rig)"));
    c.rig_folder = rig.folder;
    c.true_camera = rig.trueCamera(kRigCamera);
    c.calibrated_camera = rig.calibratedCamera(kRigCamera);
    c.true_e_M_c = *rig.truth.e_M_c;
    try {
      const auto he = io::ConfigNode::loadFile(rig.file("e_M_c.yaml"));  // calibrate-hand-eye output
      c.calibrated_e_M_c = io::readPose(he.child("e_M_c"));
      for (const char* k : {"r_M_o", "rms_translation_m", "rms_rotation_deg"}) he.ignore(k);
      he.finish();
    } catch (const core::InvalidInput& e) {
      throw core::InvalidInput(where(e.what()));
    }
    c.image_width = c.true_camera->width;
    c.image_height = c.true_camera->height;
    c.fx = c.true_camera->intrinsics.get_px();
    c.fy = c.true_camera->intrinsics.get_py();
  }
  {
    const auto cam = root.child("camera");
    if (c.rig_folder.empty()) {
      c.image_width = cam.get<unsigned>("width");
      c.image_height = cam.get<unsigned>("height");
      c.fx = cam.get<double>("fx");
      c.fy = cam.get<double>("fy");
    } else {
      for (const char* k : {"width", "height", "fx", "fy"}) {
        if (cam.has(k)) cam.fail(k, "no inline camera with `rig:` (the rig's truth.yaml and rig.yaml give the camera)");
      }
    }
    c.fps = cam.get<double>("fps");
    c.sensor_noise = cam.getOr<double>("sensor_noise", c.sensor_noise);
    c.exposure = cam.getOr<double>("exposure", c.exposure);
  }
  c.noise_fraction = root.get<double>("measurement_noise_fraction");
  {
    const auto u = root.child("unit");
    const auto pan = u.get<Vector2d>("pan_limits_deg");
    const auto tilt = u.get<Vector2d>("tilt_limits_deg");
    c.unit.limits.q_min = Vector2d(core::deg2rad(pan(0)), core::deg2rad(tilt(0)));
    c.unit.limits.q_max = Vector2d(core::deg2rad(pan(1)), core::deg2rad(tilt(1)));
    c.unit.limits.qdot_max = Vector2d::Constant(core::deg2rad(u.get<double>("max_speed_deg")));
    c.unit.limits.qddot_max = Vector2d::Constant(core::deg2rad(u.get<double>("max_acceleration_deg")));
    c.unit.latency = u.get<double>("latency");
    const auto off = u.getOr<Vector2d>("initial_offset_deg", Vector2d::Zero());
    c.initial_offset = Vector2d(core::deg2rad(off(0)), core::deg2rad(off(1)));
  }
  c.processing_delay = root.get<double>("processing_delay");
  {
    const auto d = root.child("detector");
    const auto crop = d.getOr<std::vector<int>>("crop", {0, 0, 0, 0});
    if (crop.size() != 4) d.fail("crop", "4 margins [left, top, right, bottom] in px");
    c.detector.crop_left = crop[0];
    c.detector.crop_top = crop[1];
    c.detector.crop_right = crop[2];
    c.detector.crop_bottom = crop[3];
    c.detector.scale = d.getOr<double>("scale", 0.5);
    c.detector.threshold = d.getOr<int>("threshold", -1);
    c.detector.median_ksize = d.getOr<int>("median_ksize", 5);
    c.detector.min_area_px = d.getOr<double>("min_area_px", c.detector.min_area_px);
  }
  {
    const auto k = root.child("control");
    c.control.servo.gain = k.get<double>("gain");
    c.control.servo.interaction = k.getChoiceOr("interaction", {"desired", "current", "mean"}, "desired");
    c.control.gain = k.getOr<double>("predictive_gain", 0.0);
    c.control.lead = k.getOr<double>("lead", 0.0);
    c.control.feed_forward = k.getOr<bool>("feed_forward", true);
    c.control.coast_time = k.getOr<double>("coast_time", c.control.coast_time);
    c.control.limits.margin = k.getAngleOr("limit_margin_deg", c.control.limits.margin);
    if (k.has("search")) {
      const auto s = k.child("search");
      c.control.search_speed = s.getOr<double>("speed", c.control.search_speed);
      c.control.search_growth = s.getOr<double>("growth", c.control.search_growth);
      c.control.search_radius = s.getOr<double>("radius", c.control.search_radius);
      c.control.search_gain = s.getOr<double>("gain", c.control.search_gain);
    }
  }
  {
    const auto f = root.child("filter");
    c.control.filter.model = control::targetModelFromString(
        f.getChoice("model", {"constant_velocity", "cv", "constant_acceleration", "ca", "singer", "coordinated_turn",
                              "ct", "imm", "waypoint_particles"}));
    c.control.filter.q = f.getOr<double>("q", c.control.filter.q);
    c.control.filter.singer_tau = f.getOr<double>("singer_tau", c.control.filter.singer_tau);
    c.control.filter.singer_sigma = f.getOr<double>("singer_sigma", c.control.filter.singer_sigma);
    c.control.filter.init_velocity_sigma = f.getOr<double>("init_velocity_sigma", c.control.filter.init_velocity_sigma);
    c.control.filter.init_acceleration_sigma =
        f.getOr<double>("init_acceleration_sigma", c.control.filter.init_acceleration_sigma);
    c.control.filter.gate_probability = f.getOr<double>("gate_probability", c.control.filter.gate_probability);
    c.control.filter.reinit_after = f.getOr<int>("reinit_after", c.control.filter.reinit_after);
    c.control.filter.init_omega_sigma = f.getOr<double>("init_omega_sigma", c.control.filter.init_omega_sigma);
    c.control.filter.ct_q_accel = f.getOr<double>("ct_q_accel", c.control.filter.ct_q_accel);
    c.control.filter.ct_q_omega = f.getOr<double>("ct_q_omega", c.control.filter.ct_q_omega);
    c.control.filter.maneuver_q = f.getOr<double>("maneuver_q", c.control.filter.maneuver_q);
    c.control.filter.jump_window = f.getOr<double>("jump_window", c.control.filter.jump_window);
    c.control.filter.jump_threshold = f.getOr<double>("jump_threshold", c.control.filter.jump_threshold);
    c.control.filter.jump_min_samples =
        f.getOrAuto<int>("jump_min_samples", c.control.filter.jump_min_samples, "an integer >= 2");
    c.control.filter.constant_speed_sigma =
        f.getOr<double>("constant_speed_sigma", c.control.filter.constant_speed_sigma);
    c.control.filter.constant_speed = f.getOr<bool>("constant_speed", c.control.filter.constant_speed);
    c.control.filter.jump_corner_sigma =
        f.getOrAuto<double>("jump_corner_sigma", c.control.filter.jump_corner_sigma, "a length >= 0 (m)");
    c.control.filter.jump_rate = f.getOr<double>("jump_rate", c.control.filter.jump_rate);
    c.control.filter.jump_prior_sigma = f.getOr<double>("jump_prior_sigma", c.control.filter.jump_prior_sigma);
    c.control.filter.turn_prior_weight = f.getOr<double>("turn_prior_weight", c.control.filter.turn_prior_weight);
    c.control.filter.jump_evidence = f.getChoiceOr("jump_evidence", {"kink", "legs"}, c.control.filter.jump_evidence);
    c.control.filter.jump_decision = f.getChoiceOr("jump_decision", {"test", "posterior"}, c.control.filter.jump_decision);
    c.control.filter.jump_posterior = f.getOr<double>("jump_posterior", c.control.filter.jump_posterior);
    c.control.filter.turn_prior_sigma_deg =
        f.getOr<double>("turn_prior_sigma_deg", c.control.filter.turn_prior_sigma_deg);
    c.control.filter.imm_sojourn = f.getOr<Eigen::Vector3d>("imm_sojourn", c.control.filter.imm_sojourn);
    const int particles = f.getOr<int>("particles", static_cast<int>(c.control.filter.particles));
    if (particles < 100) f.fail("particles", "at least 100 particles");
    c.control.filter.particles = static_cast<std::size_t>(particles);
    c.control.filter.particle_speed = f.getOr<Eigen::Vector2d>("particle_speed", c.control.filter.particle_speed);
    c.control.filter.particle_min_leg = f.getOr<double>("particle_min_leg", c.control.filter.particle_min_leg);
    if (f.has("region")) {
      const auto g = f.child("region");
      c.control.filter.region_center = g.get<Eigen::Vector2d>("center");
      c.control.filter.region_size = g.get<Eigen::Vector2d>("size");
    }
  }
  {
    const auto r = root.child("run");
    c.duration = r.get<double>("duration");
    c.metrics_start = r.get<double>("metrics_start");
    c.occlusion_start = r.getOr<double>("occlusion_start", -1.0);
    c.occlusion_duration = r.getOr<double>("occlusion_duration", 1.0);
    c.run_baseline = r.getOr<bool>("baseline", true);
  }
  root.finish();
  try {
    c.validate();
  } catch (const core::InvalidInput& e) {
    throw core::InvalidInput(root.fileName() + ": " + e.what());
  }
  return c;
}

core::Camera panTiltTrueCamera(const PanTiltScenarioConfig& c) {
  if (c.true_camera) {
    core::Camera cam = *c.true_camera;
    cam.c_M_w = Eigen::Isometry3d::Identity();
    return cam;
  }
  core::Camera cam;
  cam.name = kRigCamera;
  cam.width = c.image_width;
  cam.height = c.image_height;
  cam.intrinsics.initPersProjWithoutDistortion(c.fx, c.fy, 0.5 * (c.image_width - 1.0), 0.5 * (c.image_height - 1.0));
  return cam;
}

core::Camera panTiltModelCamera(const PanTiltScenarioConfig& c) {
  if (!c.calibrated_camera) return panTiltTrueCamera(c);
  core::Camera cam = *c.calibrated_camera;
  cam.c_M_w = Eigen::Isometry3d::Identity();
  return cam;
}

// ---------------------------------------------------------------------------------------------

TTable1Row tTable1(sim::PathShape shape) {
  TTable1Row r;
  if (shape == sim::PathShape::Rectangle) {
    r.available = true;
    r.measured = Vector2d(3.8032, 3.3711);
    r.kalman = Vector2d(2.0601, 2.0674);
  } else if (shape == sim::PathShape::Circle) {
    r.available = true;
    r.measured = Vector2d(3.1147, 2.6701);
    r.kalman = Vector2d(1.5741, 1.1785);
  }
  return r;
}

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

const char* pathShapeName(sim::PathShape s) {
  switch (s) {
    case sim::PathShape::Rectangle: return "rectangle";
    case sim::PathShape::Circle: return "circle";
    case sim::PathShape::Random: return "random";
  }
  return "?";
}

namespace {

/// The screen world with the disc hidden during an occlusion window.
class OccludedWorld : public sim::World {
public:
  OccludedWorld(const sim::World& inner, double t0, double t1) : inner_(inner), t0_(t0), t1_(t1) {}
  const sim::Scene& staticScene() const override { return inner_.staticScene(); }
  void dynamicObjects(double t, std::vector<sim::Primitive>& out) const override {
    if (t >= t0_ && t < t1_) return;
    inner_.dynamicObjects(t, out);
  }
  sim::Lighting lighting() const override { return inner_.lighting(); }
  std::uint64_t staticVersion() const override { return inner_.staticVersion(); }

private:
  const sim::World& inner_;
  double t0_, t1_;
};

Eigen::Isometry3d screenPose(const PanTiltScenarioConfig& c) {
  Eigen::Isometry3d m = Eigen::Isometry3d::Identity();
  m.linear() << 0, 0, 1,   // screen x = −y_f, y = −z_f, z = +x_f (columns)
      -1, 0, 0,            //
      0, -1, 0;
  m.translation() = Vector3d(c.screen_distance, 0.0, c.screen_center_height);
  return m;
}

struct Accumulator {
  double sum = 0.0;
  std::size_t n = 0;
  void add(double v) { sum += v; ++n; }
  double rms() const { return n ? std::sqrt(sum / static_cast<double>(n)) : std::nan(""); }
};

}  // namespace

nlohmann::json PanTiltRunMetrics::toJson() const {
  auto xy = [](const Vector2d& v) {
    return nlohmann::json{{"x", std::isfinite(v.x()) ? nlohmann::json(v.x()) : nlohmann::json()},
                          {"y", std::isfinite(v.y()) ? nlohmann::json(v.y()) : nlohmann::json()}};
  };
  auto num = [](double v) { return std::isfinite(v) ? nlohmann::json(v) : nlohmann::json(); };
  return {{"controller", controller},
          {"frames", frames},
          {"detections", detections},
          {"metric_frames", metric_frames},
          {"image_error_rms_px", num(image_error_rms_px)},
          {"image_error_max_px", num(image_error_max_px)},
          {"rmse_measured_cm", xy(rmse_measured_cm)},
          {"rmse_filtered_cm", xy(rmse_filtered_cm)},
          {"noise_sigma_cm", xy(noise_sigma_cm)},
          {"detection_pixel_rmse_px", num(detection_pixel_rmse_px)},
          {"limits",
           {{"commands", commands},
            {"unsafe_commands", unsafe_commands},
            {"rate_violations", rate_violations},
            {"limit_hits", limit_hits},
            {"max_rate_fraction", max_rate_fraction},
            {"min_limit_distance_deg", {{"pan", min_limit_distance_deg.x()}, {"tilt", min_limit_distance_deg.y()}}},
            {"pan_range_deg", {pan_range_deg.x(), pan_range_deg.y()}},
            {"tilt_range_deg", {tilt_range_deg.x(), tilt_range_deg.y()}}}},
          {"occlusion",
           {{"present", occlusion},
            {"reacquired", reacquired},
            {"reacquisition_delay_s", num(reacquisition_delay_s)},
            {"reacquisitions", reacquisitions},
            {"frames_searching", frames_searching}}},
          {"filter_jumps", filter_jumps},
          {"filter_region_dropped", filter_region_dropped},
          {"filter_corner_settings", {{"min_samples", filter_min_samples}, {"corner_sigma_m", filter_corner_sigma}}},
          {"wall_ms_per_frame", wall_ms_per_frame}};
}

PanTiltRunMetrics runPanTilt(const PanTiltScenarioConfig& cfg, std::uint64_t seed, PanTiltControllerKind kind,
                             const PanTiltFrameSink& sink, io::LogDirectory* log,
                             const std::function<void(double)>& progress) {
  cfg.validate();
  const auto wall0 = std::chrono::steady_clock::now();
  // Streams: path, rendering, [T] noise (the same for both controllers).
  core::Rng path_rng = core::makeRng(core::deriveSeed(seed, 1));
  core::Rng render_rng = core::makeRng(core::deriveSeed(seed, 2));
  core::Rng noise_rng = core::makeRng(core::deriveSeed(seed, 3));

  sim::ScreenPathParams pp = cfg.path;
  pp.duration = cfg.duration + 10.0;
  const sim::ScreenPath path(pp, path_rng);
  const Eigen::Isometry3d f_M_screen = screenPose(cfg);
  sim::ScreenAppearance look;
  look.width = cfg.screen_width;
  look.height = cfg.screen_height;
  look.disc_radius = cfg.disc_radius;
  const sim::ScreenWorld screen_world(path, f_M_screen, sim::Scene{}, look);
  const double occ0 = cfg.occlusion_start >= 0.0 ? cfg.occlusion_start : 1e300;
  const double occ1 = cfg.occlusion_start >= 0.0 ? cfg.occlusion_start + cfg.occlusion_duration : 1e300;
  const OccludedWorld world(screen_world, occ0, occ1);

  // [T] noise: σ = fraction × amplitude of the true path, per axis.
  // Closed paths: over one full lap (independent of the run's length); random: over the run.
  double amplitude_span = cfg.duration;
  if (pp.shape == sim::PathShape::Rectangle) amplitude_span = 2.0 * (pp.width + pp.height) / pp.speed;
  if (pp.shape == sim::PathShape::Circle) amplitude_span = 2.0 * core::kPi * pp.radius / pp.speed;
  const Vector2d amplitude = pathAmplitude(path, amplitude_span);
  const Vector2d sigma = cfg.noise_fraction * amplitude;
  Eigen::Matrix2d R = sigma.cwiseProduct(sigma).asDiagonal();
  if (R.determinant() <= 0.0) R += 1e-8 * Eigen::Matrix2d::Identity();

  // Unit, pointing at the start point plus the configured offset.
  // The true unit (simulator) and the unit as the controllers know it (calibrated mount).
  const robots::PanTiltKinematics kin =
      cfg.true_e_M_c ? robots::PanTiltKinematics(*cfg.true_e_M_c) : robots::PanTiltKinematics();
  const robots::PanTiltKinematics kin_model =
      cfg.calibrated_e_M_c ? robots::PanTiltKinematics(*cfg.calibrated_e_M_c) : robots::PanTiltKinematics();
  robots::SimulatedPanTiltParams up = cfg.unit;
  {
    const Vector2d p0 = path.position(0.0);
    Vector2d q0 = kin.pointAt(f_M_screen * Vector3d(p0.x(), p0.y(), -0.001)) + cfg.initial_offset;
    up.q0 = q0.cwiseMax(up.limits.q_min).cwiseMin(up.limits.q_max);
  }
  robots::SimulatedPanTiltUnit unit(up);

  // Camera on the unit.
  sim::SimCamera sc;
  sc.camera = panTiltTrueCamera(cfg);
  core::Camera model_cam = panTiltModelCamera(cfg);  // pose set per frame
  sc.clock.rate = cfg.fps;
  sc.effects.noise.sigma = cfg.sensor_noise;
  sc.effects.noise.pool_size = 1u << 20;
  sc.effects.blur.exposure = cfg.exposure;
  sc.effects.blur.samples = cfg.exposure > 0.0 ? 3 : 1;
  sc.pose_at = [&unit, &kin](double t) { return kin.c_M_f(unit.read(t).q); };
  std::vector<sim::SimCamera> cams{sc};
  sim::RenderSettings rs;
  rs.supersampling = 3;
  sim::CameraRig rig(std::move(cams), render_rng, rs);
  rig.reset(0.0);
  const Vector2d principal(sc.camera.intrinsics.get_u0(), sc.camera.intrinsics.get_v0());

  vision::ScreenTargetDetector detector(cfg.detector);

  std::unique_ptr<control::PanTiltController> ctrl;
  control::PredictivePanTiltController* ours = nullptr;
  if (kind == PanTiltControllerKind::Predictive) {
    control::PredictiveConfig pc = cfg.control;
    pc.filter.particle_seed = core::deriveSeed(seed, 78);  // (waypoint_particles; the replay uses the same)
    auto p = std::make_unique<control::PredictivePanTiltController>(pc, up.limits, up.latency, f_M_screen, kin_model);
    ours = p.get();
    ctrl = std::move(p);
  } else {
    ctrl = std::make_unique<control::BaselinePanTiltController>(cfg.control.servo, up.limits, up.latency,
                                                                cfg.control.limits, kin_model);
  }

  PanTiltRunMetrics m;
  m.controller = ctrl->name();
  m.noise_sigma_cm = 100.0 * sigma;
  m.occlusion = cfg.occlusion_start >= 0.0 && cfg.occlusion_start < cfg.duration;
  Accumulator img, mx, my, fx_, fy_, det_px;
  Vector2d pan_rng(1e9, -1e9), tilt_rng(1e9, -1e9);
  const double period = 1.0 / cfg.fps;
  std::vector<robots::IssuedCommand> recent;
  const std::string prefix = ctrl->name();
  io::CsvWriter* csv = nullptr;
  if (log != nullptr && log->enabled()) {
    csv = &log->stream(prefix + "_frames",
                       {"t", "truth_x", "truth_y", "detected", "meas_x", "meas_y", "filt_x", "filt_y", "truth_u",
                        "truth_v", "meas_u", "meas_v", "pred_u", "pred_v", "error_px", "pan", "tilt", "pan_rate",
                        "tilt_rate", "cmd_pan", "cmd_tilt", "mode"},
                       17);  // exact doubles: replayPanTiltFilter re-runs the filter on these measurements
  }

  const auto n_frames = static_cast<std::size_t>(std::floor(cfg.duration * cfg.fps));
  for (std::size_t k = 0; k < n_frames; ++k) {
    std::optional<sim::Frame> frame = rig.captureNext(world);
    if (!frame) continue;
    const double tc = frame->capture_time;  // (rig.peek() would already name the next capture)
    ++m.frames;
    const core::Camera& cam = frame->camera;
    const Vector2d truth = path.position(tc);
    const Vector3d truth_f = f_M_screen * Vector3d(truth.x(), truth.y(), 0.0);
    const Vector3d truth_c = cam.toCamera(truth_f);
    const Vector2d truth_px = cam.normalizedToPixel(Vector2d(truth_c.x() / truth_c.z(), truth_c.y() / truth_c.z()));
    const double err_px = (truth_px - principal).norm();

    // [T] noise draws happen every frame (same sequence for both controllers).
    const Vector2d n(core::gaussian(noise_rng, sigma.x()), core::gaussian(noise_rng, sigma.y()));

    control::TargetObservation obs;
    obs.stamp = frame->stamp;
    Vector2d meas_px = Vector2d::Constant(std::nan(""));
    const auto det = detector.detect(frame->image, frame->stamp);
    // The camera as the controllers know it at the capture stamp: calibrated intrinsics, calibrated
    // mount, encoder reading at the stamp.
    model_cam.c_M_w = kin_model.c_M_f(unit.read(frame->stamp).q);
    if (det.ok()) {
      // Back-project onto the screen plane (z_screen = 0) through that camera.
      const Vector3d ray_f = model_cam.rayThroughPixel_w(det.value().pixel);
      const Vector3d c_f = model_cam.center_w();
      const Eigen::Isometry3d screen_M_f = f_M_screen.inverse();
      const Vector3d o_s = screen_M_f * c_f;
      const Vector3d d_s = screen_M_f.linear() * ray_f;
      if (d_s.z() > 1e-9) {
        const double lambda = -o_s.z() / d_s.z();
        const Vector3d hit = o_s + lambda * d_s;
        const Vector2d measured = hit.head<2>() + n;
        const Vector3d meas_c = model_cam.toCamera(f_M_screen * Vector3d(measured.x(), measured.y(), 0.0));
        obs.detected = meas_c.z() > 0.0;
        obs.plane = measured;
        obs.plane_cov = R;
        obs.feature = Vector2d(meas_c.x() / meas_c.z(), meas_c.y() / meas_c.z());
        meas_px = model_cam.normalizedToPixel(obs.feature);
        if (tc >= cfg.metrics_start) det_px.add((det.value().pixel - truth_px).squaredNorm());
      }
    }
    if (obs.detected) ++m.detections;
    ctrl->observe(obs);

    const bool in_metrics = tc >= cfg.metrics_start && !(tc >= occ0 && tc < occ1 + 2.0);
    if (ours != nullptr && obs.detected && ours->lastUpdate().accepted) {
      if (m.occlusion && !m.reacquired && tc >= occ1) {
        m.reacquired = true;
        m.reacquisition_delay_s = tc - occ1;
      }
    } else if (ours == nullptr && obs.detected && m.occlusion && !m.reacquired && tc >= occ1) {
      m.reacquired = true;
      m.reacquisition_delay_s = tc - occ1;
    }
    // The filtered estimate scored on every detected frame: a measurement the gate rejected still
    // counts, with the filter's own estimate at that time (its prediction).
    Vector2d filt = Vector2d::Constant(std::nan(""));
    if (ours != nullptr && obs.detected && ours->filter().initialized())
      filt = ours->lastUpdate().accepted ? ours->filteredPlane() : Vector2d(ours->filter().at(obs.stamp).p);
    if (in_metrics) {
      ++m.metric_frames;
      img.add(err_px * err_px);
      m.image_error_max_px = std::max(m.image_error_max_px, err_px);
      if (obs.detected) {
        mx.add(std::pow(obs.plane.x() - truth.x(), 2));
        my.add(std::pow(obs.plane.y() - truth.y(), 2));
        if (std::isfinite(filt.x())) {
          fx_.add(std::pow(filt.x() - truth.x(), 2));
          fy_.add(std::pow(filt.y() - truth.y(), 2));
        }
      }
    }

    // Command, issued after the processing delay.
    const double t_cmd = tc + cfg.processing_delay;
    control::ControlInput in;
    in.t = t_cmd;
    in.joints = unit.read(t_cmd);
    in.recent = recent;
    in.period = period;
    const control::ControlOutput out = ctrl->command(in);
    const robots::JointState e =
        robots::predictJointState(up.limits, in.joints, recent, up.latency, t_cmd + up.latency);
    ++m.commands;
    if (!robots::isSafeCommand(up.limits, e.q, e.qdot, out.qdot, period, 1e-9)) ++m.unsafe_commands;
    m.max_rate_fraction = std::max(m.max_rate_fraction, out.qdot.cwiseAbs().cwiseQuotient(up.limits.qdot_max).maxCoeff());
    unit.commandVelocity(t_cmd, out.qdot);
    recent.push_back({t_cmd, out.qdot});
    while (recent.size() > 2 && recent.front().t < t_cmd - up.latency - 2.0 * period) recent.erase(recent.begin());
    if (out.mode == control::TrackingMode::Searching) ++m.frames_searching;

    const Vector2d q = in.joints.q;
    pan_rng = Vector2d(std::min(pan_rng(0), q(0)), std::max(pan_rng(1), q(0)));
    tilt_rng = Vector2d(std::min(tilt_rng(0), q(1)), std::max(tilt_rng(1), q(1)));
    for (int i = 0; i < 2; ++i) {
      m.min_limit_distance_deg(i) = std::min(m.min_limit_distance_deg(i),
                                             core::rad2deg(std::min(q(i) - up.limits.q_min(i), up.limits.q_max(i) - q(i))));
    }

    Vector2d pred_px = Vector2d::Constant(std::nan(""));
    if (out.has_prediction) pred_px = model_cam.normalizedToPixel(out.predicted_feature);
    if (csv != nullptr) {
      csv->row({tc, truth.x(), truth.y(), obs.detected ? 1.0 : 0.0, obs.detected ? obs.plane.x() : std::nan(""),
                obs.detected ? obs.plane.y() : std::nan(""), filt.x(), filt.y(), truth_px.x(), truth_px.y(),
                meas_px.x(), meas_px.y(), pred_px.x(), pred_px.y(), err_px, q(0), q(1), in.joints.qdot(0),
                in.joints.qdot(1), out.qdot(0), out.qdot(1), static_cast<double>(out.mode)});
    }
    if (sink) {
      PanTiltFrameView v;
      v.image = &frame->image;
      v.t = tc;
      v.controller = prefix;
      v.detected = obs.detected;
      v.measured_px = meas_px;
      v.truth_px = truth_px;
      v.has_prediction = out.has_prediction;
      v.predicted_px = pred_px;
      v.principal_px = principal;
      v.error_px = err_px;
      v.mode = control::toString(out.mode);
      sink(v);
    }
    if (progress && (k % 30 == 0 || k + 1 == n_frames)) progress(static_cast<double>(k + 1) / n_frames);
  }
  unit.stop(unit.now().t);
  unit.advanceTo(unit.now().t + 1.0);

  m.image_error_rms_px = img.rms();
  m.rmse_measured_cm = 100.0 * Vector2d(mx.rms(), my.rms());
  if (ours != nullptr) {
    m.rmse_filtered_cm = 100.0 * Vector2d(fx_.rms(), fy_.rms());
    m.reacquisitions = ours->reacquisitions();
    m.filter_jumps = ours->filter().jumps();
    m.filter_region_dropped = ours->filter().regionDropped();
    std::tie(m.filter_min_samples, m.filter_corner_sigma) = cornerSettings(ours->filter());
  }
  m.detection_pixel_rmse_px = det_px.rms();
  m.rate_violations = unit.rateViolations();
  m.limit_hits = unit.limitHits();
  m.pan_range_deg = Vector2d(core::rad2deg(pan_rng(0)), core::rad2deg(pan_rng(1)));
  m.tilt_range_deg = Vector2d(core::rad2deg(tilt_rng(0)), core::rad2deg(tilt_rng(1)));
  const double wall =
      std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - wall0).count();
  m.wall_ms_per_frame = m.frames ? wall / static_cast<double>(m.frames) : 0.0;
  return m;
}

nlohmann::json PanTiltReplayMetrics::toJson() const {
  return {{"measurements", measurements},
          {"jumps", jumps},
          {"rmse_measured_cm", {rmse_measured_cm.x(), rmse_measured_cm.y()}},
          {"rmse_filtered_cm", {rmse_filtered_cm.x(), rmse_filtered_cm.y()}},
          {"horizon_s", horizon_s},
          {"rmse_predicted_cm", {rmse_predicted_cm.x(), rmse_predicted_cm.y()}},
          {"predicted_error_px", predicted_error_px},
          {"frame_horizon_s", frame_horizon_s},
          {"frame_predicted_error_px", frame_predicted_error_px},
          {"region_dropped", region_dropped},
          {"corner_settings", {{"min_samples", min_samples}, {"corner_sigma_m", corner_sigma}}}};
}

PanTiltReplayMetrics replayPanTiltFilter(const PanTiltScenarioConfig& cfg, std::uint64_t seed,
                                         const std::string& frames_csv, PanTiltReplayEstimator estimator,
                                         io::LogDirectory* log, std::size_t particles) {
  const bool oracle_corners = estimator == PanTiltReplayEstimator::OracleCorners;
  cfg.validate();
  core::Rng path_rng = core::makeRng(core::deriveSeed(seed, 1));  // the run's path stream
  sim::ScreenPathParams pp = cfg.path;
  pp.duration = cfg.duration + 10.0;
  const sim::ScreenPath path(pp, path_rng);
  double amplitude_span = cfg.duration;  // (as runPanTilt)
  if (pp.shape == sim::PathShape::Rectangle) amplitude_span = 2.0 * (pp.width + pp.height) / pp.speed;
  if (pp.shape == sim::PathShape::Circle) amplitude_span = 2.0 * core::kPi * pp.radius / pp.speed;
  const Vector2d sigma = cfg.noise_fraction * pathAmplitude(path, amplitude_span);
  Eigen::Matrix2d R = sigma.cwiseProduct(sigma).asDiagonal();
  if (R.determinant() <= 0.0) R += 1e-8 * Eigen::Matrix2d::Identity();

  std::ifstream in(frames_csv);
  if (!in) throw core::InvalidInput(frames_csv + ": cannot read (predictive_frames.csv of pan_tilt_tracking --log)");
  std::string line;
  std::getline(in, line);
  std::vector<std::string> header;
  {
    std::stringstream ss(line);
    std::string f;
    while (std::getline(ss, f, ',')) header.push_back(f);
  }
  const auto col = [&](const std::string& name) {
    const auto it = std::find(header.begin(), header.end(), name);
    if (it == header.end()) throw core::InvalidInput(frames_csv + ": no column '" + name + "'");
    return static_cast<std::size_t>(it - header.begin());
  };
  const std::size_t ct = col("t"), cd = col("detected"), cx = col("meas_x"), cy = col("meas_y");
  // The log's own truth (when it has it) must be the path of `seed`: a log of another seed, path or
  // speed would otherwise be scored against the wrong truth without a word.
  const auto has = [&](const std::string& name) { return std::find(header.begin(), header.end(), name) != header.end(); };
  const bool check_truth = has("truth_x") && has("truth_y");
  const std::size_t ctx = check_truth ? col("truth_x") : 0, cty = check_truth ? col("truth_y") : 0;

  control::PredictiveConfig pc = cfg.control;
  pc.filter.particle_seed = core::deriveSeed(seed, 78);  // as runPanTilt: a replay reproduces the run
  control::PredictivePanTiltController ctrl(pc, cfg.unit.limits, cfg.unit.latency, screenPose(cfg));
  // Oracle (a bound, not a controller): constant-speed legs started at the path's true corner times with
  // the true speed; jump detection off. Only the leg directions, the corners' positions and the speed's
  // leg-to-leg variation (none) remain to be estimated from the measurements.
  std::optional<control::PlanarTargetFilter> oracle;
  std::vector<double> corners;
  std::size_t next_corner = 0;
  if (oracle_corners) {
    if (pp.shape == sim::PathShape::Circle) throw core::InvalidInput("--oracle-corners: the circle has no corners");
    if (pp.corner_radius > 0.0)
      throw core::InvalidInput("--oracle-corners: the path's corners are rounded (path.corner_radius > 0); the oracle's "
                               "legs are straight");
    control::TargetFilterConfig fc;
    fc.model = control::TargetModel::ConstantVelocity;
    fc.q = 1e-5;  // the first leg (before the first corner), a plain CV filter
    fc.init_velocity_sigma = cfg.control.filter.init_velocity_sigma;
    fc.gate_probability = cfg.control.filter.gate_probability;
    fc.reinit_after = cfg.control.filter.reinit_after;
    fc.jump_window = 1.0;
    fc.jump_threshold = 1e300;  // never fires
    fc.constant_speed = true;
    fc.constant_speed_sigma = 0.0;
    fc.turn_prior_weight = cfg.control.filter.turn_prior_weight;  // the config's learnt-turn prior, if any
    fc.turn_prior_sigma_deg = cfg.control.filter.turn_prior_sigma_deg;
    fc.region_center = cfg.control.filter.region_center;  // and its waypoint region, if any
    fc.region_size = cfg.control.filter.region_size;
    oracle.emplace(fc);
    corners = path.cornerTimes(cfg.duration);
  }
  // Reference (not a controller): the waypoint particle filter, the posterior mean under the random
  // path's generator. It knows the generator's box (filter.region) and minimum leg, not the path.
  std::optional<control::WaypointParticleFilter> pf;
  if (estimator == PanTiltReplayEstimator::WaypointParticles) {
    if (pp.shape != sim::PathShape::Random || pp.corner_radius > 0.0)
      throw core::InvalidInput("--particles: the model is the random path's (sharp corners, "
                               "path.corner_radius 0)");
    const auto& fcfg = cfg.control.filter;
    if (!(fcfg.region_size.x() > 0.0 && fcfg.region_size.y() > 0.0))
      throw core::InvalidInput("--particles: needs the waypoint region (filter.region: {center, size})");
    control::WaypointParticleConfig wc;
    wc.particles = particles;
    wc.region_center = fcfg.region_center;
    wc.region_size = fcfg.region_size;
    wc.min_leg = 0.1 * std::min(fcfg.region_size.x(), fcfg.region_size.y());  // as sim::ScreenPath
    wc.speed_min = wc.speed_max = pp.speed;  // given, as to the oracle (our filter learns it in the first legs)
    wc.seed = core::deriveSeed(seed, 77);
    pf.emplace(wc);
  }
  const auto filterReady = [&]() {
    return pf ? pf->initialized() : oracle ? oracle->initialized() : ctrl.filter().initialized();
  };
  const auto filterAt = [&](double t) {
    return pf ? pf->predict(t) : oracle ? Vector2d(oracle->at(t).p) : Vector2d(ctrl.filter().at(t).p);
  };
  const double occ0 = cfg.occlusion_start >= 0.0 ? cfg.occlusion_start : 1e300;
  const double occ1 = cfg.occlusion_start >= 0.0 ? cfg.occlusion_start + cfg.occlusion_duration : 1e300;
  PanTiltReplayMetrics out;
  out.horizon_s = cfg.processing_delay + cfg.unit.latency + cfg.control.lead;
  out.frame_horizon_s = (std::floor((cfg.processing_delay + cfg.unit.latency) * cfg.fps + 1e-9) + 1.0) / cfg.fps;
  Accumulator mx, my, fx_, fy_, px_, py_, frame_p;
  io::CsvWriter* csv = nullptr;
  if (log != nullptr && log->enabled())
    csv = &log->stream("replay_frames", {"t", "truth_x", "truth_y", "detected", "meas_x", "meas_y", "filt_x", "filt_y",
                                         "accepted", "jumps"});
  std::size_t row = 1;
  while (std::getline(in, line)) {
    ++row;
    if (line.empty()) continue;
    std::vector<double> v;
    std::stringstream ss(line);
    std::string f;
    while (std::getline(ss, f, ',')) v.push_back(f.empty() || f == "nan" ? std::nan("") : std::strtod(f.c_str(), nullptr));
    if (v.size() != header.size()) throw core::InvalidInput(frames_csv + ":" + std::to_string(row) + ": wrong number of columns");
    const double t = v[ct];
    if (t >= cfg.duration) break;
    if (check_truth && (path.position(t) - Vector2d(v[ctx], v[cty])).norm() > 1e-6)
      throw core::InvalidInput(frames_csv + ":" + std::to_string(row) + ": the logged truth (" + std::to_string(v[ctx]) +
                               ", " + std::to_string(v[cty]) + ") is not the path of seed " + std::to_string(seed) +
                               " at t = " + std::to_string(t) +
                               " s: replay with the --seed and the path settings the log was made with");
    control::TargetObservation obs;
    obs.stamp = t;
    obs.detected = v[cd] > 0.5;
    if (obs.detected) {
      obs.plane = Vector2d(v[cx], v[cy]);
      obs.plane_cov = R;
      ++out.measurements;
    }
    bool accepted = false;
    Vector2d filtered = Vector2d::Constant(std::nan(""));  // scored on every detected frame, as in the closed loop
    if (pf) {
      if (obs.detected) {
        pf->update(t, obs.plane, R);
        accepted = true;
        filtered = pf->mean();
      } else {
        pf->propagateTo(t);
      }
    } else if (oracle) {
      while (next_corner < corners.size() && corners[next_corner] <= t) {
        if (oracle->initialized() && corners[next_corner] >= oracle->state().t()) {
          oracle->setSpeed(pp.speed, 1e-12);
          oracle->startLeg(corners[next_corner]);
        }
        ++next_corner;
      }
      if (obs.detected) {
        accepted = oracle->update(t, obs.plane, R).accepted;
        filtered = accepted ? Vector2d(oracle->estimate().x().head<2>()) : Vector2d(oracle->at(t).p);
      }
    } else {
      ctrl.observe(obs);
      accepted = ctrl.lastUpdate().accepted;
      if (obs.detected && ctrl.filter().initialized())
        filtered = accepted ? ctrl.filteredPlane() : Vector2d(ctrl.filter().at(t).p);
    }
    if (csv != nullptr) {
      const Vector2d truth = path.position(t);
      const double nan = std::nan("");
      csv->row({t, truth.x(), truth.y(), obs.detected ? 1.0 : 0.0, obs.detected ? obs.plane.x() : nan,
                obs.detected ? obs.plane.y() : nan, filtered.x(), filtered.y(),
                accepted ? 1.0 : 0.0, static_cast<double>(oracle ? next_corner : ctrl.filter().jumps())});
    }
    if (!(t >= cfg.metrics_start && !(t >= occ0 && t < occ1 + 2.0))) continue;
    const Vector2d truth = path.position(t);
    if (obs.detected) {
      mx.add(std::pow(obs.plane.x() - truth.x(), 2));
      my.add(std::pow(obs.plane.y() - truth.y(), 2));
      if (std::isfinite(filtered.x())) {
        fx_.add(std::pow(filtered.x() - truth.x(), 2));
        fy_.add(std::pow(filtered.y() - truth.y(), 2));
      }
    }
    if (filterReady()) {
      const Vector2d e = filterAt(t + out.horizon_s) - path.position(t + out.horizon_s);
      px_.add(e.x() * e.x());
      py_.add(e.y() * e.y());
      frame_p.add((filterAt(t + out.frame_horizon_s) - path.position(t + out.frame_horizon_s)).squaredNorm());
    }
  }
  out.jumps = pf ? 0 : oracle ? corners.size() : ctrl.filter().jumps();
  out.region_dropped = pf ? false : oracle ? oracle->regionDropped() : ctrl.filter().regionDropped();
  if (!pf && !oracle) std::tie(out.min_samples, out.corner_sigma) = cornerSettings(ctrl.filter());
  out.rmse_measured_cm = 100.0 * Vector2d(mx.rms(), my.rms());
  out.rmse_filtered_cm = 100.0 * Vector2d(fx_.rms(), fy_.rms());
  out.rmse_predicted_cm = 100.0 * Vector2d(px_.rms(), py_.rms());
  out.predicted_error_px = std::hypot(px_.rms(), py_.rms()) * cfg.fx / cfg.screen_distance;
  out.frame_predicted_error_px = frame_p.rms() * cfg.fx / cfg.screen_distance;
  return out;
}

PanTiltComparison runPanTiltComparison(const PanTiltScenarioConfig& config, std::uint64_t seed,
                                       const PanTiltFrameSink& sink, io::LogDirectory* log,
                                       const std::function<void(double)>& progress) {
  PanTiltComparison c;
  c.seed = seed;
  c.path = pathShapeName(config.path.shape);
  const double share = config.run_baseline ? 0.5 : 1.0;
  c.ours = runPanTilt(config, seed, PanTiltControllerKind::Predictive, sink, log,
                      progress ? std::function<void(double)>([&](double f) { progress(share * f); }) : nullptr);
  if (config.run_baseline) {
    c.baseline = runPanTilt(config, seed, PanTiltControllerKind::Baseline, sink, log,
                            progress ? std::function<void(double)>([&](double f) { progress(0.5 + 0.5 * f); }) : nullptr);
    c.has_baseline = true;
  }
  return c;
}

nlohmann::json PanTiltComparison::toJson(const PanTiltScenarioConfig& cfg) const {
  nlohmann::json j;
  auto xy = [](const Vector2d& v) {
    return nlohmann::json{{"x", std::isfinite(v.x()) ? nlohmann::json(v.x()) : nlohmann::json()},
                          {"y", std::isfinite(v.y()) ? nlohmann::json(v.y()) : nlohmann::json()}};
  };
  j["scenario"] = "pan_tilt";
  j["path"] = path;
  j["seed"] = seed;
  j["duration_s"] = cfg.duration;
  j["metrics_start_s"] = cfg.metrics_start;
  j["camera"] = {{"width", cfg.image_width}, {"height", cfg.image_height}, {"fx", cfg.fx}, {"fy", cfg.fy}, {"fps", cfg.fps}};
  j["path_speed_m_s"] = cfg.path.speed;
  j["filter_model"] = control::toString(cfg.control.filter.model);
  j["servo_gain"] = cfg.control.servo.gain;  // the baseline's (and ours unless predictive_gain is set)
  j["predictive_gain"] = cfg.control.gain > 0.0 ? cfg.control.gain : cfg.control.servo.gain;
  j["rig"] = cfg.rig_folder;
  j["noise_definition"] =
      "per axis, white Gaussian noise with std = measurement_noise_fraction x (max - min)/2 of the true path "
      "along that axis, added to the measured target position on the screen plane";
  j["noise_fraction"] = cfg.noise_fraction;
  j["noise_sigma_cm"] = xy(ours.noise_sigma_cm);
  j["rmse_measured_cm"] = xy(ours.rmse_measured_cm);
  j["rmse_filtered_cm"] = xy(ours.rmse_filtered_cm);
  const TTable1Row t = tTable1(cfg.path.shape);
  if (t.available) {
    j["t_table1"] = {{"rmse_measured_cm", xy(t.measured)}, {"rmse_kalman_cm", xy(t.kalman)}};
    j["target_rmse_filtered_cm_max"] = xy(0.5 * t.kalman);
    j["meets_filtered_target"] =
        ours.rmse_filtered_cm.x() <= 0.5 * t.kalman.x() && ours.rmse_filtered_cm.y() <= 0.5 * t.kalman.y();
  }
  j["image_error_rms_px"] = ours.image_error_rms_px;
  if (has_baseline) {
    j["baseline_image_error_rms_px"] = baseline.image_error_rms_px;
    j["image_error_ratio_to_baseline"] = ours.image_error_rms_px / baseline.image_error_rms_px;
  }
  j["reacquired_after_occlusion"] = ours.reacquired;
  j["reacquisition_delay_s"] = std::isfinite(ours.reacquisition_delay_s) ? nlohmann::json(ours.reacquisition_delay_s) : nlohmann::json();
  j["commands_outside_limits"] = ours.unsafe_commands + ours.rate_violations + ours.limit_hits +
                                 (has_baseline ? baseline.unsafe_commands + baseline.rate_violations + baseline.limit_hits : 0);
  j["ours"] = ours.toJson();
  if (has_baseline) j["baseline"] = baseline.toJson();
  return j;
}

}  // namespace viewline::scenarios
