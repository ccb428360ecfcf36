#include "viewline/scenarios/pan_tilt/config.h"

#include <cmath>
#include <vector>

#include "viewline/core/checks.h"
#include "viewline/core/error.h"
#include "viewline/core/frames.h"
#include "viewline/io/config_check.h"
#include "viewline/io/camera_fields.h"
#include "viewline/io/rig.h"
#include "viewline/scenarios/simulated_rig.h"

namespace viewline::scenarios {

using Eigen::Vector2d;

namespace {
constexpr const char* kRigCamera = "ptu_camera";  ///< the camera's name in a pan-tilt rig folder
}  // namespace

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
  core::requireNonNegative(sensor_noise, "camera.sensor_noise");
  core::requireNonNegative(exposure, "camera.exposure");
  core::requireNonNegative(noise_fraction, "measurement_noise_fraction");
  unit.limits.validate();
  core::requireNonNegative(unit.latency, "unit.latency");
  if (hardware_unit) hardware_unit->validate();
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
  // First, so that the config reference's probe of each source kind reaches it (a probe is read up to
  // its first missing required key).
  PanTiltScenarioConfig c;
  c.source = runtime::readSourceConfig(root);
  c.faults = runtime::readFaultPlanConfig(root);
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
    // A rig: truth for the simulator (a simulated rig), calibration for the controllers.
    const SimulatedRig rig = loadSimulatedRig(root, "rig");
    const auto where = [&](const std::string& what) {
      return root.location("rig") + ": key '" + root.keyPath("rig") + "': " + what;
    };
    // A calibrated-only rig (no truth.yaml) cannot render: source: sim needs the truth.
    if (c.source.simulated()) {
      try {
        rig.requireTruth("source: sim renders the frames");
      } catch (const core::InvalidInput& e) {
        throw core::InvalidInput(where(e.what()));
      }
    }
    if (rig.hasTruth() && !rig.truth.e_M_c)
      throw core::InvalidInput(where(rig.folder + "/truth.yaml has no hand_eye section (not a pan-tilt rig)"));
    c.rig_folder = rig.folder;
    c.calibrated_camera = rig.calibratedCamera(kRigCamera);
    try {
      const auto he = io::ConfigNode::loadFile(rig.file("e_M_c.yaml"));  // calibrate-hand-eye output
      c.calibrated_e_M_c = io::readPose(he.child("e_M_c"));
      for (const char* k : {"r_M_o", "rms_translation_m", "rms_rotation_deg"}) he.ignore(k);
      he.finish();
    } catch (const core::InvalidInput& e) {
      throw core::InvalidInput(where(e.what()));
    }
    if (rig.hasTruth()) {
      c.true_camera = rig.trueCamera(kRigCamera);
      c.true_e_M_c = *rig.truth.e_M_c;
    } else {
      // Real frames: nothing is rendered, and the unit (simulated or a driver) carries the camera
      // where the calibration says it is, so the "true" camera and mount are the calibrated ones.
      c.true_camera = c.calibrated_camera;
      c.true_e_M_c = c.calibrated_e_M_c;
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
      // The rig's truth.yaml and rig.yaml give the camera. (io::readPinholeFields does not fit the
      // inline camera: [T]'s focal lengths fx, fy instead of a field of view, the principal point at
      // the image centre.)
      io::refuseGeometryWithRig(cam, c.rig_folder, {"width", "height", "fx", "fy"});
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
  if (root.has("robot")) {
    const auto r = root.child("robot");
    if (r.getChoice("kind", {"simulated", "flir_ptu"}) == "flir_ptu") {
      robots::FlirPtuConfig h;
      h.port = r.getOr<std::string>("port", "");
      h.baud = r.getOr<int>("baud", h.baud);
      h.tcp = r.getOr<std::string>("tcp", "");
      h.reply_timeout = r.getOr<double>("reply_timeout", h.reply_timeout);
      h.latency = r.getOr<double>("latency", c.unit.latency);
      c.hardware_unit = h;
    }
  }
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
    c.control.filter.model = tracking::targetModelFromString(
        f.getChoice("model", {"constant_velocity", "cv", "constant_acceleration", "ca", "singer", "coordinated_turn",
                              "ct", "imm", "waypoint_particles", "mixture"}));
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
    c.control.filter.mixture_switch_rate =
        f.getOr<double>("mixture_switch_rate", c.control.filter.mixture_switch_rate);
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
  io::finishAndValidate(root, c);
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

const char* pathShapeName(sim::PathShape s) {
  switch (s) {
    case sim::PathShape::Rectangle: return "rectangle";
    case sim::PathShape::Circle: return "circle";
    case sim::PathShape::Random: return "random";
  }
  return "?";
}

}  // namespace viewline::scenarios
