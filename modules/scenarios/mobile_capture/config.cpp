#include "viewline/scenarios/mobile_capture/config.h"

#include <cmath>
#include <filesystem>
#include <sstream>
#include <vector>

#include "viewline/core/checks.h"
#include "viewline/core/error.h"
#include "viewline/core/frames.h"
#include "viewline/io/config_check.h"
#include "viewline/io/camera_fields.h"
#include "viewline/scenarios/mobile_capture/recording.h"
#include "viewline/scenarios/simulated_rig.h"

namespace viewline::scenarios {

using Eigen::Vector3d;

MobileCaptureConfig MobileCaptureConfig::defaults() {
  MobileCaptureConfig c;
  // Red object: hue wraps through 0; saturated and not too dark. Small, box-shaped blobs: no
  // opening (it would erase a 5-pixel blob far away), lenient roundness (a box is no disc).
  c.detector.hsv = vision::ColorRange{170, 10, 120, 255, 50, 255};
  c.detector.open_kernel_px = 0;
  c.detector.close_kernel_px = 3;
  c.detector.min_area_px = 4.0;
  c.detector.noise_area_px = 2.0;
  c.detector.min_roundness = 0.2;
  c.detector.good_roundness = 0.45;
  c.detector.roi_half_size_px = 40.0;
  c.planner.reach = 0.2;
  c.planner.turn_rate = 1.5;
  c.base.command_timeout = 0.5;  // s: ROS diff_drive_controller's cmd_vel_timeout default
  return c;
}

planning::CapturePlannerParams MobileCaptureConfig::plannerParams() const {
  planning::CapturePlannerParams p = planner;
  p.period = vision_period;
  p.robot_speed = base.max_speed;
  return p;
}

control::GoToPointParams MobileCaptureConfig::goParams() const {
  control::GoToPointParams g = go;
  g.max_speed = base.max_speed;
  g.max_turn_rate = base.max_turn_rate;
  return g;
}

void MobileCaptureConfig::validate() const {
  core::requireFinite(robot_start, "robot_start");
  core::requireFinite(object_start, "object_start");
  core::requireFinite(robot_heading, "robot_heading");
  core::requireFinite(object_heading, "object_heading");
  core::requirePositive(max_time, "max_time");
  core::requirePositive(floor_size, "floor_size");
  core::requirePositive(vision_period, "vision_period");
  core::requirePositive(base.control_period, "timing.control_period");
  const double ratio = vision_period / controlPeriod();
  if (std::abs(ratio - std::round(ratio)) > 1e-9 || ratio < 1.0) {
    throw core::InvalidInput("vision_period: expected an integer multiple of control_period");
  }
  if (width < 16 || height < 16) throw core::InvalidInput("camera width/height: expected >= 16 px");
  core::requirePositive(hfov, "camera hfov");
  core::requirePositive(vfov, "camera vfov");
  core::requireNonNegative(sensor_noise, "sensor_noise");
  if (supersampling < 1) throw core::InvalidInput("supersampling: expected >= 1");
  head.validate();
  base.validate();
  detector.validate();
  core::requirePositive(pixel_sigma, "pixel_sigma");
  core::requirePositive(floor_sigma, "floor_sigma");
  core::requireNonNegative(calibration_angle_sigma, "calibration_angle_sigma_deg");
  core::requireNonNegative(calibration_height_sigma, "calibration_height_sigma");
  core::requirePositive(object_height, "object_height");
  filter.validate("filter");
  core::requireNonNegative(max_accel_v, "max_accel_v");
  core::requireNonNegative(max_accel_omega, "max_accel_omega");
  if (horizon_steps < 1) throw core::InvalidInput("horizon_steps: expected >= 1");
  plannerParams().validate();
  goParams().validate();
  search.validate();
  core::requirePositive(filter_test_duration, "filter_test.duration");
  core::requirePositive(filter_test_measurement_var, "filter_test.measurement_var_cm2");
  if (convergence_time < 0.0 || convergence_time >= filter_test_duration) {
    throw core::InvalidInput("filter_test.convergence_time: expected in [0, duration)");
  }
  if (filter_test_runs < 1) throw core::InvalidInput("filter_test.runs: expected >= 1");
  if (fov_sweep_poses < 1 || fov_sweep_points < 1) throw core::InvalidInput("fov_sweep: expected poses, points >= 1");
  if (threads < 1) throw core::InvalidInput("threads: expected >= 1");
}

namespace {

template <class T>
void readOpt(const io::ConfigNode& n, const std::string& key, T& value) {
  value = n.getOr<T>(key, value);
}
void readAngle(const io::ConfigNode& n, const std::string& key, double& value) {
  value = n.getAngleOr(key, value);
}
void positive(const io::ConfigNode& n, const std::string& key, double v) {
  if (!(v > 0.0) || !std::isfinite(v)) n.fail(key, "a positive number");
}

}  // namespace

MobileCaptureConfig loadMobileCaptureConfig(const io::ConfigNode& root) {
  MobileCaptureConfig c = MobileCaptureConfig::defaults();
  c.faults = runtime::readFaultPlanConfig(root);  // first: the config reference's probe reaches it
  c.source = readMobileCaptureSource(root);  // sim, a recording (recording.h) or footage (footage.h)
  if (root.has("world")) {
    const auto w = root.child("world");
    readOpt(w, "robot_start", c.robot_start);
    readAngle(w, "robot_heading_deg", c.robot_heading);
    readOpt(w, "object_start", c.object_start);
    readAngle(w, "object_heading_deg", c.object_heading);
    readOpt(w, "object_noise", c.object_noise);
    readOpt(w, "max_time", c.max_time);
    positive(w, "max_time", c.max_time);
    readOpt(w, "floor_size", c.floor_size);
    positive(w, "floor_size", c.floor_size);
    readOpt(w, "blackout_start", c.blackout_start);
    readOpt(w, "blackout_duration", c.blackout_duration);
    if (c.blackout_duration < 0.0) w.fail("blackout_duration", "a duration >= 0 s");
  }
  if (root.has("timing")) {
    const auto t = root.child("timing");
    readOpt(t, "vision_period", c.vision_period);
    positive(t, "vision_period", c.vision_period);
    readOpt(t, "control_period", c.base.control_period);
    positive(t, "control_period", c.base.control_period);
  }
  if (root.has("camera")) {
    const auto cam = root.child("camera");
    if (root.has("rig")) io::refuseGeometryWithRig(cam, root.getPath("rig"), {"width", "height", "hfov_deg", "vfov_deg"});
    // The head's joints place the camera, and the inline camera is a perfect pinhole centred on
    // the image: the shared keys that say otherwise are refused rather than ignored.
    for (const char* key : {"cx", "cy", "kud", "position", "look_at"}) {
      if (cam.has(key)) cam.fail(key, "no such key for the head camera (pose from the head joints; principal point at the image centre, no distortion)");
    }
    io::PinholeFields pinhole;
    pinhole.width = c.width;
    pinhole.height = c.height;
    pinhole.hfov_rad = c.hfov;
    io::readPinholeFields(cam, pinhole);
    c.width = pinhole.width;
    c.height = pinhole.height;
    c.hfov = pinhole.hfov_rad;
    readAngle(cam, "vfov_deg", c.vfov);
    readOpt(cam, "sensor_noise", c.sensor_noise);
    readOpt(cam, "supersampling", c.supersampling);
  }
  if (root.has("head")) {
    const auto h = root.child("head");
    readOpt(h, "l1", c.head.l1);
    readOpt(h, "l2", c.head.l2);
    readOpt(h, "l3", c.head.l3);
    readAngle(h, "tilt_min_deg", c.head.tilt_min);
    readAngle(h, "tilt_max_deg", c.head.tilt_max);
    readAngle(h, "pan_min_deg", c.head.pan_min);
    readAngle(h, "pan_max_deg", c.head.pan_max);
    readAngle(h, "tilt_rate_max_deg", c.head.tilt_rate_max);
    readAngle(h, "pan_rate_max_deg", c.head.pan_rate_max);
  }
  if (root.has("base")) {
    const auto b = root.child("base");
    readOpt(b, "track", c.base.track);
    readOpt(b, "max_speed", c.base.max_speed);
    readAngle(b, "max_turn_rate_deg", c.base.max_turn_rate);
    readOpt(b, "wheel_speed_max", c.base.wheel_speed_max);
    readOpt(b, "motor_time_constant", c.base.motor_time_constant);
    readOpt(b, "kp", c.base.kp);
    readOpt(b, "ki", c.base.ki);
    readOpt(b, "kd", c.base.kd);
    readOpt(b, "encoder_noise", c.base.encoder_noise);
    readOpt(b, "command_timeout", c.base.command_timeout);
    if (!(c.base.command_timeout >= 0.0)) b.fail("command_timeout", "a time >= 0 s (0: no watchdog)");
  }
  if (root.has("gripper")) {
    const auto g = root.child("gripper");
    const auto jaws = g.getOr<std::vector<double>>("jaws", {c.jaws.x_min, c.jaws.x_max, c.jaws.half_width});
    const auto trig =
        g.getOr<std::vector<double>>("trigger", {c.trigger.x_min, c.trigger.x_max, c.trigger.half_width});
    if (jaws.size() != 3 || !(jaws[0] < jaws[1]) || !(jaws[2] > 0)) g.fail("jaws", "[x_min, x_max, half_width] with x_min < x_max, half_width > 0");
    if (trig.size() != 3 || !(trig[0] < trig[1]) || !(trig[2] > 0)) g.fail("trigger", "[x_min, x_max, half_width] with x_min < x_max, half_width > 0");
    c.jaws = {jaws[0], jaws[1], jaws[2]};
    c.trigger = {trig[0], trig[1], trig[2]};
    readOpt(g, "reach", c.planner.reach);
    readOpt(g, "grasp_cooldown", c.grasp_cooldown);
  }
  if (root.has("detector")) {
    const auto d = root.child("detector");
    if (d.has("hsv")) {
      const auto v = d.get<std::vector<int>>("hsv");
      if (v.size() != 6) d.fail("hsv", "[hue_lo, hue_hi, s_lo, s_hi, v_lo, v_hi]");
      c.detector.hsv = vision::ColorRange{v[0], v[1], v[2], v[3], v[4], v[5]};
    }
    readOpt(d, "min_area_px", c.detector.min_area_px);
    readOpt(d, "min_roundness", c.detector.min_roundness);
    readOpt(d, "roi_half_size_px", c.detector.roi_half_size_px);
    readOpt(d, "pixel_sigma", c.pixel_sigma);
    readOpt(d, "floor_sigma", c.floor_sigma);
    readAngle(d, "calibration_angle_sigma_deg", c.calibration_angle_sigma);
    readOpt(d, "calibration_height_sigma", c.calibration_height_sigma);
    readOpt(d, "object_height", c.object_height);
  }
  if (root.has("filter")) {
    const auto f = root.child("filter");
    readOpt(f, "q_v", c.filter.model.q_v);
    readOpt(f, "q_w", c.filter.model.q_w);
    readOpt(f, "input_sigma_v", c.filter.model.input_sigma_v);
    readOpt(f, "input_sigma_w", c.filter.model.input_sigma_w);
    readOpt(f, "input_period", c.filter.model.input_period);
    readOpt(f, "init_speed", c.init_speed);
    readOpt(f, "init_speed_sigma", c.filter.init_speed_sigma);
    readOpt(f, "init_turn_sigma", c.filter.init_turn_sigma);
    readOpt(f, "gate_probability", c.filter.gate.probability);
    readOpt(f, "predictor_window", c.filter.predictor_window);
    readOpt(f, "max_accel_v", c.max_accel_v);
    readOpt(f, "max_accel_omega", c.max_accel_omega);
  }
  if (root.has("planner")) {
    const auto p = root.child("planner");
    readOpt(p, "horizon_steps", c.horizon_steps);
    readAngle(p, "turn_rate_deg", c.planner.turn_rate);
  }
  if (root.has("control")) {
    const auto k = root.child("control");
    readOpt(k, "k_heading", c.go.k_heading);
    readOpt(k, "stop_distance", c.go.stop_distance);
    readOpt(k, "slow_distance", c.go.slow_distance);
  }
  if (root.has("search")) {
    const auto s = root.child("search");
    readOpt(s, "lost_after", c.search.lost_after);
    readOpt(s, "search_after", c.search.search_after);
    readAngle(s, "sweep_amplitude_deg", c.search.sweep_amplitude);
    readOpt(s, "sweep_period", c.search.sweep_period);
    readOpt(s, "search_range", c.search.search_range);
    readAngle(s, "base_turn_rate_deg", c.search.base_turn_rate);
  }
  if (root.has("filter_test")) {
    const auto f = root.child("filter_test");
    readOpt(f, "duration", c.filter_test_duration);
    readOpt(f, "measurement_var_cm2", c.filter_test_measurement_var);
    readOpt(f, "q_v", c.filter_test_q_v);
    readOpt(f, "q_w", c.filter_test_q_w);
    readOpt(f, "convergence_time", c.convergence_time);
    readOpt(f, "runs", c.filter_test_runs);
  }
  if (root.has("fov_sweep")) {
    const auto f = root.child("fov_sweep");
    readOpt(f, "poses", c.fov_sweep_poses);
    readOpt(f, "points", c.fov_sweep_points);
    readOpt(f, "pixel_sigma", c.fov_sweep_pixel_sigma);
  }
  readOpt(root, "threads", c.threads);
  if (root.has("rig")) {
    const std::string folder = root.getPath("rig");
    try {
      c.rig = loadMobileRig(folder, c.head);
    } catch (const core::InvalidInput& e) {
      throw core::InvalidInput(root.location("rig") + ": key 'rig': " + e.what());
    }
    c.width = c.rig->truth.width;
    c.height = c.rig->truth.height;
    // [K]'s angle-per-pixel method with the calibrated view angles.
    c.hfov = 2.0 * std::atan(0.5 * c.width / c.rig->calibrated.intrinsics.get_px());
    c.vfov = 2.0 * std::atan(0.5 * c.height / c.rig->calibrated.intrinsics.get_py());
  }
  io::finishAndValidate(root, c);
  return c;
}

MobileCaptureConfig::RigCameras loadMobileRig(const std::string& folder, const robots::MobilePanTiltParams& head_params) {
  const SimulatedRig rig = loadSimulatedRig(folder);
  MobileCaptureConfig::RigCameras out;
  out.folder = std::filesystem::path(rig.folder).lexically_normal().string();
  out.truth = rig.trueCamera("head");
  out.calibrated = rig.calibratedCamera("head");
  const Eigen::Matrix3d g_R_c = loadGroundRotation(rig, "head");  // checked against rig.yaml
  out.calibrated.c_M_w.linear() = g_R_c.transpose();
  // The rest joints q0: the head pointing its optical axis where truth.yaml's camera looks; then
  // truth.yaml's pose must be the DH camera at q0 (the simulator renders the DH head).
  head_params.validate();
  const robots::MobilePanTilt head(head_params);
  const Eigen::Isometry3d w_M_c = out.truth.c_M_w.inverse();
  out.q0 = head.pointAtBest(w_M_c * Vector3d(0.0, 0.0, 2.0));
  const Eigen::Isometry3d dh = robots::headCamera_c_M_w(head, out.q0, 0.0, 0.0, 0.0);
  const double pos_off = (dh.inverse().translation() - w_M_c.translation()).norm();
  const double rot_off = core::rotationAngle(dh.linear(), out.truth.c_M_w.linear());
  if (pos_off > 1e-3 || rot_off > core::deg2rad(0.05)) {
    std::ostringstream msg;
    msg << rig.file("truth.yaml") << ": camera 'head' is not the head's DH camera (head: l1, l2, l3) at any joints: "
        << "closest (tilt " << core::rad2deg(out.q0.tilt) << " deg, pan " << core::rad2deg(out.q0.pan) << " deg) is "
        << 1000.0 * pos_off << " mm and " << core::rad2deg(rot_off) << " deg off";
    throw core::InvalidInput(msg.str());
  }
  out.cal_M_c = out.calibrated.c_M_w * dh.inverse();
  return out;
}

}  // namespace viewline::scenarios
