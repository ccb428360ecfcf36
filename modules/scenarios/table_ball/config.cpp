#include "viewline/scenarios/table_ball/config.h"

#include <filesystem>

#include "viewline/core/checks.h"
#include "viewline/core/error.h"
#include "viewline/core/frames.h"
#include "viewline/io/config_check.h"
#include "viewline/io/camera_fields.h"
#include "viewline/scenarios/simulated_rig.h"

namespace viewline::scenarios {

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
  const tracking::TrackGateConfig& gate = observer.tracker.gate;
  if (!(gate.probability > 0.0 && gate.probability <= 1.0)) {
    throw core::InvalidInput("observer.gate_probability: expected in (0, 1] (1: no gate)");
  }
  if (gate.restart_after < 1) throw core::InvalidInput("observer.restart_after: expected >= 1");
  if (width < 16 || height < 16) throw core::InvalidInput("camera.width/height: expected >= 16 pixels");
  core::requirePositive(hfov, "camera.hfov_deg");
  if (hfov >= core::kPi) throw core::InvalidInput("camera.hfov_deg: expected < 180");
  if (cx) core::requireFinite(*cx, "camera.cx");
  if (cy) core::requireFinite(*cy, "camera.cy");
  core::requirePositive(rate_hz, "camera.rate_hz");
  core::requireFinite(camera_position, "camera.position");
  core::requireFinite(camera_look_at, "camera.look_at");
  if ((camera_position - camera_look_at).norm() < 1e-3) throw core::InvalidInput("camera.look_at: equals camera.position");
  core::requireNonNegative(sway, "camera.sway_deg");
  core::requireNonNegative(sway_hz, "camera.sway_hz");
  core::requireNonNegative(sway_translation, "camera.sway_translation");
  core::requireNonNegative(ground_rotation_noise, "camera.ground_rotation_noise_deg");
  core::requireNonNegative(sensor_noise, "camera.sensor_noise");
  core::requireNonNegative(exposure, "camera.exposure");
  if (blur_samples < 1) throw core::InvalidInput("camera.blur_samples: expected >= 1");
  core::requireNonNegative(drop_probability, "camera.drop_probability");
  if (drop_probability >= 1.0) throw core::InvalidInput("camera.drop_probability: expected < 1");
  if (supersampling < 1 || supersampling > 8) throw core::InvalidInput("camera.supersampling: expected 1..8");
  core::requireNonNegative(latency, "controller.latency");
  if (latency < 0.5 * exposure) {
    throw core::InvalidInput("controller.latency: expected >= camera.exposure / 2 (a frame is processed after its exposure)");
  }
  if (latency >= 1.0 / rate_hz) throw core::InvalidInput("controller.latency: expected < one frame period");
  core::requireNonNegative(observer.table_pose_time_constant, "observer.table_pose_time_constant");
  if (observer.table_pose == TablePoseSource::AprilTag && !table_tags) {
    throw core::InvalidInput("observer.table_pose: apriltag needs table.tags: true");
  }
  core::requirePositive(duration, "duration");
  core::requireNonNegative(warmup, "metrics.warmup");
  core::requirePositive(min_step, "metrics.min_step");
  core::requirePositive(settle_fraction, "metrics.settle_fraction");
  core::requireNonNegative(settle_min_band, "metrics.settle_min_band");
  core::requireNonNegative(nis_spacing, "metrics.nis_spacing");
  core::requirePositive(nees_spacing, "metrics.nees_spacing");
  core::requirePositive(steady_window, "metrics.steady_window");
  core::requirePositive(push_band, "metrics.push_band");
  if (setpoints.empty()) throw core::InvalidInput("events.setpoints: expected at least one (at t = 0)");
  for (std::size_t i = 0; i < setpoints.size(); ++i) {
    const std::string w = "events.setpoints[" + std::to_string(i) + "]";
    core::requireNonNegative(setpoints[i].t, w + ".t");
    core::requireFinite(setpoints[i].xy, w + ".xy");
    if (setpoints[i].xy.cwiseAbs().maxCoeff() > lim) throw core::InvalidInput(w + ".xy: outside the reachable table area");
    if (i > 0 && setpoints[i].t <= setpoints[i - 1].t) throw core::InvalidInput(w + ".t: expected increasing times");
  }
  if (setpoints.front().t != 0.0) throw core::InvalidInput("events.setpoints[0].t: expected 0");
  for (std::size_t i = 0; i < pushes.size(); ++i) {
    const std::string w = "events.pushes[" + std::to_string(i) + "]";
    core::requireNonNegative(pushes[i].t, w + ".t");
    core::requireFinite(pushes[i].dv, w + ".dv");
    if (i > 0 && pushes[i].t <= pushes[i - 1].t) throw core::InvalidInput(w + ".t: expected increasing times");
  }
}

