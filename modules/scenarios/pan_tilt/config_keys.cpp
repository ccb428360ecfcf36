// Unit and meaning of every key the pan_tilt config reader (config.cpp) reads. The reference
// docs/config_reference.md is generated from this table and the recorded reads; the unit test
// ScenarioConfigKeys fails when a key is read without an entry here or an entry is never read.
#include "viewline/scenarios/config_keys.h"
#include "viewline/runtime/faults.h"
#include "viewline/scenarios/pan_tilt/config.h"

namespace viewline::scenarios {

io::ConfigReferenceSection panTiltConfigReference() {
  io::ConfigReferenceSection s;
  s.name = "pan_tilt";
  s.title = "Pan-tilt tracking (`pan_tilt_tracking`)";
  s.summary =
      "A pan-tilt unit keeps a disc moving on a screen centred in its camera ([T]): path, screen, "
      "camera, unit, detector, control law and target filter.";
  s.shipped = {"pan_tilt_circle.yaml", "pan_tilt_random.yaml", "pan_tilt_rectangle.yaml"};
  // No shipped file has the inline camera (all name a rig): the camera given by its intrinsics.
  s.probes = {
      "path: {shape: circle, speed: 0.1}\nscreen: {distance: 1.3, center_height: 0.0, disc_radius: 0.03}\n"
      "camera: {width: 640, height: 480, fx: 900, fy: 900, fps: 30}\n",
      // The FLIR PTU branch of `robot` (no shipped file drives hardware).
      "path: {shape: circle, speed: 0.1}\nscreen: {distance: 1.3, center_height: 0.0, disc_radius: 0.03}\n"
      "camera: {width: 640, height: 480, fx: 900, fy: 900, fps: 30}\nmeasurement_noise_fraction: 0.1\n"
      "unit: {pan_limits_deg: [-150, 150], tilt_limits_deg: [-47, 31], max_speed_deg: 300, max_acceleration_deg: 1200, "
      "latency: 0.03}\nprocessing_delay: 0.01\n"
      "robot: {kind: flir_ptu, port: /dev/ttyUSB0, baud: 9600, tcp: '127.0.0.1:4000', reply_timeout: 0.5, latency: 0.03}\n"};
  for (const std::string& p : runtime::sourceConfigProbes("")) s.probes.push_back(p);
  s.read = [](const io::ConfigNode& root) { loadPanTiltScenarioConfig(root); };
  s.keys = {
      {"path", "", "the target's path on the screen"},
      {"path.shape", "", "rectangle, circle or random (a polyline through uniform random points in the box)"},
      {"path.speed", "m/s", "constant speed along the path"},
      {"path.center", "m", "path centre on the screen (x right, y down) from the screen centre"},
      {"path.width", "m", "rectangle (and random box) width"},
      {"path.height", "m", "rectangle (and random box) height"},
      {"path.radius", "m", "circle radius"},
      {"path.corner_radius", "m", "each waypoint rounded by an arc of this radius (random only; 0: sharp polyline)"},
      {"screen", "", "the screen the disc moves on"},
      {"screen.distance", "m", "screen plane along +x of the unit"},
      {"screen.center_height", "m", "height of the screen (and path) centre relative to the unit's base origin"},
      {"screen.width", "m", "screen width"},
      {"screen.height", "m", "screen height"},
      {"screen.disc_radius", "m", "radius of the projected dark disc"},
      {"rig", "", "calibrated pan-tilt rig folder (truth renders, calibration and hand-eye control); absent: inline camera"},
      {"camera", "", "the camera on the unit"},
      {"camera.width", "px", "image width (inline camera, no rig)"},
      {"camera.height", "px", "image height (inline camera, no rig)"},
      {"camera.fx", "px", "focal length along x (inline camera, no rig)"},
      {"camera.fy", "px", "focal length along y (inline camera, no rig)"},
      {"camera.fps", "Hz", "frames per second (the control rate)"},
      {"camera.sensor_noise", "grey levels", "additive Gaussian noise per pixel (std)"},
      {"camera.exposure", "s", "exposure: motion blur (0: none)"},
      {"measurement_noise_fraction", "", "white noise on the measured target, as a fraction of the signal amplitude per axis ([T])"},
      {"unit", "", "the simulated pan-tilt unit (FLIR PTU-D46)"},
      {"unit.pan_limits_deg", "deg", "pan joint limits [min, max]"},
      {"unit.tilt_limits_deg", "deg", "tilt joint limits [min, max]"},
      {"unit.max_speed_deg", "deg/s", "joint speed limit, both axes"},
      {"unit.max_acceleration_deg", "deg/s²", "joint acceleration limit, both axes"},
      {"unit.latency", "s", "command to effect"},
      {"unit.initial_offset_deg", "deg", "start pointing this far (pan, tilt) from the path's start point"},
      {"processing_delay", "s", "image capture to command (>= exposure / 2, < one frame period)"},
      {"robot", "", "the unit driven (absent: the simulated unit of `unit`)"},
      {"robot.kind", "", "simulated, or flir_ptu: a FLIR PTU (or viewline_ptu_emulator) over its ASCII protocol; the run is paced to the wall clock"},
      {"robot.port", "", "flir_ptu: serial device (e.g. /dev/ttyUSB0; or the emulator's pty); give port or tcp"},
      {"robot.baud", "bit/s", "flir_ptu: serial baud rate (9600 .. 115200)"},
      {"robot.tcp", "", "flir_ptu: host:port of an E-series unit or the emulator; give port or tcp"},
      {"robot.reply_timeout", "s", "flir_ptu: time allowed for each reply before the run stops with a time-out (the unit is halted)"},
      {"robot.latency", "s", "flir_ptu: command latency the controllers assume (default: unit.latency)"},
      {"detector", "", "the screen-target detector of [T] (vision::ScreenTargetDetector)"},
      {"detector.crop", "px", "margins removed [left, top, right, bottom]"},
      {"detector.scale", "", "image resize factor"},
      {"detector.threshold", "grey levels", "binarisation level (-1: Otsu)"},
      {"detector.median_ksize", "px", "median filter aperture"},
      {"detector.min_area_px", "px", "smaller blobs are rejected"},
      {"control", "", "the visual-servo control laws"},
      {"control.gain", "1/s", "lambda of the ViSP law, used by both controllers"},
      {"control.interaction", "", "interaction matrix at the desired features (desired), the current ones or their mean"},
      {"control.predictive_gain", "1/s", "lambda of the predictive law only (0: gain)"},
      {"control.lead", "s", "prediction beyond the command latency"},
      {"control.feed_forward", "", "add the -J+ ds_target/dt feed-forward term"},
      {"control.coast_time", "s", "time following the prediction without measurements (bridges short occlusions)"},
      {"control.limit_margin_deg", "deg", "margin kept from the joint limits"},
      {"control.search", "", "spiral search in joint space after coast_time without the target"},
      {"control.search.speed", "rad/s", "speed along the spiral"},
      {"control.search.growth", "rad", "spiral radius gained per turn"},
      {"control.search.radius", "rad", "largest radius (then the spiral restarts)"},
      {"control.search.gain", "1/s", "pull towards the spiral point"},
      {"filter", "", "the target filter on the screen plane"},
      {"filter.model", "", "target motion model: cv, ca, singer, ct (coordinated turn), imm, waypoint_particles or mixture (cv legs beside ct)"},
      {"filter.q", "m²/s³", "CV and IMM-cv: acceleration density (CA: jerk density, m²/s⁵)"},
      {"filter.singer_tau", "s", "Singer manoeuvre time constant"},
      {"filter.singer_sigma", "m/s²", "Singer acceleration std"},
      {"filter.init_velocity_sigma", "m/s", "velocity prior std at (re)initialisation and after a jump"},
      {"filter.init_acceleration_sigma", "m/s²", "acceleration prior std (CA, Singer)"},
      {"filter.gate_probability", "", "probability of the chi-square gate on the NIS"},
      {"filter.reinit_after", "", "consecutive gated-out measurements before re-initialising"},
      {"filter.init_omega_sigma", "rad/s", "prior std of the turn rate (CT, IMM)"},
      {"filter.ct_q_accel", "m²/s³", "CT and IMM-ct acceleration density"},
      {"filter.ct_q_omega", "rad²/s³", "CT and IMM turn-rate random-walk density"},
      {"filter.maneuver_q", "m²/s³", "IMM manoeuvre mode (CV) acceleration density"},
      {"filter.jump_window", "s", "time searched back for a velocity jump (a corner at constant speed; 0: off)"},
      {"filter.jump_threshold", "", "chi-square (2 dof) level of the test statistic that declares a jump"},
      {"filter.jump_min_samples", "", "measurements needed on each side of a candidate jump time (auto: from the noise and speed)"},
      {"filter.constant_speed_sigma", "m/s", "std of one leg's speed about the learnt one"},
      {"filter.constant_speed", "", "cv: the target keeps one speed, learnt from the legs between jumps"},
      {"filter.jump_corner_sigma", "m", "added to the corner position's std when a constant-speed leg starts (auto: from the noise)"},
      {"filter.jump_rate", "1/s", "prior rate of jumps (0: hard decisions only)"},
      {"filter.jump_prior_sigma", "m/s", "prior std per axis of the velocity jump"},
      {"filter.turn_prior_weight", "", "prior mass of a new leg's direction on the turns learnt at the last corners (0: uniform)"},
      {"filter.jump_evidence", "", "Bayes factors of the soft mixture: kink (a free velocity step) or legs (constant-speed legs)"},
      {"filter.jump_decision", "", "what declares a jump: test (jump_threshold) or posterior (jump_posterior)"},
      {"filter.jump_posterior", "", "posterior mass that declares a jump (jump_decision: posterior)"},
      {"filter.turn_prior_sigma_deg", "deg", "std of each learnt turn in the turn prior"},
      {"filter.imm_sojourn", "s", "IMM mean sojourn times of the cv, ct and manoeuvre modes"},
      {"filter.mixture_switch_rate", "1/s", "mixture: rate at which the target may switch between cv legs and ct"},
      {"filter.particles", "", "particles of waypoint_particles (>= 100)"},
      {"filter.particle_speed", "m/s", "uniform prior [min, max] of the target's one speed (waypoint_particles; equal ends: known speed)"},
      {"filter.particle_min_leg", "m", "the path generator's shortest leg (waypoint_particles)"},
      {"filter.region", "", "waypoint region: legs join waypoints drawn uniformly in this box (absent: none)"},
      {"filter.region.center", "m", "box centre, screen coordinates"},
      {"filter.region.size", "m", "box size [width, height]"},
      {"run", "", "the run"},
      {"run.duration", "s", "simulated time"},
      {"run.metrics_start", "s", "metrics from this time on, in [0, duration)"},
      {"run.occlusion_start", "s", "the disc disappears for occlusion_duration from this time (< 0: never)"},
      {"run.occlusion_duration", "s", "length of the occlusion"},
      {"run.baseline", "", "also run ViSP's law on the same seed"},
  };
  for (const io::ConfigKeyDoc& k : runtime::sourceConfigKeys()) s.keys.push_back(k);
  for (const io::ConfigKeyDoc& k : runtime::faultConfigKeys()) s.keys.push_back(k);
  s.probes.push_back(runtime::faultConfigProbe());
  return s;
}

}  // namespace viewline::scenarios
