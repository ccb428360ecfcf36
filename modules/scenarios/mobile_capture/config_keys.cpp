// Unit and meaning of every key the mobile_capture config reader (config.cpp) reads. The reference
// docs/config_reference.md is generated from this table and the recorded reads; the unit test
// ScenarioConfigKeys fails when a key is read without an entry here or an entry is never read.
#include "viewline/scenarios/config_keys.h"
#include "viewline/runtime/faults.h"
#include "viewline/runtime/source_config.h"
#include "viewline/scenarios/mobile_capture/config.h"

namespace viewline::scenarios {

io::ConfigReferenceSection mobileCaptureConfigReference() {
  io::ConfigReferenceSection s;
  s.name = "mobile_capture";
  s.title = "Mobile capture (`mobile_capture`)";
  s.summary =
      "A differential-drive robot with a pan-tilt head camera and a gripper intercepts and grasps an "
      "object moving on the floor ([K]). Every section is optional (defaults: "
      "`MobileCaptureConfig::defaults()`).";
  s.shipped = {"mobile_capture.yaml"};
  // The shipped file names a rig: the inline camera's field of view too.
  s.probes = {"camera: {width: 640, height: 480, hfov_deg: 50, vfov_deg: 40}\n", runtime::faultConfigProbe()};
  for (const std::string& p : runtime::sourceConfigProbes("")) s.probes.push_back(p);
  s.read = [](const io::ConfigNode& root) { loadMobileCaptureConfig(root); };
  s.keys = {
      {"world", "", "the floor, the robot and the object"},
      {"world.robot_start", "m", "robot start position on the floor"},
      {"world.robot_heading_deg", "deg", "robot start heading"},
      {"world.object_start", "m", "object start position on the floor"},
      {"world.object_heading_deg", "deg", "object start heading"},
      {"world.object_noise", "", "ξv, ξω of [K] on the object's profile (false: the nominal profile)"},
      {"world.max_time", "s", "a run without capture by then is a failure"},
      {"world.floor_size", "m", "side of the textured floor square centred at the origin"},
      {"world.blackout_start", "s", "camera covered from then (< 0: never)"},
      {"world.blackout_duration", "s", "length of the blackout: the target is lost and must be found again"},
      {"timing", "", "periods"},
      {"timing.vision_period", "s", "vision and filter step ([K]); also the profile step and the planner's period"},
      {"timing.control_period", "s", "wheel PID period ([K])"},
      {"camera", "", "the head camera (geometry from rig:, else the inline keys)"},
      {"rig", "", "calibrated rig folder (truth renders, calibration estimates); absent: inline camera geometry"},
      {"camera.width", "px", "image width (inline camera, no rig)"},
      {"camera.height", "px", "image height (inline camera, no rig)"},
      {"camera.hfov_deg", "deg", "horizontal field of view (inline camera, no rig)"},
      {"camera.kud", "", "read by the shared camera reader but refused when present: the head camera has no distortion"},
      {"camera.vfov_deg", "deg", "vertical field of view (inline camera, no rig)"},
      {"camera.sensor_noise", "grey levels", "sensor noise (std)"},
      {"camera.supersampling", "", "renderer anti-aliasing sub-samples on edge pixels"},
      {"head", "", "the pan-tilt head (DH)"},
      {"head.l1", "m", "DH length l1"},
      {"head.l2", "m", "DH length l2"},
      {"head.l3", "m", "DH length l3"},
      {"head.tilt_min_deg", "deg", "tilt joint lower limit"},
      {"head.tilt_max_deg", "deg", "tilt joint upper limit"},
      {"head.pan_min_deg", "deg", "pan joint lower limit"},
      {"head.pan_max_deg", "deg", "pan joint upper limit"},
      {"head.tilt_rate_max_deg", "deg/s", "tilt rate limit"},
      {"head.pan_rate_max_deg", "deg/s", "pan rate limit"},
      {"base", "", "the differential-drive base"},
      {"base.track", "m", "distance between the wheels"},
      {"base.max_speed", "m/s", "speed limit ([K]); also the planner's robot speed"},
      {"base.max_turn_rate_deg", "deg/s", "turn-rate limit"},
      {"base.wheel_speed_max", "m/s", "wheel rim speed limit"},
      {"base.motor_time_constant", "s", "wheel motor time constant"},
      {"base.kp", "", "wheel PID proportional gain"},
      {"base.ki", "", "wheel PID integral gain"},
      {"base.kd", "", "wheel PID derivative gain"},
      {"base.encoder_noise", "", "wheel encoder noise (std)"},
      {"base.command_timeout", "s", "the base's command watchdog: no command for this long and it brakes to rest (0: none; robot faults)"},
      {"gripper", "", "the gripper zones, robot frame"},
      {"gripper.jaws", "m", "[x_min, x_max, half_width]: the grasp succeeds when the true object is here"},
      {"gripper.trigger", "m", "[x_min, x_max, half_width]: the gripper closes when the estimated object is here"},
      {"gripper.reach", "m", "reach from the axle, used by the planner"},
      {"gripper.grasp_cooldown", "s", "wait after a missed grasp"},
      {"detector", "", "the object detector (colour blob)"},
      {"detector.hsv", "", "HSV range [hue_lo, hue_hi, s_lo, s_hi, v_lo, v_hi] (absent: red)"},
      {"detector.min_area_px", "px", "blobs with fewer pixels are too small"},
      {"detector.min_roundness", "", "area / (π ρ²) below which a blob is rejected"},
      {"detector.roi_half_size_px", "px", "half side of the search window around a predicted position"},
      {"detector.pixel_sigma", "px", "white blob-centre noise: R = σ² J Jᵀ with J the ground-projection Jacobian"},
      {"detector.floor_sigma", "m", "std of the blob centroid's offset from the box centre (a bias: in the object's covariance, not in R)"},
      {"detector.calibration_angle_sigma_deg", "deg", "std of the calibrated camera-to-ground rotation about each axis (a bias: in the object's covariance, not in R)"},
      {"detector.calibration_height_sigma", "m", "std of the calibrated camera height (a bias: in the object's covariance, not in R)"},
      {"detector.object_height", "m", "measurements on the plane z = height / 2"},
      {"filter", "", "the object's EKF and predictor ([K])"},
      {"filter.q_v", "m²/s³", "speed random-walk density"},
      {"filter.q_w", "rad²/s³", "turn-rate random-walk density"},
      {"filter.input_sigma_v", "m/s", "held speed noise per input period (0: none)"},
      {"filter.input_sigma_w", "rad/s", "held turn-rate noise per input period (0: none)"},
      {"filter.input_period", "s", "period over which the held input noise is constant"},
      {"filter.init_speed", "m/s", "initial speed (the two-point start measures it)"},
      {"filter.init_speed_sigma", "m/s", "initial speed std"},
      {"filter.init_turn_sigma", "rad/s", "initial turn-rate std"},
      {"filter.gate_probability", "", "probability of the chi-square gate"},
      {"filter.predictor_window", "", "samples of the least-squares predictor ([K] eqs 27-29)"},
      {"filter.max_accel_v", "m/s²", "clamp of the predictor's linear acceleration (0: constant v)"},
      {"filter.max_accel_omega", "rad/s²", "clamp of the predictor's angular acceleration (0: constant ω)"},
      {"planner", "", "the interception planner ([K] eq 30)"},
      {"planner.horizon_steps", "", "M of [K] eq 30, in vision periods"},
      {"planner.turn_rate_deg", "deg/s", "charge the initial turn at this rate (0: as [K])"},
      {"control", "", "the go-to controller"},
      {"control.k_heading", "1/s", "heading gain"},
      {"control.stop_distance", "m", "stop within this distance of the target point"},
      {"control.slow_distance", "m", "slow down within this distance"},
      {"search", "", "searching for a lost object"},
      {"search.lost_after", "s", "object lost after this long unseen"},
      {"search.search_after", "s", "search starts after this long lost"},
      {"search.sweep_amplitude_deg", "deg", "head sweep amplitude"},
      {"search.sweep_period", "s", "head sweep period"},
      {"search.search_range", "m", "range of the search"},
      {"search.base_turn_rate_deg", "deg/s", "base turn rate while searching"},
      {"filter_test", "", "the filter test of [K] §3.2"},
      {"filter_test.duration", "s", "length of each filter-test run"},
      {"filter_test.measurement_var_cm2", "cm²", "measurement variance per axis"},
      {"filter_test.q_v", "m²/s³", "the EKF's speed random-walk density in the test"},
      {"filter_test.q_w", "rad²/s³", "the EKF's turn-rate random-walk density in the test"},
      {"filter_test.convergence_time", "s", "RMSE taken after this"},
      {"filter_test.runs", "", "runs of the filter test"},
      {"fov_sweep", "", "the field-of-view sweep (ground localisation check)"},
      {"fov_sweep.poses", "", "random head and base poses"},
      {"fov_sweep.points", "", "floor points per pose"},
      {"fov_sweep.pixel_sigma", "px", "noise added to the projected pixels"},
      {"threads", "", "parallel runs"},
  };
  // sim and recording run the batch; images, video and v4l2 one footage session (mobile_capture/footage.h).
  for (const io::ConfigKeyDoc& k : runtime::sourceConfigKeys()) s.keys.push_back(k);
  for (io::ConfigKeyDoc& d : runtime::faultConfigKeys()) s.keys.push_back(std::move(d));
  return s;
}

}  // namespace viewline::scenarios