Eigen::Vector2d TableBallConfig::setpointAt(double t) const {
  Eigen::Vector2d r = setpoints.front().xy;
  for (const auto& s : setpoints) {
    if (s.t <= t) r = s.xy;
  }
  return r;
}

tracking::RollingBallTrackerConfig TableBallConfig::trackerConfig() const {
  tracking::RollingBallTrackerConfig c = observer.tracker;
  c.model.table_side = table_side;
  c.model.ball_radius = ball_radius;
  c.nominal_period = framePeriod();
  return c;
}

control::TableBalancerConfig TableBallConfig::controllerConfig(const robots::TableTilt& arm) const {
  const robots::TableTiltLimits& limits = arm.limits();
  control::TableBalancerConfig k = controller;
  k.period = framePeriod();
  k.delay = latency + limits.delay;  // capture -> ramp start, then the wrist's own delay
  k.max_angle = limits.max_angle;
  k.max_rate = limits.max_rate;
  return k;
}

namespace {

void readCamera(const io::ConfigNode& n, TableBallConfig& c) {
  if (c.rig) {
    io::refuseGeometryWithRig(n, c.rig->folder);
    c.width = c.rig->truth.width;
    c.height = c.rig->truth.height;
  } else {
    io::PinholeFields f;
    f.width = c.width;
    f.height = c.height;
    f.hfov_rad = c.hfov;
    f.position = c.camera_position;
    f.look_at = c.camera_look_at;
    io::readPinholeFields(n, f);
    // The renderer's and the observer's inline camera is distortion-free; a rig's truth.yaml
    // describes a distorted one.
    if (f.kud != 0.0) n.fail("kud", "0 (the inline camera has no distortion; use rig: for a distorted camera)");
    c.width = f.width;
    c.height = f.height;
    c.hfov = f.hfov_rad;
    c.cx = f.cx;
    c.cy = f.cy;
    c.camera_position = *f.position;
    c.camera_look_at = *f.look_at;
  }
  c.rate_hz = n.getOr<double>("rate_hz", c.rate_hz);
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

void readObserver(const io::ConfigNode& n, TableBallConfig& c) {
  c.observer.table_pose = n.getChoiceOr("table_pose", {"corners", "apriltag"}, "corners") == "apriltag"
                              ? TablePoseSource::AprilTag
                              : TablePoseSource::Corners;
  const std::string geometry = n.getChoiceOr("ball_geometry", {"table_plane", "known_radius", "unknown_radius"}, "table_plane");
  c.observer.ball_geometry = geometry == "known_radius"     ? BallGeometry::KnownRadius
                             : geometry == "unknown_radius" ? BallGeometry::UnknownRadius
                                                            : BallGeometry::TablePlane;
  auto& m = c.observer.tracker.model;
  m.sigma_w = n.getOr<double>("sigma_w", m.sigma_w);
  m.sigma_v = n.getOr<double>("sigma_v", m.sigma_v);
  m.beta = n.getOr<double>("beta", m.beta);
  m.prediction_steps = n.getOr<int>("prediction_steps", m.prediction_steps);
  c.observer.tracker.stationary_gain = n.getOr<bool>("stationary_gain", c.observer.tracker.stationary_gain);
  c.observer.tracker.initial_velocity_std = n.getOr<double>("initial_velocity_std", c.observer.tracker.initial_velocity_std);
  c.observer.tracker.impulse_nis = n.getOr<double>("impulse_nis", c.observer.tracker.impulse_nis);
  c.observer.tracker.impulse_std = n.getOr<double>("impulse_std", c.observer.tracker.impulse_std);
  c.observer.tracker.coloured_sigma = n.getOr<double>("coloured_sigma", c.observer.tracker.coloured_sigma);
  c.observer.tracker.coloured_correlation = n.getOr<double>("coloured_correlation", c.observer.tracker.coloured_correlation);
  c.observer.tracker.input_hold = n.getChoiceOr("input_hold", {"end", "ramp"}, "end") == "ramp"
                                     ? tracking::InputHold::Ramp
                                     : tracking::InputHold::End;
  auto& gate = c.observer.tracker.gate;
  gate.probability = n.getOr<double>("gate_probability", gate.probability);
  gate.restart_after = n.getOr<int>("restart_after", gate.restart_after);
  c.observer.detector.refine = n.getOr<bool>("refine", c.observer.detector.refine);
  c.observer.edge_tracking = n.getOr<bool>("edge_tracking", c.observer.edge_tracking);
  c.observer.table_pose_time_constant = n.getOr<double>("table_pose_time_constant", c.observer.table_pose_time_constant);
  c.border_aware_pnp = n.getOr<bool>("border_aware_pnp", c.border_aware_pnp);
}

}  // namespace

TableBallConfig tableBallConfigFromYaml(const io::ConfigNode& root) {
  TableBallConfig c;
  // First, so that the config reference's probe of each source kind reaches it.
  c.source = runtime::readSourceConfig(root);
  c.faults = runtime::readFaultPlanConfig(root);
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
      // A calibrated-only rig (no truth.yaml) cannot render: source: sim needs the truth.
      if (c.source.simulated()) loadSimulatedRig(folder).requireTruth("source: sim renders the frames");
      c.rig = loadTableRig(folder);
    } catch (const core::InvalidInput& e) {
      throw core::InvalidInput(root.location("rig") + ": key 'rig': " + e.what());
    }
  }
  readCamera(root.child("camera"), c);
  readObserver(root.child("observer"), c);
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
    c.settle_min_band = n.getOr<double>("settle_min_band", c.settle_min_band);
    c.nis_spacing = n.getOr<double>("nis_spacing", c.nis_spacing);
    c.nees_spacing = n.getOr<double>("nees_spacing", c.nees_spacing);
    c.steady_window = n.getOr<double>("steady_window", c.steady_window);
    c.push_band = n.getOr<double>("push_band", c.push_band);
    c.compare_tunings = n.getOr<bool>("compare_tunings", c.compare_tunings);
    c.time_reference = n.getOr<bool>("time_reference", c.time_reference);
  }
  io::finishAndValidate(root, c);
  return c;
}

TableBallConfig::RigCameras loadTableRig(const std::string& folder) {
  const SimulatedRig rig = loadSimulatedRig(folder);
  TableBallConfig::RigCameras out;
  out.folder = std::filesystem::path(rig.folder).lexically_normal().string();
  // A calibrated-only rig replays recorded frames: nothing renders, so the camera is its calibration.
  out.truth = rig.hasTruth() ? rig.trueCamera("head") : rig.calibratedCamera("head");
  out.calibrated = rig.calibratedCamera("head");
  // ground.yaml (camera-to-ground): the calibrated rotation of the head at rest to the ground
  // (z up), which is all the observer needs of the rest pose besides the nominal table prior.
  const Eigen::Matrix3d g_R_c = loadGroundRotation(rig, "head");
  out.calibrated.c_M_w.linear() = g_R_c.transpose();
  return out;
}

}  // namespace viewline::scenarios
