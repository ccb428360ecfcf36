#include "viewline/scenarios/ball_catching/config.h"

#include <cmath>

#include "viewline/core/error.h"
#include "viewline/core/frames.h"
#include "viewline/io/camera_fields.h"
#include "viewline/scenarios/ball_catching/recording.h"
#include "viewline/scenarios/simulated_rig.h"

namespace viewline::scenarios {

using core::InvalidInput;
using Vector6 = Eigen::Matrix<double, 6, 1>;

namespace {

// ViSP's back-projection coefficient kdu (x = x_d (1 + kdu r_d²)) fitted by least squares to the
// exact inverse of the forward kud model over the image (same idea as calib::fitKdu).
double fitKdu(double px, double py, double u0, double v0, double kud, unsigned w, unsigned h) {
  if (kud == 0.0) return 0.0;
  double num = 0.0, den = 0.0;
  for (int i = 0; i <= 20; ++i)
    for (int j = 0; j <= 20; ++j) {
      const double x = ((w - 1.0) * i / 20.0 - u0) / px, y = ((h - 1.0) * j / 20.0 - v0) / py;
      const double r2 = x * x + y * y;
      const double xd = x * (1 + kud * r2), yd = y * (1 + kud * r2);
      const double rd2 = xd * xd + yd * yd;
      num += (x - xd) * xd * rd2 + (y - yd) * yd * rd2;
      den += (xd * rd2) * (xd * rd2) + (yd * rd2) * (yd * rd2);
    }
  return den > 0.0 ? num / den : 0.0;
}

core::Camera makeCamera(const CatchCameraConfig& c) {
  core::Camera cam;
  cam.name = c.name;
  cam.width = c.width;
  cam.height = c.height;
  const vpCameraParameters base = core::intrinsicsFromFov(c.hfov_rad, c.width, c.height);
  const double u0 = c.cx >= 0.0 ? c.cx : base.get_u0();
  const double v0 = c.cy >= 0.0 ? c.cy : base.get_v0();
  if (c.kud != 0.0) {
    cam.intrinsics.initPersProjWithDistortion(base.get_px(), base.get_py(), u0, v0, c.kud,
                                              fitKdu(base.get_px(), base.get_py(), u0, v0, c.kud, c.width, c.height));
  } else {
    cam.intrinsics.initPersProjWithoutDistortion(base.get_px(), base.get_py(), u0, v0);
  }
  cam.c_M_w = core::lookAt(c.position, c.look_at, Eigen::Vector3d::UnitZ());
  return cam;
}

vision::ColorRange readHsv(const io::ConfigNode& n, const char* key) {
  const auto v = n.get<std::vector<int>>(key);
  if (v.size() != 6) n.fail(key, "[hue_lo, hue_hi, s_lo, s_hi, v_lo, v_hi]");
  return {v[0], v[1], v[2], v[3], v[4], v[5]};
}

// One camera: the clock and imaging keys always, the geometry from the rig or from the keys.
CatchCameraConfig readCamera(const io::ConfigNode& n, const std::optional<SimulatedRig>& rig) {
  CatchCameraConfig k;
  k.name = n.get<std::string>("name");
  if (rig) {
    // Geometry comes from the rig: the truth renders, the calibration estimates.
    io::refuseGeometryWithRig(n, rig->folder);
    try {
      k.true_camera = rig->trueCamera(k.name);
      k.calibrated_camera = rig->calibratedCamera(k.name);
    } catch (const InvalidInput& e) {
      n.fail("name", std::string("a camera of the rig: ") + e.what());
    }
    k.width = k.true_camera->width;
    k.height = k.true_camera->height;
  } else {
    io::PinholeFields f;
    f.width = k.width;
    f.height = k.height;
    f.hfov_rad = k.hfov_rad;
    io::readPinholeFields(n, f);
    if (!f.position) n.fail("position", "the camera centre and a look_at point, m (or a rig:)");
    k.width = f.width;
    k.height = f.height;
    k.hfov_rad = f.hfov_rad;
    k.cx = f.cx.value_or(-1.0);
    k.cy = f.cy.value_or(-1.0);
    k.kud = f.kud;
    k.position = *f.position;
    k.look_at = *f.look_at;
  }
  k.source = runtime::readSourceConfig(n);  // absent: sim (the rendered camera)
  if (k.source.kind == runtime::SourceKind::Recording)
    throw core::InvalidInput(n.location("source") + ": cameras[].source.kind recording is not a camera's source (a "
                             "recording holds every camera of a throw: the top-level source: {kind: recording})");
  k.rate_hz = n.getOr<double>("rate_hz", k.rate_hz);
  k.drift = n.getOr<double>("clock_drift", k.drift);
  k.exposure_s = n.getOr<double>("exposure_s", k.exposure_s);
  k.blur_samples = n.getOr<int>("blur_samples", k.blur_samples);
  k.noise_sigma = n.getOr<double>("noise_sigma", k.noise_sigma);
  k.drop_probability = n.getOr<double>("drop_probability", k.drop_probability);
  k.trigger_jitter_s = n.getOr<double>("trigger_jitter_s", k.trigger_jitter_s);
  k.stamp_jitter_s = n.getOr<double>("stamp_jitter_s", k.stamp_jitter_s);
  return k;
}

void readThrows(const io::ConfigNode& t, BallCatchingConfig& c) {
  c.throws.release_min = t.getOr<Eigen::Vector3d>("release_min", c.throws.release_min);
  c.throws.release_max = t.getOr<Eigen::Vector3d>("release_max", c.throws.release_max);
  c.throws.aim_radius = t.getOr<double>("aim_radius", c.throws.aim_radius);
  c.throws.speed_min = t.getOr<double>("speed_min", c.throws.speed_min);
  c.throws.speed_max = t.getOr<double>("speed_max", c.throws.speed_max);
  c.throws.body.mass = t.getOr<double>("ball_mass", c.throws.body.mass);
  c.throws.body.reference_radius = t.getOr<double>("ball_radius", c.throws.body.reference_radius);
  c.throws.body.drag_coefficient = t.getOr<double>("drag_coefficient", c.throws.body.drag_coefficient);
  c.throws.body.air_density = t.getOr<double>("air_density", c.throws.body.air_density);
  c.ball_albedo_bgr = t.getOr<Eigen::Vector3d>("ball_albedo_bgr", c.ball_albedo_bgr);
  c.object = t.getChoiceOr("object", {"ball", "dart"}, c.object);
}

void readRobot(const io::ConfigNode& r, BallCatchingConfig& c) {
  const std::string kind = r.getChoice("kind", {"stage", "arm"});
  c.robot.kind = kind == "arm" ? robots::CartesianBackEnd::Arm : robots::CartesianBackEnd::Stage;
  c.robot.limits.v_max = Eigen::Vector3d::Constant(r.getOr<double>("v_max", 0.5));
  c.robot.limits.a_max = Eigen::Vector3d::Constant(r.getOr<double>("a_max", 13.0));
  c.robot.limits.norm = r.getChoiceOr("limit_norm", {"euclidean", "per_axis"}, std::string("euclidean")) == "per_axis"
                            ? robots::LimitNorm::PerAxis
                            : robots::LimitNorm::Euclidean;
  c.robot.latency = r.getOr<double>("latency_s", c.robot.latency);
  c.control_period = r.getOr<double>("control_period_s", c.control_period);
  c.robot.home = r.getOr<Eigen::Vector3d>("home", Eigen::Vector3d(4.0, 0.0, 1.1));
  c.robot.workspace_min = r.getOr<Eigen::Vector3d>("workspace_min", c.robot.home + Eigen::Vector3d(-0.1, -0.6, -0.5));
  c.robot.workspace_max = r.getOr<Eigen::Vector3d>("workspace_max", c.robot.home + Eigen::Vector3d(0.1, 0.6, 0.6));
  if (r.has("arm")) {
    const auto a = r.child("arm");
    Eigen::Isometry3d M = Eigen::Isometry3d::Identity();
    M.translation() = a.get<Eigen::Vector3d>("base_position");
    M.linear() = core::rotation(Eigen::Vector3d::UnitZ(), a.getAngleOr("base_yaw_deg", 0.0));
    c.robot.w_M_base = M;
    c.robot.tool_offset = a.getOr<Eigen::Vector3d>("tool_offset", c.robot.tool_offset);
    c.robot.joint_margin = a.getAngleOr("joint_margin_deg", c.robot.joint_margin);
  } else if (c.robot.kind == robots::CartesianBackEnd::Arm) {
    r.fail("arm", "an arm section (base_position, base_yaw_deg, tool_offset) for kind: arm");
  }
}

void readDetector(const io::ConfigNode& d, BallCatchingConfig& c) {
  if (d.has("hsv")) c.detector.hsv = readHsv(d, "hsv");
  c.detector.min_area_px = d.getOr<double>("min_area_px", c.detector.min_area_px);
  c.detector.noise_area_px = d.getOr<double>("noise_area_px", c.detector.noise_area_px);
  c.detector.min_roundness = d.getOr<double>("min_roundness", c.detector.min_roundness);
  c.detector.roi_half_size_px = d.getOr<double>("roi_half_size_px", c.detector.roi_half_size_px);
  c.detector.open_kernel_px = d.getOr<int>("open_kernel_px", c.detector.open_kernel_px);
  c.detector.close_kernel_px = d.getOr<int>("close_kernel_px", c.detector.close_kernel_px);
  c.sigma_px_floor = d.getOr<double>("sigma_px_floor", c.sigma_px_floor);
  c.sigma_px = d.getOr<double>("sigma_px", c.sigma_px);
  c.pixel_noise_px = d.getOr<double>("pixel_noise_px", c.pixel_noise_px);
}

void readTracker(const io::ConfigNode& t, tracking::TrackerConfig& k, double& unregistered_bias_sigma_px) {
  Vector6 m = k.prior_mean;
  m.head<3>() = t.getOr<Eigen::Vector3d>("prior_position", Eigen::Vector3d(2.0, 0.0, 1.4));
  m.tail<3>() = t.getOr<Eigen::Vector3d>("prior_velocity", Eigen::Vector3d(7.5, 0.0, 0.0));
  k.prior_mean = m;
  const double sp = t.getOr<double>("prior_std_position", 10.0), sv = t.getOr<double>("prior_std_velocity", 10.0);
  k.prior_cov.setZero();
  k.prior_cov.diagonal() << Eigen::Vector3d::Constant(sp * sp), Eigen::Vector3d::Constant(sv * sv);
  k.model.accel_psd = t.getOr<double>("accel_psd", 0.5);
  k.gate.kind = tracking::gateKindFromString(t.getOr<std::string>("gate", "mahalanobis"), "tracker.gate");
  k.gate.directional_p = t.getOr<double>("directional_p", k.gate.directional_p);
  k.gate.mahalanobis_alpha = t.getOr<double>("mahalanobis_alpha", k.gate.mahalanobis_alpha);
  k.restart_after_rejections = t.getOr<int>("restart_after_rejections", k.restart_after_rejections);
  k.max_coast = t.getOr<double>("max_coast_s", k.max_coast);
  k.refit_young_tracks = t.getOr<int>("refit_young_tracks", k.refit_young_tracks);
  if (t.has("pixel_bias")) {
    const auto b = t.child("pixel_bias");
    k.pixel_bias.sigma_px = b.getOr<double>("sigma_px", k.pixel_bias.sigma_px);
    k.pixel_bias.time_constant_s = b.getOr<double>("time_constant_s", k.pixel_bias.time_constant_s);
    unregistered_bias_sigma_px = b.getOr<double>("unregistered_sigma_px", unregistered_bias_sigma_px);
  }
}

void readPlanner(const io::ConfigNode& p, planning::CatchPlannerConfig& k) {
  const std::string model = p.getChoiceOr("model", {"drag", "ballistic"}, "drag");
  k.model.kind = model == "drag" ? planning::FlightModel::Drag : planning::FlightModel::Ballistic;
  k.model.accel_psd = p.getOr<double>("accel_psd", 0.0);
  k.start_sigma = p.getOr<double>("start_sigma_m", k.start_sigma);
  k.commit_sigma = p.getOr<double>("commit_sigma_m", k.commit_sigma);
  k.commit_min_updates = p.getOr<int>("commit_min_updates", k.commit_min_updates);
  k.give_up = p.getOr<bool>("give_up", k.give_up);
  k.give_up_late = p.getOr<double>("give_up_late_s", k.give_up_late);
  k.give_up_sigmas = p.getOr<double>("give_up_sigmas", k.give_up_sigmas);
  k.home_delay = p.getOr<double>("home_delay_s", k.home_delay);
  k.min_lead = p.getOr<double>("min_lead_s", k.min_lead);
  k.target_prior_std = p.getOr<double>("target_prior_std_m", k.target_prior_std);
  k.move_sigmas = p.getOr<double>("move_sigmas", k.move_sigmas);
}

void readRegistration(const io::ConfigNode& r, CatchRegistration& g) {
  g.enabled = r.getOr<bool>("enabled", g.enabled);
  g.marker_offset = r.getOr<Eigen::Vector3d>("marker_offset", g.marker_offset);
  g.marker_radius = r.getOr<double>("marker_radius", g.marker_radius);
  g.marker_albedo_bgr = r.getOr<Eigen::Vector3d>("marker_albedo_bgr", g.marker_albedo_bgr);
  if (r.has("marker_hsv")) g.marker_hsv = readHsv(r, "marker_hsv");
  g.offsets_x = r.getOr<std::vector<double>>("offsets_x", g.offsets_x);
  g.offsets_y = r.getOr<std::vector<double>>("offsets_y", g.offsets_y);
  g.offsets_z = r.getOr<std::vector<double>>("offsets_z", g.offsets_z);
  if (!(g.marker_radius > 0.0)) r.fail("marker_radius", "a positive radius, m");
  g.min_points = r.getOr<int>("min_points", g.min_points);
  g.gate_px = r.getOr<double>("gate_px", g.gate_px);
  g.max_rms_px = r.getOr<double>("max_rms_px", g.max_rms_px);
  g.max_shift_m = r.getOr<double>("max_shift_m", g.max_shift_m);
  g.max_rotation_rad = r.getAngleOr("max_rotation_deg", g.max_rotation_rad);
  g.robot_position_error_m = r.getOr<double>("robot_position_error_m", g.robot_position_error_m);
  if (g.min_points < 6) r.fail("min_points", "at least 6 (a camera pose from its marker points)");
  if (!(std::isfinite(g.robot_position_error_m) && g.robot_position_error_m >= 0.0))
    r.fail("robot_position_error_m", "a finite std >= 0, m");
}

}  // namespace

core::Camera CatchCameraConfig::renderCamera() const { return true_camera ? *true_camera : makeCamera(*this); }
core::Camera CatchCameraConfig::estimatorCamera() const {
  return calibrated_camera ? *calibrated_camera : makeCamera(*this);
}

Eigen::Matrix3d boxRotation(const Eigen::Vector3d& n) {
  Eigen::Matrix3d R;
  R.col(2) = n;
  Eigen::Vector3d x = Eigen::Vector3d::UnitZ().cross(n);
  if (x.norm() < 1e-6) x = Eigen::Vector3d::UnitX();
  R.col(0) = x.normalized();
  R.col(1) = R.col(2).cross(R.col(0));
  return R;
}

tracking::TrackerConfig BallCatchingConfig::trackerConfig() const {
  tracking::TrackerConfig t = tracker;
  if (!t.pixel_bias.enabled() || unregistered_bias_sigma_px <= 0.0) return t;
  t.pixel_bias.camera_sigma_px.clear();
  for (std::size_t i = 0; i < activeCameras(); ++i)
    t.pixel_bias.camera_sigma_px.push_back(cameras[i].registered ? t.pixel_bias.sigma_px : unregistered_bias_sigma_px);
  return t;
}

planning::CatchPlannerConfig BallCatchingConfig::plannerConfig() const {
  planning::CatchPlannerConfig p = planner;
  p.home = robot.home;
  p.normal = box_normal;
  p.model.gravity_w = sim::gravityWorld();
  p.model.drag_k = throws.body.dragPerMass();  // the ball is known: same ball every throw
  return p;
}

bool BallCatchingConfig::onFootage() const {
  for (std::size_t i = 0; i < activeCameras() && i < cameras.size(); ++i)
    if (!cameras[i].source.simulated()) return true;
  return false;
}

void BallCatchingConfig::validate() const {
  if (cameras.empty()) throw InvalidInput("cameras: expected at least one camera");
  if (!(unregistered_bias_sigma_px >= 0.0) || !std::isfinite(unregistered_bias_sigma_px))
    throw InvalidInput("tracker.pixel_bias.unregistered_sigma_px: expected a finite number >= 0");
  if (camera_count > cameras.size()) throw InvalidInput("camera_count: more than the cameras listed");
  if (onFootage()) {
    // One clock for the session: footage cannot be fused with a camera rendered on a throw's clock.
    for (std::size_t i = 0; i < activeCameras(); ++i)
      if (cameras[i].source.simulated())
        throw InvalidInput("cameras[" + cameras[i].name + "].source: every active camera needs footage when one has "
                           "it (the rendered cameras run on a simulated throw's clock)");
    if (!source.simulated())
      throw InvalidInput("source: kind recording and cameras[].source footage are exclusive (one or the other)");
  }
  for (const auto& c : cameras) {
    if (!(c.rate_hz > 0.0)) throw InvalidInput("cameras[" + c.name + "].rate_hz: expected > 0");
    if (c.width == 0 || c.height == 0) throw InvalidInput("cameras[" + c.name + "].width/height: expected > 0");
    if (!(c.hfov_rad > 0.0 && c.hfov_rad < 3.0)) throw InvalidInput("cameras[" + c.name + "].hfov_deg: expected (0, 170)");
  }
  if (!(rate_override_hz >= 0.0 && std::isfinite(rate_override_hz)))
    throw InvalidInput("rate_override_hz: expected >= 0 (0: each camera's rate_hz)");
  if (!(throws.speed_min > 0.0 && throws.speed_max >= throws.speed_min))
    throw InvalidInput("throws.speed_min/speed_max: expected 0 < min <= max");
  if (!(throws.aim_radius >= 0.0)) throw InvalidInput("throws.aim_radius: expected >= 0");
  for (int i = 0; i < 3; ++i)
    if (!(throws.release_min(i) <= throws.release_max(i))) throw InvalidInput("throws.release_min: expected <= release_max");
  if (object != "ball" && object != "dart") throw InvalidInput("throws.object: expected ball or dart");
  if (!(std::abs(box_normal.norm() - 1.0) < 1e-9)) throw InvalidInput("box.normal: expected a unit vector");
  if (!(hole_radius > throws.body.reference_radius))
    throw InvalidInput("box.hole_radius: expected larger than the ball radius");
  if (!(control_period > 0.0)) throw InvalidInput("robot.control_period_s: expected > 0");
  if (!(processing_latency >= 0.0)) throw InvalidInput("processing_latency_s: expected >= 0");
  if (!(sigma_px_floor > 0.0)) throw InvalidInput("detector.sigma_px_floor: expected > 0");
  if (!(sigma_px >= 0.0 && std::isfinite(sigma_px))) throw InvalidInput("detector.sigma_px: expected a finite value >= 0");
  if (!(pixel_noise_px >= 0.0 && std::isfinite(pixel_noise_px)))
    throw InvalidInput("detector.pixel_noise_px: expected a finite value >= 0");
  if (threads < 1) throw InvalidInput("threads: expected >= 1");
  if (flight_fit.min_images < (flight_fit.hasPrior() ? 1 : 6))
    throw InvalidInput("flight_fit.min_images: expected >= 6 (six unknowns) without a prior, >= 1 with one");
  if (flight_fit.prior_std.minCoeff() < 0.0 || !flight_fit.prior_std.allFinite() || !flight_fit.prior_mean.allFinite())
    throw InvalidInput("flight_fit.prior_*: expected finite values, stds >= 0");
  if (!(flight_fit.aim_prior_std >= 0.0 && std::isfinite(flight_fit.aim_prior_std)))
    throw InvalidInput("flight_fit.aim_prior_std_m: expected a finite value >= 0");
  if (flight_fit.min_cameras < 1) throw InvalidInput("flight_fit.min_cameras: expected >= 1");
  if (flight_fit.max_iterations < 1) throw InvalidInput("flight_fit.max_iterations: expected >= 1");
  robot.validate();
  tracker.validate();
  plannerConfig().validate();
  detector.validate();
}

BallCatchingConfig loadBallCatchingConfig(const io::ConfigNode& root) {
  BallCatchingConfig c;
  c.faults = runtime::readFaultPlanConfig(root);  // first: the config reference's probe reaches it
  c.name = root.getOr<std::string>("name", c.name);
  c.source = readCatchSource(root);  // sim or a recording (ball_catching/recording.h)
  c.threads = root.getOr<int>("threads", c.threads);
  c.processing_latency = root.getOr<double>("processing_latency_s", c.processing_latency);
  c.camera_count = root.getOr<unsigned>("camera_count", 0u);
  c.rate_override_hz = root.getOr<double>("rate_override_hz", 0.0);
  std::optional<SimulatedRig> rig;
  if (root.has("rig")) {
    rig = loadSimulatedRig(root, "rig");
    c.rig = rig->folder;
  }
  for (const auto& n : root.childList("cameras")) c.cameras.push_back(readCamera(n, rig));
  c.true_cameras = root.getOr<bool>("true_cameras", false);
  if (c.true_cameras) {
    if (!rig) root.fail("true_cameras", "a rig: (inline cameras are already the simulator's own)");
    for (auto& k : c.cameras) k.calibrated_camera = k.true_camera;
  }
  // Sensor noise of every camera at once (the noise table): < 0 keeps each camera's noise_sigma.
  const double noise = root.getOr<double>("noise_sigma_override", -1.0);
  if (noise >= 0.0)
    for (auto& k : c.cameras) k.noise_sigma = noise;
  if (root.has("throws")) readThrows(root.child("throws"), c);
  if (root.has("box")) {
    const auto b = root.child("box");
    c.hole_radius = b.getOr<double>("hole_radius", c.hole_radius);
    c.box_normal = b.getOr<Eigen::Vector3d>("normal", c.box_normal);
    if (!c.box_normal.allFinite() || c.box_normal.norm() < 1e-9) b.fail("normal", "a non-zero vector");
    c.box_size = b.getOr<double>("size", c.box_size);
    c.render_box = b.getOr<bool>("render", c.render_box);
  }
  c.box_normal.normalize();
  readRobot(root.child("robot"), c);
  c.robot.w_R_box = boxRotation(c.box_normal);  // the arm holds the box front towards the thrower
  if (root.has("detector")) readDetector(root.child("detector"), c);
  if (root.has("tracker")) {
    readTracker(root.child("tracker"), c.tracker, c.unregistered_bias_sigma_px);
  } else {
    c.tracker.prior_mean << 2.0, 0.0, 1.4, 7.5, 0.0, 0.0;
    c.tracker.model.accel_psd = 0.5;
  }
  c.tracker.model.gravity_w = sim::gravityWorld();
  if (root.has("planner")) readPlanner(root.child("planner"), c.planner);
  if (root.has("registration")) readRegistration(root.child("registration"), c.registration);
  if (c.true_cameras && c.registration.enabled)
    root.fail("true_cameras", "registration.enabled: false as well (the registration would move the true cameras)");
  if (root.has("flight_fit")) {
    const auto f = root.child("flight_fit");
    c.flight_fit.enabled = f.getOr<bool>("enabled", c.flight_fit.enabled);
    c.flight_fit.min_images = f.getOr<int>("min_images", c.flight_fit.min_images);
    c.flight_fit.min_cameras = f.getOr<int>("min_cameras", c.flight_fit.min_cameras);
    c.flight_fit.max_iterations = f.getOr<int>("max_iterations", c.flight_fit.max_iterations);
    FlightFitConfig& ff = c.flight_fit;
    ff.prior_mean.head<3>() = f.getOr<Eigen::Vector3d>("prior_position", ff.prior_mean.head<3>());
    ff.prior_mean.tail<3>() = f.getOr<Eigen::Vector3d>("prior_velocity", ff.prior_mean.tail<3>());
    ff.prior_std.head<3>() = f.getOr<Eigen::Vector3d>("prior_std_position", ff.prior_std.head<3>());
    ff.prior_std.tail<3>() = f.getOr<Eigen::Vector3d>("prior_std_velocity", ff.prior_std.tail<3>());
    ff.aim_prior_std = f.getOr<double>("aim_prior_std_m", ff.aim_prior_std);
  }
  if (root.has("render")) {
    const auto r = root.child("render");
    c.render.supersampling = r.getOr<int>("supersampling", c.render.supersampling);
    c.post_crossing_s = r.getOr<double>("post_crossing_s", c.post_crossing_s);
    c.prediction_lead_s = r.getOr<double>("prediction_lead_s", c.prediction_lead_s);
  }
  if (root.has("room")) {
    const auto r = root.child("room");
    c.room.walls = r.getOr<bool>("walls", c.room.walls);
    c.room.floor_size = r.getOr<double>("floor_size", c.room.floor_size);
  }
  root.finish();
  c.validate();
  return c;
}

}  // namespace viewline::scenarios
