// Unit and meaning of every key the dart config reader (config.cpp) reads. The reference
// docs/config_reference.md is generated from this table and the recorded reads; the unit test
// ScenarioConfigKeys fails when a key is read without an entry here or an entry is never read.
#include "viewline/scenarios/config_keys.h"
#include "viewline/runtime/faults.h"
#include "viewline/scenarios/dart/config.h"

namespace viewline::scenarios {

io::ConfigReferenceSection dartConfigReference() {
  io::ConfigReferenceSection s;
  s.name = "dart";
  s.title = "Dart tracking (`dart_tracking`)";
  s.summary =
      "The measurement-level dart experiment of [L] §VI: generated detections of thrown darts from "
      "simulated cameras, the viewline tracker's consistency, gates, asynchronous and late data and "
      "single-camera start. Every key is optional (defaults: `scenarios::defaultDartScenario()`).";
  s.shipped = {"dart_tracking.yaml"};
  // The detector block of footage (not in the shipped file, which runs the experiments).
  s.probes = {"source: {kind: recording, path: rec}\n", runtime::faultConfigProbe(),
              "detector: {hsv: [35, 85, 80, 255, 30, 255], min_area_px: 6, noise_area_px: 2, min_roundness: 0.45,\n"
              "           roi_half_size_px: 48, open_kernel_px: 3, close_kernel_px: 3, sigma_px_floor: 0.3, sigma_px: 0}\n"};
  // A camera's footage: one probe per kind (a recording is refused per camera, so not probed).
  for (const std::string& p : runtime::sourceConfigProbes("    ")) {
    if (p.find("kind: recording") != std::string::npos) continue;
    s.probes.push_back("cameras:\n  - name: a\n    eye: [1.2, -2.6, 1.6]\n    target: [1.2, 0.0, 1.75]\n    hfov_deg: 62\n" +
                       p);
  }
  s.read = [](const io::ConfigNode& root) { dartScenarioFromNode(root); };
  s.keys = {
      {"cameras", "", "the simulated cameras (absent: two cameras, side and rear, 2-3 m from the thrower)"},
      {"cameras[].name", "", "camera name in logs and summaries"},
      {"cameras[].eye", "m", "camera centre, world frame"},
      {"cameras[].target", "m", "a point on the optical axis, world frame (differs from eye)"},
      {"cameras[].hfov_deg", "deg", "horizontal field of view, in (0, 170)"},
      {"cameras[].width", "px", "image width"},
      {"cameras[].height", "px", "image height"},
      {"cameras[].kud", "", "ViSP radial distortion coefficient (pixel -> metre)"},
      {"cameras[].rate_hz", "Hz", "frame rate of the free-running camera"},
      {"cameras[].clock_drift_std", "", "relative frequency error of the camera clock (std), in [0, 0.1)"},
      {"cameras[].jitter_std_s", "s", "capture-time jitter (std), below a quarter frame period"},
      {"gravity", "m/s²", "gravity in the world frame; the one owner (the tracker's model asks for it)"},
      {"throw", "", "the thrown darts"},
      {"throw.release_mean", "m", "mean release point, world frame"},
      {"throw.release_std", "m", "std of the release point per axis"},
      {"throw.board_center", "m", "bull's eye, world frame"},
      {"throw.aim_std", "m", "spread of the aim point on the board (y and z)"},
      {"throw.speed_min", "m/s", "smallest release speed"},
      {"throw.speed_max", "m/s", "largest release speed (>= speed_min)"},
      {"throw.truth_accel_psd", "m²/s³", "white acceleration of the true flights (0: pure ballistic)"},
      {"pixel_noise_px", "px", "detection noise (std per axis)"},
      {"outlier_rate", "", "fraction of detections that are gross outliers anywhere in the image, in [0, 1)"},
      {"source", "", "where the detections come from (absent: generated from the simulated flights)"},
      {"source.kind", "", "sim (generated) or recording (a folder written by --record); footage goes per camera "
                          "(cameras[].source)"},
      {"source.path", "", "recording: the folder written by --record (as --replay)"},
      {"detector", "", "footage only: the dart's coloured marker detector (vision::BallDetector; a dart seen by a "
                       "camera is a small blob: smaller area floors than the ball's)"},
      {"detector.hsv", "", "HSV range of the marker [hue_lo, hue_hi, s_lo, s_hi, v_lo, v_hi] (absent: the detector's green)"},
      {"detector.min_area_px", "px", "blobs with fewer pixels are too small (a dart's marker is a few pixels across)"},
      {"detector.noise_area_px", "px", "blobs below this are ignored altogether"},
      {"detector.min_roundness", "", "area / (π ρ²) below which a blob is no marker"},
      {"detector.roi_half_size_px", "px", "half side of the search window around the tracker's predicted pixel"},
      {"detector.open_kernel_px", "px", "elliptic opening kernel size (odd; 0 or 1: none)"},
      {"detector.close_kernel_px", "px", "elliptic closing kernel size (odd; 0 or 1: none)"},
      {"detector.sigma_px_floor", "px", "floor of the blob's own std handed to the tracker"},
      {"detector.sigma_px", "px", "measured std of the detection per axis, told to the tracker (0: the blob's own, floored)"},
      {"tracker", "", "the viewline tracker (tracking::TrackerConfig)"},
      {"tracker.prior_position", "m", "prior position of a new track (absent: [1, 0, 1.75], mid-flight)"},
      {"tracker.prior_velocity", "m/s", "prior velocity of a new track (absent: [12, 0, 0], towards the board)"},
      {"tracker.prior_std", "m, m/s", "prior std of position and velocity (absent: 10, P0 = 100 I)"},
      {"tracker.accel_psd", "m²/s³", "white acceleration of the tracker's ballistic model"},
      {"tracker.gate", "", "measurement gate: none, directional ([L] §V) or mahalanobis (chi-square; absent: mahalanobis)"},
      {"tracker.directional_p", "", "p of the directional gate of [L] §V"},
      {"tracker.mahalanobis_alpha", "", "false-rejection probability of the chi-square gate"},
      {"tracker.restart_after_rejections", "", "consecutive gated images of one camera before the track restarts"},
      {"tracker.max_coast_s", "s", "time without a fused image after which the next one starts a new track"},
      {"tracker.history_capacity", "", "measurements kept per track for a restart"},
      {"tracker.min_depth", "m", "floor of the predicted depth in the measurement noise model"},
      {"tracker.max_forward_gap_s", "s", "a measurement further than this after the newest stamp is refused"},
      {"tracker.image_margin_px", "px", "pixels this far outside the image are still accepted"},
      {"tracker.start", "", "robust track start: a track is reported only once confirmed (absent: the first image seeds it)"},
      {"tracker.start.confirm_images", "",
       "images a tentative track needs in its one consistent subset before it is confirmed (0: off)"},
      {"tracker.start.max_outliers", "", "images of the window the start may set aside as outliers"},
      {"tracker.start.window", "", "newest images a tentative track keeps (>= confirm_images + max_outliers)"},
      {"tracker.start.probability", "", "chi-square probability of a subset's joint consistency test, in (0, 1)"},
      {"tracker.dt_offset_period_s", "s", "grid of the Δt-offset filter ([L] eq 26) in the comparison"},
      {"experiments", "", "the experiments A-E of [L] §VI"},
      {"experiments.alternate_step_s", "s", "time between alternating images (each camera at 1 / (2 step))"},
      {"experiments.late_max_delay_s", "s", "arrivals shuffled up to this late"},
      {"experiments.late_horizon_s", "s", "how far back the tracker re-processes late data (>= late_max_delay_s)"},
      {"experiments.single_camera", "", "index of the camera of the single-camera start"},
      {"experiments.single_offset_max", "m, m/s", "largest offset of the single-camera prior from the truth"},
      {"experiments.single_prior_std", "m", "prior std of the single-camera start ([L] §VI.B)"},
      {"experiments.single_tolerance", "m", "converged when within this distance of a filter started at the truth"},
      {"experiments.nees_index", "", "measurement (0-based) at which each run gives its NEES sample"},
      {"experiments.settled_index", "", "RMSE and PCRLB pooled over measurements with this index and later"},
      {"experiments.confidence", "", "confidence of the consistency intervals, in (0, 1)"},
  };
  // Injected faults, on footage only (dart/footage.h).
  for (io::ConfigKeyDoc d : runtime::faultConfigKeys()) {
    if (d.key == "faults")
      d.meaning = "injected camera and detector faults on footage (absent: none; refused on generated detections; "
                  "the robot kinds have no robot to hit); runtime/faults.h";
    s.keys.push_back(std::move(d));
  }
  // Footage per camera (dart/footage.h): the runtime's `source:` keys under each camera.
  for (io::ConfigKeyDoc d : runtime::sourceConfigKeys()) {
    if (d.key == "source") {
      d.meaning = "this camera's footage (absent: generated detections); every camera has footage or none: one "
                  "session over it, no truth (dart/footage.h)";
    } else if (d.key == "source.kind") {
      d.meaning = "sim (generated), images, video or v4l2 (recording is the top-level source's)";
    } else if (d.key == "source.path") {
      d.meaning = "video: the file";
    }
    d.key = "cameras[]." + d.key;
    s.keys.push_back(std::move(d));
  }
  return s;
}

}  // namespace viewline::scenarios
