#include "viewline/scenarios/ball_catching.h"

#include <algorithm>
#include <atomic>
#include <chrono>
#include <cmath>
#include <deque>
#include <memory>
#include <mutex>
#include <thread>
#include <opencv2/calib3d.hpp>
#include <opencv2/core/eigen.hpp>

#include "viewline/core/checks.h"
#include "viewline/core/error.h"
#include "viewline/core/frames.h"
#include "viewline/core/random.h"
#include "viewline/scenarios/simulated_rig.h"
#include "viewline/sim/rig.h"

namespace viewline::scenarios {

using core::InvalidInput;
using Vector6 = Eigen::Matrix<double, 6, 1>;

namespace {

constexpr const char* kMissReasons[] = {"late", "off_target", "lost_track", "not_reachable"};

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

}  // namespace

core::Camera CatchCameraConfig::renderCamera() const { return true_camera ? *true_camera : makeCamera(*this); }
core::Camera CatchCameraConfig::estimatorCamera() const {
  return calibrated_camera ? *calibrated_camera : makeCamera(*this);
}

namespace {

Eigen::Matrix3d boxRotation(const Eigen::Vector3d& n) {
  Eigen::Matrix3d R;
  R.col(2) = n;
  Eigen::Vector3d x = Eigen::Vector3d::UnitZ().cross(n);
  if (x.norm() < 1e-6) x = Eigen::Vector3d::UnitX();
  R.col(0) = x.normalized();
  R.col(1) = R.col(2).cross(R.col(0));
  return R;
}

double percentile(std::vector<double> v, double q) {
  if (v.empty()) return std::nan("");
  std::sort(v.begin(), v.end());
  const double pos = q * static_cast<double>(v.size() - 1);
  const auto i = static_cast<std::size_t>(std::floor(pos));
  const double f = pos - static_cast<double>(i);
  return i + 1 < v.size() ? v[i] * (1 - f) + v[i + 1] * f : v[i];
}

// The box with its hole centred on `hole`, and the registration marker on its top.
void appendBox(const BallCatchingConfig& cfg, const Eigen::Matrix3d& R, const Eigen::Vector3d& hole,
               std::vector<sim::Primitive>& out) {
  const Eigen::Vector3d& n = cfg.box_normal;
  Eigen::Isometry3d M = Eigen::Isometry3d::Identity();
  M.linear() = R;
  M.translation() = hole - n * (0.5 * cfg.box_size);
  out.push_back(sim::makeBox("box", M, Eigen::Vector3d::Constant(cfg.box_size), Eigen::Vector3d(0.7, 0.72, 0.7)));
  M.translation() = hole + n * 1e-3;
  out.push_back(sim::makeDisc("hole", M, cfg.hole_radius, Eigen::Vector3d(0.04, 0.04, 0.04)));
  if (cfg.registration.enabled)
    out.push_back(sim::makeSphere("marker", hole + cfg.registration.marker_offset, cfg.registration.marker_radius,
                                  cfg.registration.marker_albedo_bgr));
}

// The room and the box held still with its hole at `hole` (registration).
class StaticBoxWorld : public sim::World {
public:
  StaticBoxWorld(const sim::Scene& room, const BallCatchingConfig& cfg, const Eigen::Vector3d& hole)
      : room_(room), cfg_(cfg), hole_(hole), R_(boxRotation(cfg.box_normal)) {}
  const sim::Scene& staticScene() const override { return room_; }
  void dynamicObjects(double, std::vector<sim::Primitive>& out) const override { appendBox(cfg_, R_, hole_, out); }

private:
  const sim::Scene& room_;
  const BallCatchingConfig& cfg_;
  Eigen::Vector3d hole_;
  Eigen::Matrix3d R_;
};

// The world of one throw: the room, the ball on its flight, the box at the robot's hole position.
class CatchWorld : public sim::World {
public:
  CatchWorld(const sim::Scene& room, const sim::DragFlight& flight, const BallCatchingConfig& cfg,
             const robots::CartesianRobot& robot)
      : room_(room), flight_(flight), cfg_(cfg), robot_(robot), R_(boxRotation(cfg.box_normal)) {}
  const sim::Scene& staticScene() const override { return room_; }
  void dynamicObjects(double t, std::vector<sim::Primitive>& out) const override {
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

private:
  const sim::Scene& room_;
  const sim::DragFlight& flight_;
  const BallCatchingConfig& cfg_;
  const robots::CartesianRobot& robot_;
  Eigen::Matrix3d R_;
};

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

// ------------------------------------------------------------------------------------------------
// Config

void BallCatchingConfig::finalize() {
  if (!box_normal.allFinite() || box_normal.norm() < 1e-9) throw InvalidInput("box.normal: expected a non-zero vector");
  box_normal.normalize();
  robot.w_R_box = boxRotation(box_normal);
  planner.home = robot.home;
  planner.normal = box_normal;
  planner.limits = robot.limits;
  planner.latency = robot.latency;
  planner.model.gravity_w = sim::gravityWorld();
  planner.model.drag_k = throws.body.dragPerMass();  // the ball is known: same ball every throw
  tracker.model.gravity_w = sim::gravityWorld();
}

void BallCatchingConfig::validate() const {
  if (cameras.empty()) throw InvalidInput("cameras: expected at least one camera");
  if (camera_count > cameras.size()) throw InvalidInput("camera_count: more than the cameras listed");
  for (const auto& c : cameras) {
    if (!(c.rate_hz > 0.0)) throw InvalidInput("cameras[" + c.name + "].rate_hz: expected > 0");
    if (c.width == 0 || c.height == 0) throw InvalidInput("cameras[" + c.name + "].width/height: expected > 0");
    if (!(c.hfov_rad > 0.0 && c.hfov_rad < 3.0)) throw InvalidInput("cameras[" + c.name + "].hfov_deg: expected (0, 170)");
  }
  if (!(throws.speed_min > 0.0 && throws.speed_max >= throws.speed_min))
    throw InvalidInput("throws.speed_min/speed_max: expected 0 < min <= max");
  if (!(throws.aim_radius >= 0.0)) throw InvalidInput("throws.aim_radius: expected >= 0");
  for (int i = 0; i < 3; ++i)
    if (!(throws.release_min(i) <= throws.release_max(i))) throw InvalidInput("throws.release_min: expected <= release_max");
  if (object != "ball" && object != "dart") throw InvalidInput("throws.object: expected ball or dart");
  if (!(hole_radius > throws.body.reference_radius))
    throw InvalidInput("box.hole_radius: expected larger than the ball radius");
  if (!(control_period > 0.0)) throw InvalidInput("robot.control_period_s: expected > 0");
  if (!(processing_latency >= 0.0)) throw InvalidInput("processing_latency_s: expected >= 0");
  if (!(sigma_px_floor > 0.0)) throw InvalidInput("detector.sigma_px_floor: expected > 0");
  if (!(pixel_noise_px >= 0.0 && std::isfinite(pixel_noise_px)))
    throw InvalidInput("detector.pixel_noise_px: expected a finite value >= 0");
  if (threads < 1) throw InvalidInput("threads: expected >= 1");
  robot.validate();
  tracker.validate();
  planner.validate();
  detector.validate();
}

namespace {

void readHsv(const io::ConfigNode& n, vision::ColorRange& r) {
  const auto v = n.get<std::vector<int>>("hsv");
  if (v.size() != 6) n.fail("hsv", "[hue_lo, hue_hi, s_lo, s_hi, v_lo, v_hi]");
  r = {v[0], v[1], v[2], v[3], v[4], v[5]};
}

}  // namespace

BallCatchingConfig loadBallCatchingConfig(const io::ConfigNode& root) {
  BallCatchingConfig c;
  c.name = root.getOr<std::string>("name", c.name);
  c.threads = root.getOr<int>("threads", c.threads);
  c.processing_latency = root.getOr<double>("processing_latency_s", c.processing_latency);
  c.camera_count = root.getOr<unsigned>("camera_count", 0u);
  c.rate_override_hz = root.getOr<double>("rate_override_hz", 0.0);
  std::optional<SimulatedRig> rig;
  if (root.has("rig")) {
    rig = loadSimulatedRig(root, "rig");
    c.rig = rig->folder;
  }
  for (const auto& n : root.childList("cameras")) {
    CatchCameraConfig k;
    k.name = n.get<std::string>("name");
    if (rig) {
      // Geometry comes from the rig: the truth renders, the calibration estimates.
      for (const char* key : {"width", "height", "hfov_deg", "cx", "cy", "kud", "position", "look_at"})
        if (n.has(key)) n.fail(key, "no camera geometry with rig: (it comes from " + rig->folder + "/truth.yaml and rig.yaml)");
      try {
        k.true_camera = rig->trueCamera(k.name);
        k.calibrated_camera = rig->calibratedCamera(k.name);
      } catch (const InvalidInput& e) {
        n.fail("name", std::string("a camera of the rig: ") + e.what());
      }
      k.width = k.true_camera->width;
      k.height = k.true_camera->height;
    } else {
      k.width = n.getOr<unsigned>("width", k.width);
      k.height = n.getOr<unsigned>("height", k.height);
      k.hfov_rad = n.getAngleOr("hfov_deg", k.hfov_rad);
      k.cx = n.getOr<double>("cx", -1.0);
      k.cy = n.getOr<double>("cy", -1.0);
      k.kud = n.getOr<double>("kud", 0.0);
      k.position = n.get<Eigen::Vector3d>("position");
      k.look_at = n.get<Eigen::Vector3d>("look_at");
    }
    k.rate_hz = n.getOr<double>("rate_hz", k.rate_hz);
    k.drift = n.getOr<double>("clock_drift", k.drift);
    k.exposure_s = n.getOr<double>("exposure_s", k.exposure_s);
    k.blur_samples = n.getOr<int>("blur_samples", k.blur_samples);
    k.noise_sigma = n.getOr<double>("noise_sigma", k.noise_sigma);
    k.drop_probability = n.getOr<double>("drop_probability", k.drop_probability);
    k.trigger_jitter_s = n.getOr<double>("trigger_jitter_s", k.trigger_jitter_s);
    k.stamp_jitter_s = n.getOr<double>("stamp_jitter_s", k.stamp_jitter_s);
    c.cameras.push_back(k);
  }
  if (root.has("throws")) {
    const auto t = root.child("throws");
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
  if (root.has("box")) {
    const auto b = root.child("box");
    c.hole_radius = b.getOr<double>("hole_radius", c.hole_radius);
    c.box_normal = b.getOr<Eigen::Vector3d>("normal", c.box_normal);
    c.box_size = b.getOr<double>("size", c.box_size);
    c.render_box = b.getOr<bool>("render", c.render_box);
  }
  {
    const auto r = root.child("robot");
    const std::string kind = r.getChoice("kind", {"stage", "arm"});
    c.robot.kind = kind == "arm" ? robots::CartesianBackEnd::Arm : robots::CartesianBackEnd::Stage;
    c.robot.limits.v_max = Eigen::Vector3d::Constant(r.getOr<double>("v_max", 0.5));
    c.robot.limits.a_max = Eigen::Vector3d::Constant(r.getOr<double>("a_max", 13.0));
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
  if (root.has("detector")) {
    const auto d = root.child("detector");
    if (d.has("hsv")) readHsv(d, c.detector.hsv);
    c.detector.min_area_px = d.getOr<double>("min_area_px", c.detector.min_area_px);
    c.detector.noise_area_px = d.getOr<double>("noise_area_px", c.detector.noise_area_px);
    c.detector.min_roundness = d.getOr<double>("min_roundness", c.detector.min_roundness);
    c.detector.roi_half_size_px = d.getOr<double>("roi_half_size_px", c.detector.roi_half_size_px);
    c.detector.open_kernel_px = d.getOr<int>("open_kernel_px", c.detector.open_kernel_px);
    c.detector.close_kernel_px = d.getOr<int>("close_kernel_px", c.detector.close_kernel_px);
    c.sigma_px_floor = d.getOr<double>("sigma_px_floor", c.sigma_px_floor);
    c.pixel_noise_px = d.getOr<double>("pixel_noise_px", c.pixel_noise_px);
  }
  if (root.has("tracker")) {
    const auto t = root.child("tracker");
    Vector6 m = c.tracker.prior_mean;
    m.head<3>() = t.getOr<Eigen::Vector3d>("prior_position", Eigen::Vector3d(2.0, 0.0, 1.4));
    m.tail<3>() = t.getOr<Eigen::Vector3d>("prior_velocity", Eigen::Vector3d(7.5, 0.0, 0.0));
    c.tracker.prior_mean = m;
    const double sp = t.getOr<double>("prior_std_position", 10.0), sv = t.getOr<double>("prior_std_velocity", 10.0);
    c.tracker.prior_cov.setZero();
    c.tracker.prior_cov.diagonal() << Eigen::Vector3d::Constant(sp * sp), Eigen::Vector3d::Constant(sv * sv);
    c.tracker.model.accel_psd = t.getOr<double>("accel_psd", 0.5);
    c.tracker.gate.kind = tracking::gateKindFromString(t.getOr<std::string>("gate", "mahalanobis"), "tracker.gate");
    c.tracker.gate.directional_p = t.getOr<double>("directional_p", c.tracker.gate.directional_p);
    c.tracker.gate.mahalanobis_alpha = t.getOr<double>("mahalanobis_alpha", c.tracker.gate.mahalanobis_alpha);
    c.tracker.restart_after_rejections = t.getOr<int>("restart_after_rejections", c.tracker.restart_after_rejections);
    c.tracker.max_coast = t.getOr<double>("max_coast_s", c.tracker.max_coast);
    c.tracker.refit_young_tracks = t.getOr<int>("refit_young_tracks", c.tracker.refit_young_tracks);
  } else {
    c.tracker.prior_mean << 2.0, 0.0, 1.4, 7.5, 0.0, 0.0;
    c.tracker.model.accel_psd = 0.5;
  }
  if (root.has("planner")) {
    const auto p = root.child("planner");
    const std::string model = p.getChoiceOr("model", {"drag", "ballistic"}, "drag");
    c.planner.model.kind = model == "drag" ? planning::FlightModel::Drag : planning::FlightModel::Ballistic;
    c.planner.model.accel_psd = p.getOr<double>("accel_psd", 0.0);
    c.planner.start_sigma = p.getOr<double>("start_sigma_m", c.planner.start_sigma);
    c.planner.commit_sigma = p.getOr<double>("commit_sigma_m", c.planner.commit_sigma);
    c.planner.commit_min_updates = p.getOr<int>("commit_min_updates", c.planner.commit_min_updates);
    c.planner.give_up = p.getOr<bool>("give_up", c.planner.give_up);
    c.planner.give_up_late = p.getOr<double>("give_up_late_s", c.planner.give_up_late);
    c.planner.home_delay = p.getOr<double>("home_delay_s", c.planner.home_delay);
    c.planner.min_lead = p.getOr<double>("min_lead_s", c.planner.min_lead);
    c.planner.target_prior_std = p.getOr<double>("target_prior_std_m", c.planner.target_prior_std);
  }
  if (root.has("registration")) {
    const auto r = root.child("registration");
    CatchRegistration& g = c.registration;
    g.enabled = r.getOr<bool>("enabled", g.enabled);
    g.marker_offset = r.getOr<Eigen::Vector3d>("marker_offset", g.marker_offset);
    g.marker_radius = r.getOr<double>("marker_radius", g.marker_radius);
    g.marker_albedo_bgr = r.getOr<Eigen::Vector3d>("marker_albedo_bgr", g.marker_albedo_bgr);
    if (r.has("marker_hsv")) {
      const auto v = r.get<std::vector<int>>("marker_hsv");
      if (v.size() != 6) r.fail("marker_hsv", "[hue_lo, hue_hi, s_lo, s_hi, v_lo, v_hi]");
      g.marker_hsv = {v[0], v[1], v[2], v[3], v[4], v[5]};
    }
    g.offsets_x = r.getOr<std::vector<double>>("offsets_x", g.offsets_x);
    g.offsets_y = r.getOr<std::vector<double>>("offsets_y", g.offsets_y);
    g.offsets_z = r.getOr<std::vector<double>>("offsets_z", g.offsets_z);
    if (!(g.marker_radius > 0.0)) r.fail("marker_radius", "a positive radius, m");
    g.min_points = r.getOr<int>("min_points", g.min_points);
    g.gate_px = r.getOr<double>("gate_px", g.gate_px);
    g.max_rms_px = r.getOr<double>("max_rms_px", g.max_rms_px);
    g.max_shift_m = r.getOr<double>("max_shift_m", g.max_shift_m);
    g.max_rotation_rad = r.getAngleOr("max_rotation_deg", g.max_rotation_rad);
    if (g.min_points < 6) r.fail("min_points", "at least 6 (a camera pose from its marker points)");
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
  c.finalize();
  c.validate();
  return c;
}

// ------------------------------------------------------------------------------------------------
// One throw

ThrowResult runThrow(const BallCatchingConfig& cfg, const sim::Scene& room, int index, std::uint64_t seed,
                     const CatchHooks* hooks) {
  const auto wall0 = std::chrono::steady_clock::now();
  ThrowResult res;
  res.index = index;
  res.seed = seed;
  core::Rng rng = core::makeRng(seed);
  const Eigen::Vector3d& n = cfg.box_normal;
  const Eigen::Vector3d& home = cfg.robot.home;
  const double clearance = cfg.hole_radius - cfg.throws.body.reference_radius;
  io::LogDirectory* log = hooks ? hooks->log : nullptr;

  // 1. The throw.
  const ThrowDistribution& td = cfg.throws;
  Eigen::Vector3d release;
  for (int i = 0; i < 3; ++i) release(i) = core::uniform(rng, td.release_min(i), td.release_max(i));
  const double rho = td.aim_radius * std::sqrt(core::uniform(rng, 0.0, 1.0));
  const double phi = core::uniform(rng, 0.0, 2.0 * core::kPi);
  const Eigen::Matrix3d Rb = boxRotation(n);
  const Eigen::Vector3d aim = home + rho * (std::cos(phi) * Rb.col(0) + std::sin(phi) * Rb.col(1));
  const double speed = core::uniform(rng, td.speed_min, td.speed_max);
  Eigen::Vector3d d = aim - release;
  d.z() = 0.0;
  res.distance = std::abs(n.dot(aim - release));
  const double T = d.norm() / speed;
  const Eigen::Vector3d v0 = solveLaunchVelocity(release, aim, T, td.body);
  res.release = release;
  res.launch_velocity = v0;
  res.launch_speed = v0.norm();
  res.launch_elevation_deg = core::rad2deg(std::atan2(v0.z(), v0.head<2>().norm()));
  const sim::DragFlight flight({release, v0}, 0.0, T + cfg.post_crossing_s + 0.3, td.body);

  // True crossing of the plane through home (the hole's n-coordinate never changes: the planner
  // moves it in the plane; checked below against the robot's actual position).
  auto h = [&](double t) { return n.dot(flight.state(t).p - home); };
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
  res.t_cross = 0.5 * (ta + tb);
  res.cross_true = flight.state(res.t_cross).p;
  const double t_end = res.t_cross + cfg.post_crossing_s;

  // 2. Cameras (random phase per throw), robot, planner, tracker, detectors.
  const std::size_t ncam = cfg.camera_count > 0 ? cfg.camera_count : cfg.cameras.size();
  std::vector<sim::SimCamera> sims;
  std::vector<core::Camera> est_cams;
  for (std::size_t i = 0; i < ncam; ++i) {
    const CatchCameraConfig& c = cfg.cameras[i];
    sim::SimCamera sc;
    sc.camera = c.renderCamera();
    sc.clock.rate = cfg.rate_override_hz > 0.0 ? cfg.rate_override_hz : c.rate_hz;
    sc.clock.phase = core::uniform(rng, 0.0, 1.0 / sc.clock.rate);
    sc.clock.drift = c.drift;
    sc.effects.noise.sigma = c.noise_sigma;
    sc.effects.blur.exposure = c.exposure_s;
    sc.effects.blur.samples = c.blur_samples;
    sc.effects.faults.drop_probability = c.drop_probability;
    sc.effects.faults.trigger_jitter = c.trigger_jitter_s;
    sc.effects.faults.stamp_jitter = c.stamp_jitter_s;
    est_cams.push_back(c.estimatorCamera());  // calibrated (rig:) or the render camera (inline cameras)
    sims.push_back(std::move(sc));
  }
  sim::CameraRig rig(sims, rng, cfg.render);
  robots::SimulatedCartesianRobot robot(cfg.robot);
  robot.reset(0.0);
  planning::CatchPlanner planner(cfg.planner, [&robot](const Eigen::Vector3d& p) { return robot.reachable(p); });
  planner.reset(0.0, home);
  tracking::ViewlineTracker tracker(est_cams, cfg.tracker);
  std::vector<vision::BallDetector> detectors;
  for (const auto& c : est_cams) detectors.emplace_back(cfg.detector, c);
  CatchWorld world(room, flight, cfg, robot);

  struct Pending {
    double t_avail;
    estimation::StateEstimate est;
  };
  std::deque<Pending> pending;
  core::Rng noise_rng = core::makeRng(core::deriveSeed(seed, 0xD37));  // pixel_noise_px only
  std::optional<Eigen::Vector3d> lead_prediction;
  double t_tick = 0.0;
  std::uint64_t next_id = 1;
  io::CsvWriter no_log;
  io::CsvWriter& plan_log =
      log ? log->stream("plan", {"throw", "t", "sp_x", "sp_y", "sp_z", "sv_x", "sv_y", "sv_z", "phase"}) : no_log;
  auto streamUntil = [&](double t_limit) {
    while (t_tick <= t_limit) {
      while (!pending.empty() && pending.front().t_avail <= t_tick) {
        const auto u = planner.update(pending.front().t_avail, pending.front().est);
        if (u.crossing && pending.front().t_avail <= res.t_cross - cfg.prediction_lead_s) lead_prediction = u.crossing->p;
        if (log && u.crossing)
          log->stream("predictions", {"throw", "t", "t_cross", "x", "y", "z", "sigma_max", "sigma_t", "feasible", "phase"})
              .row({double(index), pending.front().t_avail, u.crossing->t, u.crossing->p.x(), u.crossing->p.y(),
                    u.crossing->p.z(), u.crossing->sigmaMax(), std::sqrt(u.crossing->var_t), u.feasible ? 1.0 : 0.0,
                    double(static_cast<int>(planner.phase()))});
        pending.pop_front();
      }
      const robots::CartesianState sp = planner.setpoint(t_tick);
      robot.command(sp);
      if (log)
        plan_log.row({double(index), t_tick, sp.p.x(), sp.p.y(), sp.p.z(), sp.v.x(), sp.v.y(), sp.v.z(),
                      double(static_cast<int>(planner.phase()))});
      t_tick += cfg.control_period;
    }
  };

  while (true) {
    const sim::Capture& cap = rig.peek();
    if (cap.capture_time >= t_end) break;
    // The box must be simulated up to the end of this exposure before it is rendered.
    streamUntil(cap.capture_time + 0.5 * cfg.cameras[cap.camera_index].exposure_s);
    auto frame = rig.captureNext(world);
    if (!frame) continue;
    ++res.frames;
    const std::size_t ci = frame->camera_index;
    if (const sim::ObjectTruth* b = frame->find(cfg.object); b && b->in_front && b->in_image && res.t_first_visible < 0.0)
      res.t_first_visible = frame->capture_time;
    if (log && frame->find(cfg.object)) {
      const Eigen::Vector3d p = flight.state(frame->capture_time).p;
      log->stream("truth", {"throw", "t", "camera", "x", "y", "z"})
          .row({double(index), frame->capture_time, double(ci), p.x(), p.y(), p.z()});
    }
    std::optional<Eigen::Vector2d> predicted;
    if (tracker.initialised()) {
      const double tp = std::max(frame->stamp, tracker.state().t());
      if (auto uv = est_cams[ci].project(tracker.predictAt(tp).x().head<3>())) predicted = *uv;
    }
    const auto det = detectors[ci].detect(frame->image, frame->stamp, predicted);
    std::optional<Eigen::Vector2d> det_px;
    if (det.ok()) {
      ++res.detections;
      if (res.t_first_detection < 0.0) res.t_first_detection = frame->capture_time;
      const double sigma_det = std::max(cfg.sigma_px_floor, std::sqrt(0.5 * det.value().pixel_covariance.trace()));
      const double sigma = std::hypot(sigma_det, cfg.pixel_noise_px);
      det_px = det.value().pixel;
      if (cfg.pixel_noise_px > 0.0)
        *det_px += cfg.pixel_noise_px * Eigen::Vector2d(core::gaussian(noise_rng), core::gaussian(noise_rng));
      tracking::ImageMeasurement m{next_id++, ci, frame->stamp, *det_px, sigma};
      const tracking::Refusal r = tracker.submit(m);
      bool fused = false;
      if (r == tracking::Refusal::None) {
        const auto o = tracker.outcome(m.id);
        fused = o && o->fate == tracking::Fate::Fused;
        if (fused) ++res.fused;
        else ++res.gated;
        if (fused && tracker.initialised())
          pending.push_back({frame->stamp + cfg.processing_latency, tracker.state()});
      }
      if (log) {
        log->stream("measurements", {"throw", "t", "camera", "u", "v", "sigma_px", "fused"})
            .row({double(index), frame->stamp, double(ci), m.uv.x(), m.uv.y(), sigma, fused ? 1.0 : 0.0});
        if (fused) {
          const Vector6 x = tracker.state().x();
          log->stream("estimates", {"throw", "t", "x", "y", "z", "vx", "vy", "vz"})
              .row({double(index), tracker.state().t(), x(0), x(1), x(2), x(3), x(4), x(5)});
        }
      }
    }
    if (hooks && hooks->on_frame) {
      CatchFrame f;
      f.throw_index = index;
      f.camera = ci;
      f.camera_model = &est_cams[ci];  // what the estimator believes (the calibrated camera with rig:)
      f.t = frame->capture_time;
      f.image = &frame->image;
      f.detection = det_px;
      f.crossing = planner.target();
      f.hole = robot.read(frame->capture_time).p;
      if (tracker.initialised()) f.estimate = tracker.state().x().head<3>();
      hooks->on_frame(f);
    }
  }
  streamUntil(t_end + cfg.robot.latency + cfg.control_period);

  // 6. Outcome.
  const robots::CartesianState hole = robot.read(res.t_cross);
  res.hole_at_cross = hole.p;
  if (std::abs(n.dot(hole.p - home)) > 1e-9)
    throw core::NumericalError("runThrow: the hole left the box plane (planner bug)");
  Eigen::Vector3d off = res.cross_true - hole.p;
  off -= n * n.dot(off);
  res.miss_distance = off.norm();
  res.caught = res.miss_distance <= clearance;
  res.limit_violations = robot.velocityViolations() + robot.accelerationViolations();
  res.refused_setpoints = robot.refusedSetpoints();
  // Oracle.
  res.oracle_time = planning::SyncProfile::minimumDuration(home, Eigen::Vector3d::Zero(), res.cross_true,
                                                           cfg.robot.limits.v_max, cfg.robot.limits.a_max);
  res.reachable = res.t_first_visible >= 0.0 && robot.reachable(res.cross_true) &&
                  res.t_first_visible + cfg.robot.latency + res.oracle_time <= res.t_cross;
  // Planner.
  res.had_target = planner.target().has_value();
  res.committed = planner.committed();
  res.gave_up = planner.giveUpTime().has_value();
  if (planner.firstMoveTime()) res.t_first_move = *planner.firstMoveTime();
  if (lead_prediction) res.prediction_error_lead = (*lead_prediction - res.cross_true).norm();
  if (planner.giveUpTime()) res.give_up_lead = res.t_cross - *planner.giveUpTime();
  if (planner.commitTime() && planner.firstUpdateTime())
    res.decision_time = *planner.commitTime() - *planner.firstUpdateTime();
  if (res.had_target) {
    res.target = planner.target()->p;
    res.prediction_error = (res.target - res.cross_true).norm();
  }
  if (!res.caught) {
    if (!res.reachable) res.miss_reason = "not_reachable";
    else if (!res.had_target) res.miss_reason = "lost_track";
    else if ((hole.p - res.target).norm() > clearance) res.miss_reason = "late";
    else res.miss_reason = "off_target";
  }
  res.wall_s = std::chrono::duration<double>(std::chrono::steady_clock::now() - wall0).count();
  if (log) {
    log->stream("throws", {"throw", "seed", "t_cross", "cross_x", "cross_y", "cross_z", "target_y", "target_z",
                           "miss_mm", "caught", "reachable", "decision_time", "t_first_visible", "t_first_detection",
                           "t_first_move", "oracle_time", "gave_up", "reason"})
        .rowText({std::to_string(index), std::to_string(seed), std::to_string(res.t_cross),
                  std::to_string(res.cross_true.x()), std::to_string(res.cross_true.y()),
                  std::to_string(res.cross_true.z()), std::to_string(res.target.y()), std::to_string(res.target.z()),
                  std::to_string(1e3 * res.miss_distance), res.caught ? "1" : "0", res.reachable ? "1" : "0",
                  std::to_string(res.decision_time), std::to_string(res.t_first_visible),
                  std::to_string(res.t_first_detection), std::to_string(res.t_first_move),
                  std::to_string(res.oracle_time), res.gave_up ? "1" : "0", res.miss_reason});
  }
  return res;
}

// ------------------------------------------------------------------------------------------------
// Camera-to-robot registration

RegistrationResult registerCamerasToRobot(BallCatchingConfig& cfg, const sim::Scene& room, std::uint64_t seed) {
  const CatchRegistration& rg = cfg.registration;
  core::Rng rng = core::makeRng(seed);
  std::vector<sim::SimCamera> sims;
  std::vector<core::Camera> est;
  std::vector<vision::BallDetector> detectors;
  vision::BallDetectorConfig dc = cfg.detector;
  dc.hsv = rg.marker_hsv;
  dc.fallback_full_frame = false;
  for (const auto& c : cfg.cameras) {  // every configured camera, whatever camera_count
    sim::SimCamera sc;
    sc.camera = c.renderCamera();
    sc.clock.rate = c.rate_hz;
    sc.effects.noise.sigma = c.noise_sigma;
    sims.push_back(std::move(sc));
    est.push_back(c.estimatorCamera());
    detectors.emplace_back(dc, est.back());
  }
  sim::CameraRig rig(sims, rng, cfg.render);
  RegistrationResult out;
  // Per camera: known marker positions (robot world) and their detected, undistorted normalised
  // image points (calibrated intrinsics).
  std::vector<std::vector<cv::Point3d>> obj(sims.size());
  std::vector<std::vector<cv::Point2d>> img(sims.size());
  for (double dx : rg.offsets_x)
    for (double dy : rg.offsets_y)
      for (double dz : rg.offsets_z) {
        const Eigen::Vector3d hole = cfg.robot.home + Eigen::Vector3d(dx, dy, dz);
        const Eigen::Vector3d marker = hole + rg.marker_offset;
        ++out.poses;
        StaticBoxWorld world(room, cfg, hole);
        rig.reset(0.0);
        std::vector<bool> seen(sims.size(), false);
        for (std::size_t got = 0; got < sims.size();) {
          auto f = rig.captureNext(world);
          if (!f || seen[f->camera_index]) continue;
          const std::size_t ci = f->camera_index;
          seen[ci] = true;
          ++got;
          // Search only around where the calibrated camera expects the marker (the robot knows
          // where it holds it): other green things in the room are never taken for it.
          const auto expected = est[ci].project(marker);
          if (!expected || !est[ci].inImage(*expected, 0.0)) continue;
          const auto det = detectors[ci].detect(f->image, f->stamp, *expected);
          if (!det.ok() || (det.value().pixel - *expected).norm() > rg.gate_px) continue;  // noise blobs
          const Eigen::Vector2d x = est[ci].pixelToNormalized(det.value().pixel);
          obj[ci].emplace_back(marker.x(), marker.y(), marker.z());
          img[ci].emplace_back(x.x(), x.y());
        }
      }
  // Each camera's pose re-estimated from its own points (PnP, Levenberg-Marquardt from the
  // calibrated pose): the per-camera pose errors of the board calibration differ, so one rigid
  // transform for the whole rig cannot remove them. Cameras with fewer than min_points keep their
  // calibrated pose.
  const cv::Matx33d K = cv::Matx33d::eye();
  double ss_before = 0.0, ss_after = 0.0;
  int npts = 0;
  for (std::size_t ci = 0; ci < sims.size(); ++ci) {
    out.points_per_camera.push_back(static_cast<int>(obj[ci].size()));
    if (static_cast<int>(obj[ci].size()) < rg.min_points) continue;
    const Eigen::Isometry3d& M = est[ci].c_M_w;
    cv::Mat R0;
    cv::eigen2cv(Eigen::Matrix3d(M.linear()), R0);
    cv::Vec3d rvec, tvec(M.translation().x(), M.translation().y(), M.translation().z());
    cv::Rodrigues(R0, rvec);
    auto reproj = [&](const cv::Vec3d& rv, const cv::Vec3d& tv) {
      std::vector<cv::Point2d> p;
      cv::projectPoints(obj[ci], rv, tv, K, cv::noArray(), p);
      double ss = 0.0;
      for (std::size_t k = 0; k < p.size(); ++k) ss += std::pow(cv::norm(p[k] - img[ci][k]), 2);
      return ss;
    };
    const cv::Vec3d rvec0 = rvec, tvec0 = tvec;
    cv::solvePnP(obj[ci], img[ci], K, cv::noArray(), rvec, tvec, true, cv::SOLVEPNP_ITERATIVE);
    // One pass of outlier removal (residual > 3 x the median, at least 0.5 px), then solve again
    // from the calibrated pose.
    {
      std::vector<cv::Point2d> p;
      cv::projectPoints(obj[ci], rvec, tvec, K, cv::noArray(), p);
      std::vector<double> r;
      for (std::size_t k = 0; k < p.size(); ++k) r.push_back(cv::norm(p[k] - img[ci][k]));
      std::vector<double> sorted = r;
      std::nth_element(sorted.begin(), sorted.begin() + static_cast<long>(sorted.size() / 2), sorted.end());
      const double limit = std::max(3.0 * sorted[sorted.size() / 2], 0.5 / est[ci].focalPx());
      std::vector<cv::Point3d> o2;
      std::vector<cv::Point2d> i2;
      for (std::size_t k = 0; k < r.size(); ++k)
        if (r[k] <= limit) {
          o2.push_back(obj[ci][k]);
          i2.push_back(img[ci][k]);
        }
      if (static_cast<int>(o2.size()) < rg.min_points) continue;
      obj[ci] = o2;
      img[ci] = i2;
      out.points_per_camera.back() = static_cast<int>(o2.size());
      rvec = rvec0;
      tvec = tvec0;
      cv::solvePnP(obj[ci], img[ci], K, cv::noArray(), rvec, tvec, true, cv::SOLVEPNP_ITERATIVE);
    }
    const double after = reproj(rvec, tvec);
    cv::Mat R;
    cv::Rodrigues(rvec, R);
    Eigen::Matrix3d Re;
    cv::cv2eigen(R, Re);
    Eigen::Isometry3d Mn = Eigen::Isometry3d::Identity();
    Mn.linear() = Re;
    Mn.translation() = Eigen::Vector3d(tvec[0], tvec[1], tvec[2]);
    const double shift = (Mn.inverse().translation() - M.inverse().translation()).norm();
    const double rot = core::rotationAngle(Mn.linear(), M.linear());
    const double rms_px = est[ci].focalPx() * std::sqrt(after / static_cast<double>(obj[ci].size()));
    // Plausibility: a registration that does not fit its points, or moves the camera far more than
    // a calibration error, is refused (the camera keeps its calibrated pose).
    if (rms_px > rg.max_rms_px || shift > rg.max_shift_m || rot > rg.max_rotation_rad) {
      ++out.cameras_refused;
      continue;
    }
    ss_before += reproj(rvec0, tvec0);
    ss_after += after;
    npts += static_cast<int>(obj[ci].size());
    out.centre_shift_mm.push_back(1e3 * shift);
    out.rotation_deg.push_back(core::rad2deg(rot));
    core::Camera cam = est[ci];
    cam.c_M_w = Mn;
    cfg.cameras[ci].calibrated_camera = cam;
    ++out.cameras_registered;
  }
  if (out.cameras_registered == 0)
    throw core::NumericalError("registration: no camera saw the marker at " + std::to_string(rg.min_points) +
                               " poses (check registration.marker_hsv and the offsets)");
  const double f = est.front().focalPx();
  out.reprojection_px_before = f * std::sqrt(ss_before / std::max(1, npts));
  out.reprojection_px_after = f * std::sqrt(ss_after / std::max(1, npts));
  return out;
}

// ------------------------------------------------------------------------------------------------
// Batch

CatchSummary runBallCatching(const BallCatchingConfig& cfg, int throws, std::uint64_t seed, const CatchHooks& hooks) {
  if (throws < 1) throw InvalidInput("throws: expected >= 1");
  cfg.validate();
  const auto wall0 = std::chrono::steady_clock::now();
  core::Rng room_rng = core::makeRng(core::deriveSeed(seed, 0xB0B));
  const sim::Scene room = sim::makeRoom(cfg.room, room_rng);
  CatchSummary s;
  s.seed = seed;
  BallCatchingConfig registered = cfg;  // estimator cameras in the robot's world
  if (cfg.registration.enabled) s.registration = registerCamerasToRobot(registered, room, core::deriveSeed(seed, 0x4E6));
  s.throws = throws;
  s.results.resize(static_cast<std::size_t>(throws));
  const bool serial = hooks.log || hooks.on_frame || cfg.threads <= 1;
  std::atomic<int> next{0}, done{0};
  std::mutex mu;
  std::exception_ptr error;
  auto worker = [&]() {
    while (true) {
      const int i = next++;
      if (i >= throws) return;
      try {
        s.results[static_cast<std::size_t>(i)] =
            runThrow(registered, room, i, core::deriveSeed(seed, static_cast<std::uint64_t>(i)), &hooks);
      } catch (...) {
        std::lock_guard<std::mutex> lock(mu);
        if (!error) error = std::current_exception();
        next = throws;
        return;
      }
      const int dn = ++done;
      if (hooks.progress) {
        std::lock_guard<std::mutex> lock(mu);
        hooks.progress(dn, throws);
      }
    }
  };
  if (serial) {
    worker();
  } else {
    std::vector<std::thread> pool;
    for (int t = 0; t < cfg.threads; ++t) pool.emplace_back(worker);
    for (auto& t : pool) t.join();
  }
  if (error) std::rethrow_exception(error);
  if (hooks.log) hooks.log->flush();

  for (const char* r : kMissReasons) s.miss_reasons[r] = 0;
  std::vector<double> pred_lead, pred_err, decision, miss_reach, speeds, elev, flight, give_up_lead;
  double frame_time = 0.0;
  for (const ThrowResult& r : s.results) {
    s.reachable_throws += r.reachable;
    s.caught += r.caught;
    s.caught_reachable += r.caught && r.reachable;
    if (!r.caught) ++s.miss_reasons[r.miss_reason];
    if (r.prediction_error >= 0.0) pred_err.push_back(1e3 * r.prediction_error);
    if (r.prediction_error_lead >= 0.0) pred_lead.push_back(1e3 * r.prediction_error_lead);
    if (r.decision_time >= 0.0) decision.push_back(r.decision_time);
    if (r.gave_up && !r.reachable) {
      ++s.gave_up_unreachable;
      give_up_lead.push_back(r.give_up_lead);
    }
    if (r.gave_up && r.reachable) ++s.gave_up_reachable;
    if (r.reachable) miss_reach.push_back(1e3 * r.miss_distance);
    s.limit_violations += r.limit_violations;
    s.refused_setpoints += r.refused_setpoints;
    s.frames += r.frames;
    s.detections += r.detections;
    speeds.push_back(r.launch_speed);
    elev.push_back(r.launch_elevation_deg);
    flight.push_back(r.t_cross);
    frame_time += r.wall_s;
  }
  s.catch_rate_all = static_cast<double>(s.caught) / throws;
  s.catch_rate_reachable = s.reachable_throws > 0 ? static_cast<double>(s.caught_reachable) / s.reachable_throws : 0.0;
  s.prediction_error_mm_median = percentile(pred_err, 0.5);
  s.prediction_error_mm_p95 = percentile(pred_err, 0.95);
  s.prediction_error_lead_mm_median = percentile(pred_lead, 0.5);
  s.prediction_error_lead_mm_p95 = percentile(pred_lead, 0.95);
  s.predictions_at_lead = static_cast<int>(pred_lead.size());
  s.decisions = static_cast<int>(decision.size());
  s.decision_time_s_median = percentile(decision, 0.5);
  s.decision_time_s_p95 = percentile(decision, 0.95);
  s.miss_distance_mm_median_reachable = percentile(miss_reach, 0.5);
  s.give_up_lead_s_median = percentile(give_up_lead, 0.5);
  s.detection_rate = s.frames > 0 ? static_cast<double>(s.detections) / s.frames : 0.0;
  s.launch_speed_min = *std::min_element(speeds.begin(), speeds.end());
  s.launch_speed_max = *std::max_element(speeds.begin(), speeds.end());
  s.launch_speed_mean = 0.0;
  for (double v : speeds) s.launch_speed_mean += v / static_cast<double>(speeds.size());
  s.elevation_deg_min = *std::min_element(elev.begin(), elev.end());
  s.elevation_deg_max = *std::max_element(elev.begin(), elev.end());
  s.flight_time_min = *std::min_element(flight.begin(), flight.end());
  s.flight_time_max = *std::max_element(flight.begin(), flight.end());
  s.wall_s = std::chrono::duration<double>(std::chrono::steady_clock::now() - wall0).count();
  s.ms_per_frame = s.frames > 0 ? 1e3 * frame_time / s.frames : 0.0;
  return s;
}

nlohmann::json summaryJson(const CatchSummary& s, const BallCatchingConfig& cfg) {
  auto num = [](double v) { return std::isfinite(v) ? nlohmann::json(v) : nlohmann::json(nullptr); };
  nlohmann::json j;
  j["scenario"] = cfg.name;
  j["object"] = cfg.object;
  j["seed"] = s.seed;
  j["throws"] = s.throws;
  j["reachable_throws"] = s.reachable_throws;
  j["caught"] = s.caught;
  j["catch_rate_all"] = s.catch_rate_all;
  j["catch_rate_reachable"] = s.catch_rate_reachable;
  j["miss_reasons"] = s.miss_reasons;
  j["prediction_error_mm_at_catch"] = {{"median", num(s.prediction_error_mm_median)},
                                       {"p95", num(s.prediction_error_mm_p95)}};
  j["prediction_error_mm_at_lead"] = {{"lead_s", cfg.prediction_lead_s},
                                      {"median", num(s.prediction_error_lead_mm_median)},
                                      {"p95", num(s.prediction_error_lead_mm_p95)},
                                      {"throws", s.predictions_at_lead}};
  j["decision_time_s"] = {{"median", num(s.decision_time_s_median)}, {"p95", num(s.decision_time_s_p95)},
                          {"throws_with_decision", s.decisions}};
  j["miss_distance_mm_median_reachable"] = num(s.miss_distance_mm_median_reachable);
  j["early_give_up"] = {{"not_reachable_throws_given_up", s.gave_up_unreachable},
                        {"reachable_throws_given_up", s.gave_up_reachable},
                        {"lead_before_crossing_s_median", num(s.give_up_lead_s_median)}};
  j["robot"] = {{"kind", robots::toString(cfg.robot.kind)},
                {"v_max", cfg.robot.limits.v_max.x()},
                {"a_max", cfg.robot.limits.a_max.x()},
                {"latency_s", cfg.robot.latency},
                {"limit_violations", s.limit_violations},
                {"refused_setpoints", s.refused_setpoints}};
  const std::size_t ncam = cfg.camera_count > 0 ? cfg.camera_count : cfg.cameras.size();
  j["cameras"] = ncam;
  j["rate_hz"] = cfg.rate_override_hz > 0.0 ? cfg.rate_override_hz : cfg.cameras.front().rate_hz;
  j["pixel_noise_grey"] = cfg.cameras.front().noise_sigma;
  j["detection_noise_px"] = cfg.pixel_noise_px;
  j["rig"] = cfg.rig.empty() ? nlohmann::json("inline cameras (estimator = render cameras)") : nlohmann::json(cfg.rig);
  j["planner_model"] = planning::toString(cfg.planner.model.kind);
  j["hole_radius_m"] = cfg.hole_radius;
  j["ball_radius_m"] = cfg.throws.body.reference_radius;
  j["drag_k_per_m"] = cfg.throws.body.dragPerMass();
  j["frames"] = s.frames;
  j["detection_rate"] = s.detection_rate;
  j["throw_distribution"] = {{"launch_speed_mps", {{"min", s.launch_speed_min}, {"mean", s.launch_speed_mean},
                                                   {"max", s.launch_speed_max}}},
                             {"elevation_deg", {{"min", s.elevation_deg_min}, {"max", s.elevation_deg_max}}},
                             {"flight_time_s", {{"min", s.flight_time_min}, {"max", s.flight_time_max}}},
                             {"aim_radius_m", cfg.throws.aim_radius},
                             {"mean_horizontal_speed_mps", {cfg.throws.speed_min, cfg.throws.speed_max}},
                             {"spin", "none"}};
  if (s.registration)
    j["registration"] = {{"poses", s.registration->poses},
                         {"points_per_camera", s.registration->points_per_camera},
                         {"cameras_registered", s.registration->cameras_registered},
                         {"cameras_refused", s.registration->cameras_refused},
                         {"reprojection_px_before", s.registration->reprojection_px_before},
                         {"reprojection_px_after", s.registration->reprojection_px_after},
                         {"centre_shift_mm", s.registration->centre_shift_mm},
                         {"rotation_deg", s.registration->rotation_deg}};
  else
    j["registration"] = "off";
  j["reachability_start"] = "first capture with the ball inside a camera image (truth), robot at home at rest";
  j["wall_time_s"] = s.wall_s;
  j["ms_per_frame_per_thread"] = s.ms_per_frame;
  return j;
}

}  // namespace viewline::scenarios
