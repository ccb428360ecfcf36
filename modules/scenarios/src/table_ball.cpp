#include "viewline/scenarios/table_ball.h"

#include <algorithm>
#include <chrono>
#include <ctime>
#include <cmath>
#include <filesystem>
#include <limits>
#include <optional>
#include <sstream>

#include "viewline/core/checks.h"
#include "viewline/core/error.h"
#include "viewline/core/frames.h"
#include "viewline/core/random.h"
#include "viewline/io/log.h"
#include "viewline/scenarios/simulated_rig.h"
#include "viewline/sim/physics.h"
#include "viewline/sim/renderer.h"
#include "viewline/sim/rig.h"
#include "viewline/sim/worlds.h"

namespace viewline::scenarios {

namespace {

constexpr double kInf = std::numeric_limits<double>::infinity();
constexpr double kNaN = std::numeric_limits<double>::quiet_NaN();
constexpr double kTick = 1e-3;  // physics and command interpolation step, s

void requireNonNegative(double v, const std::string& what) {
  core::requireFinite(v, what);
  if (v < 0.0) throw core::InvalidInput(what + ": expected >= 0, got " + std::to_string(v));
}

Eigen::Isometry3d translation(const Eigen::Vector3d& p) {
  Eigen::Isometry3d m = Eigen::Isometry3d::Identity();
  m.translation() = p;
  return m;
}

/// Head sway: small rotations about the camera axes and a small translation, sums of sines at
/// incommensurate frequencies around f (deterministic; phases from the seed).
struct HeadSway {
  Eigen::Isometry3d c_M_w0;
  double amplitude, f, translation;
  std::array<double, 6> phase{};
  Eigen::Isometry3d at(double t) const {
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
};

double rms(double sum_sq, int n) { return n > 0 ? std::sqrt(sum_sq / n) : kNaN; }

/// CPU time of the calling thread, s (the observer and the reference run on it, one after the
/// other; unlike wall time it does not count the time the thread waits for a core).
double threadCpuSeconds() {
  timespec ts{};
  clock_gettime(CLOCK_THREAD_CPUTIME_ID, &ts);
  return static_cast<double>(ts.tv_sec) + 1e-9 * static_cast<double>(ts.tv_nsec);
}

struct TrackAccumulator {
  double sum_sq = 0.0;
  int n = 0;
  void add(const Eigen::Vector2d& e) {
    sum_sq += e.squaredNorm();
    ++n;
  }
  double rmsMm() const { return 1000.0 * rms(sum_sq, n); }
};

Eigen::Vector2d positionOf(const Eigen::VectorXd& x) { return {x[0], x[2]}; }
Eigen::Vector2d velocityOf(const Eigen::VectorXd& x) { return {x[1], x[3]}; }

}  // namespace

// ---------------------------------------------------------------------------------------------

void TableBallConfig::validate() const {
  core::requirePositive(table_side, "table.side");
  core::requirePositive(ball_radius, "table.ball_radius");
  if (2.0 * ball_radius >= table_side) throw core::InvalidInput("table.ball_radius: expected < side / 2");
  core::requireFinite(table_center, "table.center");
  const double lim = 0.5 * table_side - ball_radius;
  core::requireFinite(initial_ball, "table.initial_ball");
  if (initial_ball.cwiseAbs().maxCoeff() > lim) throw core::InvalidInput("table.initial_ball: outside the table");
  core::requireFinite(initial_velocity, "table.initial_velocity");
  core::requirePositive(tag_size, "table.tag_size");
  core::requirePositive(border_height, "table.border_height");
  wrist.validate();
  if (width < 16 || height < 16) throw core::InvalidInput("camera.width/height: expected >= 16 pixels");
  core::requirePositive(hfov, "camera.hfov_deg");
  if (hfov >= core::kPi) throw core::InvalidInput("camera.hfov_deg: expected < 180");
  core::requirePositive(rate_hz, "camera.rate_hz");
  core::requireFinite(camera_position, "camera.position");
  core::requireFinite(camera_look_at, "camera.look_at");
  if ((camera_position - camera_look_at).norm() < 1e-3) throw core::InvalidInput("camera.look_at: equals camera.position");
  requireNonNegative(sway, "camera.sway_deg");
  requireNonNegative(sway_hz, "camera.sway_hz");
  requireNonNegative(sway_translation, "camera.sway_translation");
  requireNonNegative(ground_rotation_noise, "camera.ground_rotation_noise_deg");
  requireNonNegative(sensor_noise, "camera.sensor_noise");
  requireNonNegative(exposure, "camera.exposure");
  if (blur_samples < 1) throw core::InvalidInput("camera.blur_samples: expected >= 1");
  requireNonNegative(drop_probability, "camera.drop_probability");
  if (drop_probability >= 1.0) throw core::InvalidInput("camera.drop_probability: expected < 1");
  if (supersampling < 1 || supersampling > 8) throw core::InvalidInput("camera.supersampling: expected 1..8");
  requireNonNegative(latency, "controller.latency");
  if (latency < 0.5 * exposure) {
    throw core::InvalidInput("controller.latency: expected >= camera.exposure / 2 (a frame is processed after its exposure)");
  }
  if (latency >= 1.0 / rate_hz) throw core::InvalidInput("controller.latency: expected < one frame period");
  core::requirePositive(duration, "duration");
  requireNonNegative(warmup, "metrics.warmup");
  core::requirePositive(min_step, "metrics.min_step");
  core::requirePositive(settle_fraction, "metrics.settle_fraction");
  core::requirePositive(steady_window, "metrics.steady_window");
  core::requirePositive(push_band, "metrics.push_band");
  if (setpoints.empty()) throw core::InvalidInput("events.setpoints: expected at least one (at t = 0)");
  for (std::size_t i = 0; i < setpoints.size(); ++i) {
    const std::string w = "events.setpoints[" + std::to_string(i) + "]";
    requireNonNegative(setpoints[i].t, w + ".t");
    core::requireFinite(setpoints[i].xy, w + ".xy");
    if (setpoints[i].xy.cwiseAbs().maxCoeff() > lim) throw core::InvalidInput(w + ".xy: outside the reachable table area");
    if (i > 0 && setpoints[i].t <= setpoints[i - 1].t) throw core::InvalidInput(w + ".t: expected increasing times");
  }
  if (setpoints.front().t != 0.0) throw core::InvalidInput("events.setpoints[0].t: expected 0");
  for (std::size_t i = 0; i < pushes.size(); ++i) {
    const std::string w = "events.pushes[" + std::to_string(i) + "]";
    requireNonNegative(pushes[i].t, w + ".t");
    core::requireFinite(pushes[i].dv, w + ".dv");
    if (i > 0 && pushes[i].t <= pushes[i - 1].t) throw core::InvalidInput(w + ".t: expected increasing times");
  }
}

TableBallConfig tableBallConfigFromYaml(const io::ConfigNode& root) {
  TableBallConfig c;
  c.duration = root.getOr<double>("duration", c.duration);
  {
    const auto n = root.child("table");
    c.table_side = n.getOr<double>("side", c.table_side);
    c.ball_radius = n.getOr<double>("ball_radius", c.ball_radius);
    c.table_center = n.getOr<Eigen::Vector3d>("center", c.table_center);
    c.initial_ball = n.getOr<Eigen::Vector2d>("initial_ball", c.initial_ball);
    c.initial_velocity = n.getOr<Eigen::Vector2d>("initial_velocity", c.initial_velocity);
    c.border_height = n.getOr<double>("border_height", c.border_height);
    c.table_tags = n.getOr<bool>("tags", c.table_tags);
    c.tag_size = n.getOr<double>("tag_size", c.tag_size);
  }
  {
    const auto n = root.child("wrist");
    c.wrist.max_angle = n.getAngleOr("max_angle_deg", c.wrist.max_angle);
    c.wrist.max_rate = n.getOr<double>("max_rate", c.wrist.max_rate);
    c.wrist.delay = n.getOr<double>("delay", c.wrist.delay);
  }
  if (root.has("rig")) {
    const std::string folder = root.getPath("rig");
    try {
      c.rig = loadTableRig(folder);
    } catch (const core::InvalidInput& e) {
      throw core::InvalidInput(root.location("rig") + ": key 'rig': " + e.what());
    }
    c.width = c.rig->truth.width;
    c.height = c.rig->truth.height;
  }
  {
    const auto n = root.child("camera");
    if (c.rig) {
      for (const char* key : {"width", "height", "hfov_deg", "position", "look_at"}) {
        if (n.has(key)) {
          throw core::InvalidInput(n.location(key) + ": key '" + n.keyPath(key) +
                                   "': not allowed with 'rig' (the rig's truth.yaml and rig.yaml set the camera)");
        }
      }
    }
    c.width = n.getOr<unsigned>("width", c.width);
    c.height = n.getOr<unsigned>("height", c.height);
    c.hfov = n.getAngleOr("hfov_deg", c.hfov);
    c.rate_hz = n.getOr<double>("rate_hz", c.rate_hz);
    c.camera_position = n.getOr<Eigen::Vector3d>("position", c.camera_position);
    c.camera_look_at = n.getOr<Eigen::Vector3d>("look_at", c.camera_look_at);
    c.sway = n.getAngleOr("sway_deg", c.sway);
    c.sway_hz = n.getOr<double>("sway_hz", c.sway_hz);
    c.sway_translation = n.getOr<double>("sway_translation", c.sway_translation);
    c.ground_rotation_noise = n.getAngleOr("ground_rotation_noise_deg", c.ground_rotation_noise);
    c.sensor_noise = n.getOr<double>("sensor_noise", c.sensor_noise);
    c.exposure = n.getOr<double>("exposure", c.exposure);
    c.blur_samples = n.getOr<int>("blur_samples", c.blur_samples);
    c.drop_probability = n.getOr<double>("drop_probability", c.drop_probability);
    c.supersampling = n.getOr<int>("supersampling", c.supersampling);
  }
  {
    const auto n = root.child("observer");
    c.observer.table_pose = n.getChoiceOr("table_pose", {"corners", "apriltag"}, "corners") == "apriltag"
                                ? TablePoseSource::AprilTag
                                : TablePoseSource::Corners;
    c.observer.ball_geometry =
        n.getChoiceOr("ball_geometry", {"known_radius", "unknown_radius"}, "known_radius") == "unknown_radius"
            ? BallGeometry::UnknownRadius
            : BallGeometry::KnownRadius;
    auto& m = c.observer.tracker.model;
    m.sigma_w = n.getOr<double>("sigma_w", m.sigma_w);
    m.sigma_v = n.getOr<double>("sigma_v", m.sigma_v);
    m.beta = n.getOr<double>("beta", m.beta);
    m.prediction_steps = n.getOr<int>("prediction_steps", m.prediction_steps);
    c.observer.tracker.stationary_gain = n.getOr<bool>("stationary_gain", c.observer.tracker.stationary_gain);
    c.observer.tracker.initial_velocity_std = n.getOr<double>("initial_velocity_std", c.observer.tracker.initial_velocity_std);
    c.observer.detector.refine = n.getOr<bool>("refine", c.observer.detector.refine);
    c.observer.edge_tracking = n.getOr<bool>("edge_tracking", c.observer.edge_tracking);
    c.border_aware_pnp = n.getOr<bool>("border_aware_pnp", c.border_aware_pnp);
  }
  {
    const auto n = root.child("controller");
    auto& k = c.controller;
    c.latency = n.getOr<double>("latency", c.latency);
    k.q_position = n.getOr<double>("q_position", k.q_position);
    k.q_velocity = n.getOr<double>("q_velocity", k.q_velocity);
    k.q_tilt = n.getOr<double>("q_tilt", k.q_tilt);
    k.q_integral = n.getOr<double>("q_integral", k.q_integral);
    k.r_rate = n.getOr<double>("r_rate", k.r_rate);
    k.integral_band = n.getOr<double>("integral_band", k.integral_band);
  }
  {
    const auto n = root.child("events");
    for (const auto& s : n.childList("setpoints")) c.setpoints.push_back({s.get<double>("t"), s.get<Eigen::Vector2d>("xy")});
    if (n.has("pushes")) {
      for (const auto& p : n.childList("pushes")) c.pushes.push_back({p.get<double>("t"), p.get<Eigen::Vector2d>("dv")});
    }
  }
  if (root.has("metrics")) {
    const auto n = root.child("metrics");
    c.warmup = n.getOr<double>("warmup", c.warmup);
    c.min_step = n.getOr<double>("min_step", c.min_step);
    c.settle_fraction = n.getOr<double>("settle_fraction", c.settle_fraction);
    c.steady_window = n.getOr<double>("steady_window", c.steady_window);
    c.push_band = n.getOr<double>("push_band", c.push_band);
    c.compare_tunings = n.getOr<bool>("compare_tunings", c.compare_tunings);
    c.time_reference = n.getOr<bool>("time_reference", c.time_reference);
  }
  root.finish();
  try {
    c.validate();
  } catch (const core::InvalidInput& e) {
    throw core::InvalidInput(root.fileName() + ": " + e.what());
  }
  return c;
}

TableBallConfig::RigCameras loadTableRig(const std::string& folder) {
  const SimulatedRig rig = loadSimulatedRig(folder);
  TableBallConfig::RigCameras out;
  out.folder = std::filesystem::path(rig.folder).lexically_normal().string();
  out.truth = rig.trueCamera("head");
  out.calibrated = rig.calibratedCamera("head");
  // ground.yaml (camera-to-ground): the calibrated rotation of the head at rest to the ground
  // (z up), which is all the observer needs of the rest pose besides the nominal table prior.
  const Eigen::Matrix3d g_R_c = loadGroundRotation(rig, "head");
  out.calibrated.c_M_w.linear() = g_R_c.transpose();
  return out;
}

std::vector<vision::TagOnTable> tableTagLayout(const sim::TableWorld& world) {
  const sim::TableAppearance& look = world.appearance();
  std::vector<vision::TagOnTable> layout;
  if (!look.tags) return layout;
  for (int i = 0; i < 4; ++i) layout.push_back({look.first_tag_id + i, look.tag_size, world.table_M_vispTag(i)});
  return layout;
}

// ---------------------------------------------------------------------------------------------

nlohmann::json toJson(const TableBallResult& r) {
  auto num = [](double v) { return std::isfinite(v) ? nlohmann::json(v) : nlohmann::json(nullptr); };
  nlohmann::json j;
  j["scenario"] = "table_ball_balancing";
  j["seed"] = r.seed;
  j["duration_s"] = r.duration;
  j["frames"] = r.frames;
  j["frames_dropped"] = r.frames_dropped;
  j["table_detections"] = r.table_detections;
  j["ball_detections"] = r.ball_detections;
  j["tracked_frames"] = r.tracked_frames;
  j["observer_rmse_mm"] = num(r.observer_rmse_mm);
  j["measurement_rmse_mm"] = num(r.measurement_rmse_mm);
  j["tunings"] = {{"M_sigma_w_1_sigma_v_0.005_rmse_mm", num(r.observer_rmse_mm_M_sw1_sv0005)},
                  {"M_sigma_w_1_sigma_v_1_rmse_mm", num(r.observer_rmse_mm_M_sw1_sv1)},
                  {"stationary_gain_rmse_mm", num(r.observer_rmse_mm_stationary)}};
  j["prediction_rmse_mm_10_steps"] = num(r.prediction_rmse_mm_10);
  j["tilt_rmse_deg"] = num(r.tilt_rmse_deg);
  j["nis_mean"] = num(r.nis_mean);
  j["overshoot_pct"] = num(r.overshoot_pct);
  j["settling_time_s"] = num(r.settling_time_s);
  j["steady_state_error_mm"] = num(r.steady_state_error_mm);
  j["push_recovery_s"] = num(r.push_recovery_s);
  j["frame_time_ratio_to_reference"] = num(r.frame_time_ratio_to_reference);
  j["observer_frame_ms"] = num(r.observer_frame_ms);
  j["reference_frame_ms"] = num(r.reference_frame_ms);
  j["frame_cpu_ratio_to_reference"] = num(r.frame_cpu_ratio_to_reference);
  j["observer_frame_cpu_ms"] = num(r.observer_frame_cpu_ms);
  j["reference_frame_cpu_ms"] = num(r.reference_frame_cpu_ms);
  j["max_commanded_angle_deg"] = r.max_commanded_angle_deg;
  j["max_commanded_rate_deg_s"] = r.max_commanded_rate_deg_s;
  j["limits_respected"] = r.limits_respected;
  nlohmann::json steps = nlohmann::json::array();
  for (const auto& s : r.steps) {
    steps.push_back({{"t", s.t}, {"size_m", s.size_m}, {"overshoot_pct", num(s.overshoot_pct)},
                     {"settling_time_s", num(s.settling_time_s)}, {"settling_time_2d_s", num(s.settling_time_2d_s)}, {"steady_state_error_mm", num(s.steady_state_error_mm)}});
  }
  j["steps"] = steps;
  nlohmann::json pushes = nlohmann::json::array();
  for (const auto& p : r.pushes) {
    pushes.push_back({{"t", p.t}, {"speed_m_s", p.speed}, {"recovery_s", num(p.recovery_s)},
                      {"peak_excursion_mm", num(p.peak_excursion_mm)}});
  }
  j["pushes"] = pushes;
  j["wall_seconds"] = r.wall_seconds;
  return j;
}

// ---------------------------------------------------------------------------------------------

TableBallResult runTableBall(const TableBallConfig& cfg_in, std::uint64_t seed, const TableBallHooks& hooks) {
  const auto wall0 = std::chrono::steady_clock::now();
  TableBallConfig cfg = cfg_in;
  cfg.validate();
  const double period = 1.0 / cfg.rate_hz;
  core::Rng rng = core::makeRng(seed);
  core::Rng room_rng = core::makeRng(core::deriveSeed(seed, 1));
  core::Rng rig_rng = core::makeRng(core::deriveSeed(seed, 2));
  core::Rng imu_rng = core::makeRng(core::deriveSeed(seed, 3));

  // --- world: table + ball physics, wrist, room, head camera --------------------------------
  sim::TiltTableParams tp;
  tp.side = cfg.table_side;
  tp.ball_radius = cfg.ball_radius;
  tp.max_angle = cfg.wrist.max_angle * (1.0 + 1e-9) + 1e-9;  // the wrist model owns the limits
  tp.max_rate = 1e4;                                         // ... and follows them within a tick
  tp.delay = 0.0;
  tp.substep = kTick;
  tp.history = 1.0;
  tp.w_M_base = translation(cfg.table_center);
  sim::TiltTableState s0;
  s0.p = cfg.initial_ball;
  s0.v = cfg.initial_velocity;
  sim::TiltTable table(tp, s0);
  robots::SimulatedTableTilt wrist(cfg.wrist);

  sim::RoomParams room;
  room.floor_texture.resolution = 512;
  room.wall_texture.resolution = 512;
  sim::TableAppearance look;
  look.tags = cfg.table_tags;
  look.tag_size = cfg.tag_size;
  look.border_height = cfg.border_height;
  sim::TableWorld world(table, sim::makeRoom(room, room_rng), look);

  // `camera` renders (truth); `obs_camera` is what the observer believes (calibrated with a rig).
  core::Camera camera;
  camera.name = "head";
  camera.width = cfg.width;
  camera.height = cfg.height;
  camera.intrinsics = core::intrinsicsFromFov(cfg.hfov, cfg.width, cfg.height);
  camera.c_M_w = core::lookAt(cfg.camera_position, cfg.camera_look_at, Eigen::Vector3d::UnitZ());
  if (cfg.rig) camera = cfg.rig->truth;
  const core::Camera obs_camera = cfg.rig ? cfg.rig->calibrated : camera;
  HeadSway sway{camera.c_M_w, cfg.sway, cfg.sway_hz, cfg.sway_translation, {}};
  for (double& ph : sway.phase) ph = core::uniform(rng, 0.0, 2.0 * core::kPi);

  sim::SimCamera simcam;
  simcam.camera = camera;
  simcam.clock.rate = cfg.rate_hz;
  simcam.effects.noise.sigma = cfg.sensor_noise;
  simcam.effects.noise.pool_size = 1u << 20;
  simcam.effects.blur.exposure = cfg.exposure;
  simcam.effects.blur.samples = cfg.blur_samples;
  simcam.effects.faults.drop_probability = cfg.drop_probability;
  simcam.pose_at = [sway](double t) { return sway.at(t); };
  sim::RenderSettings render;
  render.supersampling = cfg.supersampling;
  sim::CameraRig rig({simcam}, rig_rng, render);
  rig.reset(0.0);

  // --- observer, side filters, controller -----------------------------------------------------
  TableBallObserverConfig ocfg = cfg.observer;
  ocfg.detector.side_m = cfg.table_side;
  ocfg.detector.ball_radius_m = cfg.ball_radius;
  ocfg.tracker.model.table_side = cfg.table_side;
  ocfg.tracker.model.ball_radius = cfg.ball_radius;
  ocfg.tracker.nominal_period = period;
  ocfg.border_height = cfg.border_aware_pnp ? cfg.border_height : 0.0;  // the table's known design
  if (ocfg.table_pose == TablePoseSource::AprilTag) {
    if (!cfg.table_tags) throw core::InvalidInput("observer.table_pose: apriltag needs table.tags: true");
    ocfg.tag_layout = tableTagLayout(world);  // in vpDetectorAprilTag's tag frame (z out of the tag)
    ocfg.tag_detector.tag_size_m = cfg.tag_size;
  }
  TableBallObserver observer(obs_camera, ocfg);

  std::vector<std::pair<std::string, RollingBallTracker>> side;
  if (cfg.compare_tunings) {
    RollingBallTrackerConfig a = ocfg.tracker, b = ocfg.tracker, st = ocfg.tracker;
    a.model.sigma_w = 1.0;
    a.model.sigma_v = 0.005;
    a.stationary_gain = false;
    b.model.sigma_w = 1.0;
    b.model.sigma_v = 1.0;
    b.stationary_gain = false;
    st.stationary_gain = true;
    side.emplace_back("M_best", RollingBallTracker(a));
    side.emplace_back("M_lag", RollingBallTracker(b));
    side.emplace_back("stationary", RollingBallTracker(st));
  }
  // The plain reference pipeline ([M]'s steps without our refinements and reuse) + the same filter.
  vision::TableDetectorConfig ref_det = ocfg.detector;
  ref_det.refine = false;
  RollingBallTracker ref_tracker(ocfg.tracker);

  control::TableBalancerConfig kcfg = cfg.controller;
  kcfg.period = period;
  kcfg.delay = cfg.latency + cfg.wrist.delay;
  kcfg.max_angle = cfg.wrist.max_angle;
  kcfg.max_rate = cfg.wrist.max_rate;
  control::TableBalancer controller(kcfg);

  // --- logs -----------------------------------------------------------------------------------
  io::CsvWriter* log_truth = nullptr;
  io::CsvWriter* log_meas = nullptr;
  io::CsvWriter* log_est = nullptr;
  io::CsvWriter* log_cmd = nullptr;
  if (hooks.log != nullptr && hooks.log->enabled()) {
    log_truth = &hooks.log->stream("truth", {"t", "px", "py", "vx", "vy", "tilt_x", "tilt_y"});
    log_meas = &hooks.log->stream("measurements", {"t", "table_found", "ball_found", "mx", "my", "tilt_x", "tilt_y",
                                                   "ax", "ay"});
    log_est = &hooks.log->stream("estimates", {"t", "px", "vx", "py", "vy", "w2x", "w2y", "P_px", "P_py", "pred10_x",
                                               "pred10_y", "M_best_px", "M_best_py", "M_lag_px", "M_lag_py",
                                               "stationary_px", "stationary_py"});
    log_cmd = &hooks.log->stream("commands", {"t", "ref_x", "ref_y", "cmd_tilt_x", "cmd_tilt_y", "tilt_x", "tilt_y",
                                              "px", "py"});
  }

  // --- loop -----------------------------------------------------------------------------------
  TableBallResult res;
  res.seed = seed;
  res.duration = cfg.duration;
  std::vector<double> tick_t;
  std::vector<Eigen::Vector2d> tick_p;
  tick_t.reserve(static_cast<std::size_t>(cfg.duration / kTick) + 16);
  tick_p.reserve(tick_t.capacity());

  auto setpointAt = [&](double t) {
    Eigen::Vector2d r = cfg.setpoints.front().xy;
    for (const auto& s : cfg.setpoints) {
      if (s.t <= t) r = s.xy;
    }
    return r;
  };

  control::TiltRamp current;  // holds the level table until the first estimate
  current.t0 = -1.0;
  current.period = period;
  std::optional<control::TiltRamp> next;
  std::size_t push_i = 0;
  double t_phys = 0.0;
  long tick = 0;
  Eigen::Vector2d last_cmd = Eigen::Vector2d::Zero();
  bool have_cmd = false;

  auto advancePhysics = [&](double t_target) {
    while (t_phys < t_target - 1e-9) {
      if (next && t_phys >= next->t0 - 1e-9) {
        current = *next;
        next.reset();
      }
      const Eigen::Vector2d cmd = current.commandAt(t_phys);
      if (!cfg.wrist.withinAngle(cmd, 1e-12)) res.limits_respected = false;
      if (have_cmd) {
        const double rate = (cmd - last_cmd).cwiseAbs().maxCoeff() / kTick;
        res.max_commanded_rate_deg_s = std::max(res.max_commanded_rate_deg_s, core::rad2deg(rate));
        if (rate > cfg.wrist.max_rate * (1.0 + 1e-9) + 1e-12) res.limits_respected = false;
      }
      res.max_commanded_angle_deg = std::max(res.max_commanded_angle_deg, core::rad2deg(cmd.cwiseAbs().maxCoeff()));
      last_cmd = cmd;
      have_cmd = true;
      wrist.command(t_phys, cmd);
      ++tick;
      const double s = static_cast<double>(tick) * kTick;
      while (push_i < cfg.pushes.size() && cfg.pushes[push_i].t <= s) table.push(cfg.pushes[push_i++].dv);
      table.command(s, wrist.actual(s));
      table.advanceTo(s);
      t_phys = s;
      tick_t.push_back(s);
      tick_p.push_back(table.state().p);
      if (log_cmd != nullptr && tick % 5 == 0) {
        const Eigen::Vector2d r = setpointAt(s);
        log_cmd->row({s, r.x(), r.y(), cmd.x(), cmd.y(), table.state().tilt.x(), table.state().tilt.y(),
                      table.state().p.x(), table.state().p.y()});
      }
    }
  };

  TrackAccumulator acc_obs, acc_meas, acc_pred, acc_tilt;
  std::vector<TrackAccumulator> acc_side(side.size());
  std::vector<std::pair<double, Eigen::Vector2d>> pending_pred;  // (time, predicted position 10 frames ahead)
  double nis_sum = 0.0;
  int nis_n = 0;
  double obs_time = 0.0, ref_time = 0.0, obs_cpu = 0.0, ref_cpu = 0.0;
  int timed = 0;
  double next_progress = 0.0;
  core::Camera view_camera = obs_camera;

  while (true) {
    const sim::Capture cap = rig.peek();
    if (cap.capture_time >= cfg.duration) break;
    advancePhysics(cap.capture_time + 0.5 * cfg.exposure);
    std::optional<sim::Frame> frame = rig.captureNext(world);
    ++res.frames;
    const double t = cap.stamp;
    const sim::TiltTableState truth = table.stateAt(cap.capture_time);
    const Eigen::Vector2d ref = setpointAt(t);
    const Eigen::Isometry3d w_M_t_nominal = table.tablePose(controller.modelTilt());

    const ObserverFrame* of = nullptr;
    if (frame) {
      // The observer's camera pose: the measured sway applied to the (calibrated) rest pose.
      Eigen::Isometry3d obs_c_M_w = frame->camera.c_M_w;
      if (cfg.rig) obs_c_M_w = frame->camera.c_M_w * camera.c_M_w.inverse() * obs_camera.c_M_w;
      view_camera.c_M_w = obs_c_M_w;
      Eigen::Matrix3d c_R_w = obs_c_M_w.linear();
      if (cfg.ground_rotation_noise > 0.0) {
        const Eigen::Vector3d e(core::gaussian(imu_rng, cfg.ground_rotation_noise),
                                core::gaussian(imu_rng, cfg.ground_rotation_noise),
                                core::gaussian(imu_rng, cfg.ground_rotation_noise));
        c_R_w = Eigen::AngleAxisd(e.norm(), e.norm() > 0 ? Eigen::Vector3d(e.normalized()) : Eigen::Vector3d::UnitX())
                    .toRotationMatrix() * c_R_w;
      }
      const Eigen::Isometry3d c_M_t_nominal = obs_c_M_w * w_M_t_nominal;
      const double c0 = threadCpuSeconds();
      of = &observer.process(frame->image, t, c_R_w, c_M_t_nominal);
      const double c1 = threadCpuSeconds();
      if (cfg.time_reference) {
        const auto r0 = std::chrono::steady_clock::now();
        const vision::TableScene rs = vision::referenceTableScene(frame->image, t, obs_camera, ref_det, c_M_t_nominal);
        std::optional<Eigen::Vector2d> ry;
        Eigen::Vector2d ra = of->a_xy;
        if (rs.table) {
          ra = estimation::rollingBallAcceleration(
              estimation::tableRotationInWorld(rs.table->c_M_t.linear(), c_R_w), ocfg.gravity_w);
          if (rs.ball) ry = rs.ball->known_radius.p_t.head<2>();
        }
        if (ref_tracker.initialized() || ry) ref_tracker.step(t, ra, ry);
        ref_time += std::chrono::duration<double>(std::chrono::steady_clock::now() - r0).count();
        ref_cpu += threadCpuSeconds() - c1;
        obs_time += of->seconds;
        obs_cpu += c1 - c0;
        ++timed;
      }
    } else {
      ++res.frames_dropped;
      of = &observer.predictOnly(t);
    }
    if (of->tracked) ++res.tracked_frames;
    if (of->table_found) ++res.table_detections;
    if (of->ball_found) ++res.ball_detections;
    const std::optional<Eigen::Vector2d> y = of->ball_found ? std::optional<Eigen::Vector2d>(of->measured) : std::nullopt;
    for (auto& [name, trk] : side) {
      if (trk.initialized() || y) trk.step(t, of->a_xy, y);
    }

    // Metrics against the truth at the capture instant.
    if (t >= cfg.warmup) {
      if (of->estimate_valid) acc_obs.add(positionOf(of->x) - truth.p);
      if (of->ball_found) acc_meas.add(of->measured - truth.p);
      if (of->table_found) acc_tilt.add(of->measured_tilt - truth.tilt);
      for (std::size_t i = 0; i < side.size(); ++i) {
        if (side[i].second.initialized()) acc_side[i].add(side[i].second.position() - truth.p);
      }
      if (of->ball_found && observer.tracker().initialized()) {
        nis_sum += observer.tracker().lastNis();
        ++nis_n;
      }
    }
    while (!pending_pred.empty() && pending_pred.front().first <= t + 1e-6) {
      if (std::abs(pending_pred.front().first - t) < 0.25 * period && t >= cfg.warmup) {
        acc_pred.add(pending_pred.front().second - truth.p);
      }
      pending_pred.erase(pending_pred.begin());
    }
    if (of->estimate_valid && !of->predictions.empty()) {
      pending_pred.emplace_back(t + static_cast<double>(of->predictions.size()) * period, of->predictions.back());
    }

    // Control.
    if (of->estimate_valid) {
      control::TiltRamp ramp = controller.update(t, positionOf(of->x), velocityOf(of->x), ref);
      ramp.t0 = cap.capture_time + cfg.latency;
      next = ramp;
    }

    if (log_truth != nullptr) {
      log_truth->row({cap.capture_time, truth.p.x(), truth.p.y(), truth.v.x(), truth.v.y(), truth.tilt.x(), truth.tilt.y()});
      log_meas->row({t, of->table_found ? 1.0 : 0.0, of->ball_found ? 1.0 : 0.0, of->measured.x(), of->measured.y(),
                     of->measured_tilt.x(), of->measured_tilt.y(), of->a_xy.x(), of->a_xy.y()});
      const Eigen::MatrixXd P = observer.tracker().P();
      auto sidePos = [&](std::size_t i, int k) {
        return i < side.size() && side[i].second.initialized() ? side[i].second.position()[k] : kNaN;
      };
      log_est->row({t, of->x[0], of->x[1], of->x[2], of->x[3], of->x[4], of->x[5], std::sqrt(P(0, 0)), std::sqrt(P(2, 2)),
                    of->predictions.empty() ? kNaN : of->predictions.back().x(),
                    of->predictions.empty() ? kNaN : of->predictions.back().y(), sidePos(0, 0), sidePos(0, 1),
                    sidePos(1, 0), sidePos(1, 1), sidePos(2, 0), sidePos(2, 1)});
    }
    if (hooks.on_frame) {
      TableBallFrameView view;
      view.image = frame ? &frame->image : nullptr;
      view.camera = &view_camera;  // the observer's camera (calibrated with a rig) at the last frame
      view.observer = of;
      view.truth = truth.p;
      view.setpoint = ref;
      view.tilt = truth.tilt;
      hooks.on_frame(view);
    }
    if (hooks.on_progress && t >= next_progress) {
      hooks.on_progress(t, cfg.duration);
      next_progress += 1.0;
    }
  }
  advancePhysics(cfg.duration);

  // --- metrics --------------------------------------------------------------------------------
  res.observer_rmse_mm = acc_obs.rmsMm();
  res.measurement_rmse_mm = acc_meas.rmsMm();
  res.prediction_rmse_mm_10 = acc_pred.rmsMm();
  res.tilt_rmse_deg = core::rad2deg(rms(acc_tilt.sum_sq, acc_tilt.n));
  res.nis_mean = nis_n > 0 ? nis_sum / nis_n : kNaN;
  if (side.size() == 3) {
    res.observer_rmse_mm_M_sw1_sv0005 = acc_side[0].rmsMm();
    res.observer_rmse_mm_M_sw1_sv1 = acc_side[1].rmsMm();
    res.observer_rmse_mm_stationary = acc_side[2].rmsMm();
  } else {
    res.observer_rmse_mm_M_sw1_sv0005 = res.observer_rmse_mm_M_sw1_sv1 = res.observer_rmse_mm_stationary = kNaN;
  }
  if (timed > 0) {
    res.observer_frame_ms = 1000.0 * obs_time / timed;
    res.reference_frame_ms = 1000.0 * ref_time / timed;
    res.frame_time_ratio_to_reference = obs_time / ref_time;
    res.observer_frame_cpu_ms = 1000.0 * obs_cpu / timed;
    res.reference_frame_cpu_ms = 1000.0 * ref_cpu / timed;
    res.frame_cpu_ratio_to_reference = obs_cpu / ref_cpu;
  } else {
    res.observer_frame_ms = res.reference_frame_ms = res.frame_time_ratio_to_reference = kNaN;
    res.observer_frame_cpu_ms = res.reference_frame_cpu_ms = res.frame_cpu_ratio_to_reference = kNaN;
  }

  // Event windows: each event is scored up to the next event (set-point change or push).
  std::vector<double> event_times;
  for (const auto& s : cfg.setpoints) event_times.push_back(s.t);
  for (const auto& p : cfg.pushes) event_times.push_back(p.t);
  std::sort(event_times.begin(), event_times.end());
  auto windowEnd = [&](double t0) {
    for (double e : event_times) {
      if (e > t0 + 1e-9) return std::min(e, cfg.duration);
    }
    return cfg.duration;
  };
  auto idx = [&](double t) {
    return static_cast<std::size_t>(std::lower_bound(tick_t.begin(), tick_t.end(), t - 1e-9) - tick_t.begin());
  };
  for (std::size_t i = 1; i < cfg.setpoints.size(); ++i) {
    const auto& sp = cfg.setpoints[i];
    const Eigen::Vector2d delta = sp.xy - cfg.setpoints[i - 1].xy;
    if (delta.norm() < cfg.min_step || sp.t >= cfg.duration) continue;
    const double t_end = windowEnd(sp.t);
    const Eigen::Vector2d u = delta.normalized();
    const double band = cfg.settle_fraction * delta.norm();
    StepMetrics m;
    m.t = sp.t;
    m.size_m = delta.norm();
    double last_out = sp.t, last_out_2d = sp.t, over = 0.0, ss_sum = 0.0;
    int ss_n = 0;
    for (std::size_t k = idx(sp.t); k < tick_t.size() && tick_t[k] < t_end - 1e-9; ++k) {
      const Eigen::Vector2d e = tick_p[k] - sp.xy;
      over = std::max(over, e.dot(u));
      if (std::abs(e.dot(u)) > band) last_out = tick_t[k];
      if (e.norm() > band) last_out_2d = tick_t[k];
      if (tick_t[k] >= t_end - cfg.steady_window) {
        ss_sum += e.norm();
        ++ss_n;
      }
    }
    m.overshoot_pct = 100.0 * over / delta.norm();
    m.settling_time_s = last_out >= t_end - 2.0 * kTick ? kInf : last_out - sp.t;
    m.settling_time_2d_s = last_out_2d >= t_end - 2.0 * kTick ? kInf : last_out_2d - sp.t;
    m.steady_state_error_mm = ss_n > 0 ? 1000.0 * ss_sum / ss_n : kNaN;
    res.steps.push_back(m);
  }
  for (const auto& p : cfg.pushes) {
    if (p.t >= cfg.duration) continue;
    const double t_end = windowEnd(p.t);
    PushMetrics m;
    m.t = p.t;
    m.speed = p.dv.norm();
    double last_out = p.t;
    for (std::size_t k = idx(p.t); k < tick_t.size() && tick_t[k] < t_end - 1e-9; ++k) {
      const double e = (tick_p[k] - setpointAt(tick_t[k])).norm();
      m.peak_excursion_mm = std::max(m.peak_excursion_mm, 1000.0 * e);
      if (e > cfg.push_band) last_out = tick_t[k];
    }
    m.recovery_s = last_out >= t_end - 2.0 * kTick ? kInf : last_out - p.t;
    res.pushes.push_back(m);
  }
  auto worst = [](const auto& v, auto field) {
    double w = v.empty() ? kNaN : -kInf;
    for (const auto& e : v) w = std::max(w, std::isnan(e.*field) ? kInf : e.*field);
    return w;
  };
  res.overshoot_pct = worst(res.steps, &StepMetrics::overshoot_pct);
  res.settling_time_s = worst(res.steps, &StepMetrics::settling_time_s);
  res.steady_state_error_mm = worst(res.steps, &StepMetrics::steady_state_error_mm);
  res.push_recovery_s = worst(res.pushes, &PushMetrics::recovery_s);
  if (hooks.log != nullptr) hooks.log->flush();
  res.wall_seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - wall0).count();
  return res;
}

}  // namespace viewline::scenarios
