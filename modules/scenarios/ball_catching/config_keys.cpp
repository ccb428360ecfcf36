// Unit and meaning of every key the ball_catching config reader (config.cpp) reads. The reference
// docs/config_reference.md is generated from this table and the recorded reads; the unit test
// ScenarioConfigKeys fails when a key is read without an entry here or an entry is never read.
#include "viewline/scenarios/config_keys.h"
#include "viewline/scenarios/ball_catching/config.h"
#include "viewline/runtime/faults.h"

namespace viewline::scenarios {

io::ConfigReferenceSection ballCatchingConfigReference() {
  io::ConfigReferenceSection s;
  s.name = "ball_catching";
  s.title = "Ball catching (`ball_catching`)";
  s.summary =
      "A ball (or dart) thrown at a box carried by a robot ([L] §VI.C): rendered cameras, the HSV "
      "detector, the viewline tracker, the catch planner and the robot.";
  s.shipped = {"ball_catching.yaml", "ball_catching_dart.yaml"};
  // No shipped file has inline cameras (both name a rig): a camera given by its geometry.
  s.probes = {
      "cameras:\n  - {name: a, position: [0.0, -3.0, 1.5], look_at: [2.0, 0.0, 1.3], cx: 320, cy: 240}\n"
      "robot: {kind: stage}\n",
      "source: {kind: recording, path: rec}\n", runtime::faultConfigProbe()};
  // A camera's footage: one probe per kind (a recording is refused per camera, so not probed).
  for (const std::string& p : runtime::sourceConfigProbes("    ")) {
    if (p.find("kind: recording") != std::string::npos) continue;
    s.probes.push_back("cameras:\n  - name: a\n    position: [0.0, -3.0, 1.5]\n    look_at: [2.0, 0.0, 1.3]\n" + p +
                       "robot: {kind: stage}\n");
  }
  s.read = [](const io::ConfigNode& root) { loadBallCatchingConfig(root); };
  s.keys = {
      {"name", "", "scenario name in summaries"},
      {"threads", "", "throws run in parallel (each throw has its own seed: same results), >= 1"},
      {"processing_latency_s", "s", "capture to the detection, tracker and planner update"},
      {"camera_count", "", "use the first N cameras (0: all)"},
      {"rate_override_hz", "Hz", "> 0: every camera at this rate during the throws (0: each camera's rate_hz)"},
      {"rig", "", "calibrated rig folder (truth renders, calibration estimates); absent: inline camera geometry"},
      {"true_cameras", "", "diagnosis: the estimators use the rig's true cameras instead of its calibration (the "
                           "detector's own error; with registration.enabled: false)", "false"},
      {"cameras", "", "the cameras, by name (with rig: cameras of the rig)"},
      {"cameras[].name", "", "camera name (with rig: a camera of the rig)"},
      {"cameras[].width", "px", "image width (inline camera, no rig)"},
      {"cameras[].height", "px", "image height (inline camera, no rig)"},
      {"cameras[].hfov_deg", "deg", "horizontal field of view (inline camera, no rig)"},
      {"cameras[].cx", "px", "principal point u0 (inline camera; absent: the image centre)"},
      {"cameras[].cy", "px", "principal point v0 (inline camera; absent: the image centre)"},
      {"cameras[].kud", "", "ViSP radial distortion coefficient, undistorted -> distorted (inline camera)"},
      {"cameras[].position", "m", "camera centre, world frame (inline camera: required with look_at)"},
      {"cameras[].look_at", "m", "a point on the optical axis, world frame (inline camera)"},
      {"cameras[].rate_hz", "Hz", "frame rate"},
      {"cameras[].clock_drift", "", "relative clock period error of the free-running camera"},
      {"cameras[].exposure_s", "s", "exposure: motion blur (0: none)"},
      {"cameras[].blur_samples", "", "renders averaged over the exposure"},
      {"cameras[].noise_sigma", "grey levels", "sensor noise (std)"},
      {"cameras[].drop_probability", "", "probability that a frame is lost"},
      {"cameras[].trigger_jitter_s", "s", "trigger-time jitter (std)"},
      {"cameras[].stamp_jitter_s", "s", "time-stamp jitter (std)"},
      {"noise_sigma_override", "grey levels", ">= 0: every camera's noise_sigma (the noise table); < 0: each camera's own"},
      {"throws", "", "the thrown object"},
      {"throws.release_min", "m", "release point box, lower corner (world frame)"},
      {"throws.release_max", "m", "release point box, upper corner (world frame)"},
      {"throws.aim_radius", "m", "aim points uniform in this disc around home (box plane)"},
      {"throws.speed_min", "m/s", "smallest mean horizontal speed"},
      {"throws.speed_max", "m/s", "largest mean horizontal speed"},
      {"throws.ball_mass", "kg", "ball mass (air drag)"},
      {"throws.ball_radius", "m", "ball radius"},
      {"throws.drag_coefficient", "", "drag coefficient Cd"},
      {"throws.air_density", "kg/m³", "air density"},
      {"throws.ball_albedo_bgr", "", "ball colour, blue-green-red reflectance in [0, 1] (dart: the flights)"},
      {"throws.object", "", "ball (a sphere) or dart (sim::makeDart along its velocity; the flights are tracked)"},
      {"box", "", "the box on the robot"},
      {"box.hole_radius", "m", "radius of the hole the ball must pass (> ball radius)"},
      {"box.normal", "", "box-front normal, towards the thrower (normalised)"},
      {"box.size", "m", "cube side (rendered)"},
      {"box.render", "", "render the box in the images"},
      {"robot", "", "the robot carrying the box"},
      {"robot.kind", "", "stage (Cartesian gantry) or arm (vpViper850 kinematics and joint limits)"},
      {"robot.v_max", "m/s", "tool-point speed limit ([L]), measured as robot.limit_norm says"},
      {"robot.a_max", "m/s²", "tool-point acceleration limit ([L]), measured as robot.limit_norm says"},
      {"robot.limit_norm", "", "euclidean (|v| and |a| of the tool point: an arm) or per_axis (each world axis: a gantry)",
       "euclidean"},
      {"robot.latency_s", "s", "set point to motion"},
      {"robot.control_period_s", "s", "time between set points"},
      {"robot.home", "m", "hole centre at rest, world frame"},
      {"robot.workspace_min", "m", "workspace box, lower corner (world frame)", "home + [-0.1, -0.6, -0.5]"},
      {"robot.workspace_max", "m", "workspace box, upper corner (world frame)", "home + [0.1, 0.6, 0.6]"},
      {"robot.arm", "", "arm geometry (required for kind: arm)"},
      {"robot.arm.base_position", "m", "arm base position, world frame"},
      {"robot.arm.base_yaw_deg", "deg", "arm base yaw about z"},
      {"robot.arm.tool_offset", "m", "flange to hole centre, flange frame"},
      {"robot.arm.joint_margin_deg", "deg", "margin kept from the joint limits"},
      {"detector", "", "the ball detector (vision::BallDetector: colour blob, sphere-centre correction)"},
      {"detector.hsv", "", "HSV range [hue_lo, hue_hi, s_lo, s_hi, v_lo, v_hi] (absent: the detector's orange)"},
      {"detector.min_area_px", "px", "blobs with fewer pixels are too small"},
      {"detector.noise_area_px", "px", "blobs below this are ignored altogether"},
      {"detector.min_roundness", "", "area / (π ρ²) below which a blob is no ball"},
      {"detector.roi_half_size_px", "px", "half side of the search window around a predicted position"},
      {"detector.open_kernel_px", "px", "elliptic opening kernel size (odd; 0 or 1: none)"},
      {"detector.close_kernel_px", "px", "elliptic closing kernel size (odd; 0 or 1: none)"},
      {"detector.sigma_px_floor", "px", "floor of the measurement std handed to the tracker"},
      {"detector.sigma_px", "px", "measured std of the detection per axis, told to the tracker (0: the blob's covariance, floored)", "0"},
      {"detector.pixel_noise_px", "px", "extra white noise on every detection, per axis (pixel-noise table; 0: none)"},
      {"tracker", "", "the viewline tracker (no-drag ballistic state (p, v))"},
      {"tracker.prior_position", "m", "prior position of a new track"},
      {"tracker.prior_velocity", "m/s", "prior velocity of a new track"},
      {"tracker.prior_std_position", "m", "prior std of the position"},
      {"tracker.prior_std_velocity", "m/s", "prior std of the velocity"},
      {"tracker.accel_psd", "m²/s³", "white acceleration of the model (absorbs the unmodelled drag)"},
      {"tracker.gate", "", "measurement gate: none, directional ([L] §V) or mahalanobis"},
      {"tracker.directional_p", "", "p of the directional gate of [L] §V"},
      {"tracker.mahalanobis_alpha", "", "false-rejection probability of the chi-square gate"},
      {"tracker.restart_after_rejections", "", "consecutive gated images of one camera before the track restarts"},
      {"tracker.max_coast_s", "s", "time without a fused image after which the next one starts a new track"},
      {"tracker.refit_young_tracks", "", "re-filter a track over its history while it has at most this many images (0: off)"},
      {"tracker.pixel_bias", "", "per-camera pixel bias in the tracker's state (first-order Gauss-Markov per axis)"},
      {"tracker.pixel_bias.sigma_px", "px", "stationary std of each camera's bias per axis (0: no bias state); "
                                            "detector.sigma_px is then the white part", "0"},
      {"tracker.pixel_bias.time_constant_s", "s", "correlation time τ of the bias (e^(−Δt/τ))", "1"},
      {"tracker.pixel_bias.unregistered_sigma_px", "px", "the bias std of a camera not registered to the robot "
                                                         "(its calibration error stays); 0: sigma_px for every camera", "0"},
      {"planner", "", "the catch planner (planning::CatchPlanner)"},
      {"planner.model", "", "flight model of the crossing prediction: drag or ballistic"},
      {"planner.accel_psd", "m²/s³", "process noise of the prediction"},
      {"planner.start_sigma_m", "m", "start moving below this crossing-point std"},
      {"planner.commit_sigma_m", "m", "commit to the target below this std"},
      {"planner.commit_min_updates", "", "fused images before a commitment"},
      {"planner.give_up", "", "go home when the committed target is unreachable (false: keep chasing)"},
      {"planner.give_up_late_s", "s", "a target reached later than the crossing plus this is unreachable"},
      {"planner.give_up_sigmas", "", "the give-up test takes the crossing this many std nearer the box and later (0: as predicted)", "0"},
      {"planner.home_delay_s", "s", "time after the predicted crossing before going home"},
      {"planner.min_lead_s", "s", "ignore crossings sooner than now + latency + this"},
      {"planner.target_prior_std_m", "m", "prior std of the crossing points per in-plane axis (0: no prior)"},
      {"planner.move_sigmas", "", "the goal's offset from home per in-plane axis shrunk by this many std (0: off)", "0"},
      {"registration", "", "camera-to-robot registration with a marker on the box, before the throws"},
      {"registration.enabled", "", "register the cameras (false: they keep their calibrated pose)"},
      {"registration.marker_offset", "m", "marker centre from the hole centre (world axes)"},
      {"registration.marker_radius", "m", "marker sphere radius"},
      {"registration.marker_albedo_bgr", "", "marker colour, blue-green-red reflectance in [0, 1]"},
      {"registration.marker_hsv", "", "HSV range of the marker [hue_lo, hue_hi, s_lo, s_hi, v_lo, v_hi]"},
      {"registration.offsets_x", "m", "set points from robot.home along x"},
      {"registration.offsets_y", "m", "set points from robot.home along y"},
      {"registration.offsets_z", "m", "set points from robot.home along z"},
      {"registration.min_points", "", "fewer marker detections: the camera keeps its calibrated pose (>= 6)"},
      {"registration.gate_px", "px", "detections farther than this from the expected pixel are dropped"},
      {"registration.max_rms_px", "px", "refuse a camera's registration above this reprojection RMS"},
      {"registration.max_shift_m", "m", "refuse a registration moving the camera centre more than this"},
      {"registration.max_rotation_deg", "deg", "refuse a registration rotating the camera more than this"},
      {"flight_fit", "", "drag-model batch fit of the track's images: the state the planner predicts from"},
      {"flight_fit.enabled", "", "false: the planner predicts from the tracker's drag-free estimate", "true"},
      {"flight_fit.min_images", "", "fused images before the fit is used (>= 6)", "8"},
      {"flight_fit.min_cameras", "", "distinct cameras among them (one viewline leaves the depth open)", "2"},
      {"flight_fit.max_iterations", "", "Gauss-Newton iterations per new image (warm-started)", "3"},
      {"flight_fit.prior_position", "m", "prior mean of the ball's position at the track's first image (world frame)", "[0, 0, 0]"},
      {"flight_fit.prior_velocity", "m/s", "prior mean of its velocity there (world frame)", "[0, 0, 0]"},
      {"flight_fit.prior_std_position", "m", "prior std per world axis of that position (0: no prior on the axis)", "[0, 0, 0]"},
      {"flight_fit.prior_std_velocity", "m/s", "prior std per world axis of that velocity (0: no prior on the axis)", "[0, 0, 0]"},
      {"flight_fit.aim_prior_std_m", "m", "prior std per in-plane axis of the crossing around the hole's home (0: none)", "0"},
      {"registration.robot_position_error_m", "m",
       "std per axis of the robot's positioning error while it shows the marker (simulated; 0: exact)", "0"},
      {"render", "", "rendering and the run of each throw"},
      {"render.supersampling", "", "renderer anti-aliasing sub-samples on edge pixels"},
      {"render.post_crossing_s", "s", "time simulated after the true crossing"},
      {"render.prediction_lead_s", "s", "the early-prediction metric uses the last prediction this long before the crossing"},
      {"room", "", "the rendered room"},
      {"room.walls", "", "render walls around the floor"},
      {"room.floor_size", "m", "side of the floor square"},
      {"source", "", "where the frames come from (absent: the rendered cameras)"},
      {"source.kind", "", "sim (the rendered cameras) or recording (a folder written by --record); footage goes per camera "
                          "(cameras[].source)"},
      {"source.path", "", "recording: the folder written by --record (as --replay)"},
  };
  for (io::ConfigKeyDoc& d : runtime::faultConfigKeys()) s.keys.push_back(std::move(d));
  // Footage per camera (ball_catching/footage.h): the runtime's `source:` keys under each camera.
  for (io::ConfigKeyDoc d : runtime::sourceConfigKeys()) {
    if (d.key == "source") {
      d.meaning = "this camera's footage (absent: rendered); every active camera has footage or none: one session "
                  "over it, no truth (ball_catching/footage.h)";
    } else if (d.key == "source.kind") {
      d.meaning = "sim (rendered), images, video or v4l2 (recording is the top-level source's)";
    } else if (d.key == "source.path") {
      d.meaning = "video: the file";
    }
    d.key = "cameras[]." + d.key;
    s.keys.push_back(std::move(d));
  }
  return s;
}

}  // namespace viewline::scenarios
