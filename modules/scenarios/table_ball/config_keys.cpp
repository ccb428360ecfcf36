// Unit and meaning of every key the table_ball config reader (config.cpp) reads. The reference
// docs/config_reference.md is generated from this table and the recorded reads; the unit test
// ScenarioConfigKeys fails when a key is read without an entry here or an entry is never read.
#include "viewline/scenarios/config_keys.h"
#include "viewline/runtime/faults.h"
#include "viewline/runtime/source_config.h"
#include "viewline/scenarios/table_ball/config.h"

namespace viewline::scenarios {

io::ConfigReferenceSection tableBallConfigReference() {
  io::ConfigReferenceSection s;
  s.name = "table_ball";
  s.title = "Table-ball balancing (`table_ball_balancing`)";
  s.summary =
      "A ball balanced on a table tilted by a wrist, seen by a head camera ([M]): table, wrist, camera,"
      " observer, controller, events and metrics.";
  s.shipped = {"table_ball.yaml", "table_ball_apriltag.yaml"};
  // No shipped file has the inline camera (both name a rig): the camera given by its geometry.
  s.probes = {"table: {}\nwrist: {}\ncamera: {cx: 320, cy: 240, position: [0.5, 0.0, 1.5], look_at: [0.0, 0.0, 0.9]}\n",
              runtime::faultConfigProbe()};
  for (const std::string& p : runtime::sourceConfigProbes("")) s.probes.push_back(p);
  s.read = [](const io::ConfigNode& root) { tableBallConfigFromYaml(root); };
  s.keys = {
      {"duration", "s", "simulated time (--duration overrides it)"},
      {"table", "", "the arm-held table and the ball (world z up)"},
      {"table.side", "m", "side L of the red surface"},
      {"table.ball_radius", "m", "ball radius r (< side / 2)"},
      {"table.center", "m", "untilted table centre, world frame"},
      {"table.initial_ball", "m", "ball centre on the table at t = 0, table frame"},
      {"table.initial_velocity", "m/s", "ball velocity at t = 0, table frame"},
      {"table.border_height", "m", "raised black borders above the red surface"},
      {"table.tags", "", "four tag36h11 tags around the borders (needed by observer.table_pose: apriltag)"},
      {"table.tag_size", "m", "black square of each tag"},
      {"wrist", "", "the arm's wrist tilting the table about x, then y"},
      {"wrist.max_angle_deg", "deg", "tilt limit per axis"},
      {"wrist.max_rate", "rad/s", "tilt-rate limit per axis"},
      {"wrist.delay", "s", "actuator delay"},
      {"rig", "", "calibrated rig folder (truth renders, calibration observes); absent: the inline camera keys"},
      {"camera", "", "the head camera"},
      {"camera.width", "px", "image width (inline camera, no rig)"},
      {"camera.height", "px", "image height (inline camera, no rig)"},
      {"camera.hfov_deg", "deg", "horizontal field of view (inline camera, no rig)"},
      {"camera.cx", "px", "principal point u0 (inline camera; absent: the image centre)"},
      {"camera.cy", "px", "principal point v0 (inline camera; absent: the image centre)"},
      {"camera.kud", "", "must be 0: the inline camera has no distortion (use rig: for a distorted one)"},
      {"camera.position", "m", "camera centre, world frame (inline camera, with look_at)"},
      {"camera.look_at", "m", "a point on the optical axis, world frame (inline camera)"},
      {"camera.rate_hz", "Hz", "frame rate"},
      {"camera.sway_deg", "deg", "head sway: rotation amplitude"},
      {"camera.sway_hz", "Hz", "head sway base frequency"},
      {"camera.sway_translation", "m", "head sway: translation amplitude"},
      {"camera.ground_rotation_noise_deg", "deg", "error of the known camera-to-ground rotation (std per axis)"},
      {"camera.sensor_noise", "grey levels", "sensor noise (std)"},
      {"camera.exposure", "s", "exposure: motion blur"},
      {"camera.blur_samples", "", "renders averaged over the exposure (>= 1)"},
      {"camera.drop_probability", "", "probability that a frame is lost (the observer predicts through it)"},
      {"camera.supersampling", "", "renderer anti-aliasing sub-samples on edge pixels (1..8)"},
      {"observer", "", "the table and ball observer ([M])"},
      {"observer.table_pose", "", "corners ([M]: red contour, hull, 4 corners, PnP) or apriltag (needs table.tags)"},
      {"observer.ball_geometry", "", "table_plane (the cone's axis meets the plane z = r), known_radius (d = r / sin α) or unknown_radius (r from z = r)"},
      {"observer.sigma_w", "", "process noise σw of [M]'s ball model"},
      {"observer.sigma_v", "m", "measurement noise σv of [M]'s ball model"},
      {"observer.beta", "1/s", "inverse correlation time of the coloured disturbance"},
      {"observer.prediction_steps", "", "N predicted positions per frame"},
      {"observer.stationary_gain", "", "use the DARE gain for the nominal frame period"},
      {"observer.initial_velocity_std", "m/s", "velocity prior at the first detection"},
      {"observer.impulse_nis", "", "NIS above which a push (velocity jump) is assumed and the update redone; 0: never ([M])"},
      {"observer.impulse_std", "m/s", "std per axis of the assumed velocity jump of a push"},
      {"observer.coloured_sigma", "m", "std of the frame-to-frame correlated (AR(1)) part of the measurement error; sigma_v is then the white part; 0: white only ([M])"},
      {"observer.coloured_correlation", "", "correlation of that error from one frame to the next, in [0, 1)"},
      {"observer.input_hold", "", "the measured tilt acceleration over the interval before a frame: end (that frame's value held, [M]) or ramp (linear from the previous frame's value, as the wrist turns the table between frames)"},
      {"observer.gate_probability", "", "chi-square gate on the update's NIS (tracking::TrackGate); 1: no gate, as [M]"},
      {"observer.restart_after", "", "rejections in a row that restart the track (with a gate)"},
      {"observer.refine", "", "detector refinements after [M]'s steps (false: [M] exactly)"},
      {"observer.edge_tracking", "", "track the sides and the ball locally between full [M] detections"},
      {"observer.border_aware_pnp", "", "re-solve the PnP for the strip of surface the borders hide (false: [M])"},
      {"observer.table_pose_time_constant", "s", "time constant of the table pose filter (offset of the PnP pose from the kinematic one, averaged); 0: the per-frame PnP pose ([M])"},
      {"controller", "", "LQR on the estimated state with tilt-rate input (control::TableBalancer)"},
      {"controller.latency", "s", "capture to command (model delay = latency + wrist.delay)"},
      {"controller.q_position", "1/m²", "LQR weight on the position error²"},
      {"controller.q_velocity", "s²/m²", "LQR weight on the velocity²"},
      {"controller.q_tilt", "1/rad²", "LQR weight on the tilt²"},
      {"controller.q_integral", "1/(m² s²)", "LQR weight on the integral² (0: no integral action)"},
      {"controller.r_rate", "s²/rad²", "LQR weight on the tilt-rate input²"},
      {"controller.integral_band", "m", "integrate only while the position error is below this"},
      {"events", "", "set points and pushes"},
      {"events.setpoints", "", "set points, by increasing time; the first at t = 0"},
      {"events.setpoints[].t", "s", "time from which the set point holds"},
      {"events.setpoints[].xy", "m", "set point, table frame"},
      {"events.pushes", "", "impulses on the ball"},
      {"events.pushes[].t", "s", "time of the push"},
      {"events.pushes[].dv", "m/s", "velocity added to the ball, table frame"},
      {"metrics", "", "scoring of the run"},
      {"metrics.warmup", "s", "excluded from the RMSEs"},
      {"metrics.min_step", "m", "set-point changes at least this large are scored as steps"},
      {"metrics.settle_fraction", "", "settling band as a fraction of the step"},
      {"metrics.settle_min_band", "m", "the settling band is at least this wide (2-D settling: max(fraction · step, this))"},
      {"metrics.nis_spacing", "s", "spacing of the NIS samples whose mean is tested against the chi-square band (decorrelation)"},
      {"metrics.nees_spacing", "s", "spacing of the NEES samples (ball position and velocity against the truth)"},
      {"metrics.steady_window", "s", "window before the next event for the steady-state error"},
      {"metrics.push_band", "m", "recovered from a push when back within this distance for good"},
      {"metrics.compare_tunings", "", "run [M]'s two tunings and the stationary gain beside the loop"},
      {"metrics.time_reference", "", "time the plain OpenCV reference of [M]'s steps on every frame"},
  };
  // sim and recording run the closed loop; images, video and v4l2 one session on footage
  // without truth (table_ball/footage.h).
  for (io::ConfigKeyDoc& k : runtime::sourceConfigKeys()) {
    if (k.key == "source.kind")
      k.meaning = "sim (the rendered head camera) or recording: the scored closed loop; images, video or v4l2: one "
                  "session on footage, nothing scored (table_ball/footage.h)";
    s.keys.push_back(std::move(k));
  }
  for (io::ConfigKeyDoc& d : runtime::faultConfigKeys()) s.keys.push_back(std::move(d));
  return s;
}

}  // namespace viewline::scenarios
