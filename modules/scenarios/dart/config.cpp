#include "viewline/scenarios/dart/config.h"

#include <cmath>

#include "viewline/core/checks.h"
#include "viewline/core/error.h"
#include "viewline/core/frames.h"
#include "viewline/io/config_check.h"
#include "viewline/io/config_edit.h"

namespace viewline::scenarios {

vision::BallDetectorConfig defaultDartDetector() {
  vision::BallDetectorConfig d;
  // A 2 cm marker 2.5 m away covers about 50 px on the default rig (radius about 4 px): the
  // ball's floors (12 px, 3 px) would pass it only when close, and a 5 px closing would merge it
  // with its neighbours; a 3 px opening keeps it.
  d.min_area_px = 6.0;
  d.noise_area_px = 2.0;
  d.close_kernel_px = 3;
  return d;
}

bool DartScenarioConfig::onFootage() const {
  for (const DartCameraConfig& c : cameras)
    if (!c.source.simulated()) return true;
  return false;
}

tracking::TrackerConfig DartScenarioConfig::trackerConfig() const {
  tracking::TrackerConfig t = tracker;
  t.model.gravity_w = gravity_w;
  return t;
}

void DartScenarioConfig::validate() const {
  if (cameras.empty()) throw core::InvalidInput("dart scenario: cameras: expected at least one camera");
  for (std::size_t i = 0; i < cameras.size(); ++i) {
    const auto& c = cameras[i];
    const std::string p = "dart scenario: cameras[" + std::to_string(i) + "].";
    core::requireFinite(c.eye_w, p + "eye");
    core::requireFinite(c.target_w, p + "target");
    if ((c.eye_w - c.target_w).norm() < 1e-6) throw core::InvalidInput(p + "target: must differ from eye");
    if (!(c.hfov_rad > 0.0 && c.hfov_rad < 3.0)) throw core::InvalidInput(p + "hfov_deg: expected in (0, 170)");
    if (c.width < 2 || c.height < 2) throw core::InvalidInput(p + "width/height: expected >= 2");
    core::requireFinite(c.kud, p + "kud");
    core::requirePositive(c.rate_hz, p + "rate_hz");
    if (!(c.clock_drift_std >= 0.0 && c.clock_drift_std < 0.1)) throw core::InvalidInput(p + "clock_drift_std: expected in [0, 0.1)");
    if (!(c.jitter_std_s >= 0.0 && c.jitter_std_s < 0.25 / c.rate_hz))
      throw core::InvalidInput(p + "jitter_std_s: expected >= 0 and below a quarter frame period");
  }
  if (onFootage()) {
    // One clock for the session: footage cannot be fused with generated detections.
    for (const DartCameraConfig& c : cameras)
      if (c.source.simulated())
        throw core::InvalidInput("dart scenario: cameras[" + c.name +
                                 "].source: every camera needs footage when one has it (one session on the "
                                 "footage's clock)");
    if (!source.simulated())
      throw core::InvalidInput("dart scenario: source: kind recording and cameras[].source footage are exclusive");
  } else if (!faults.faults.empty()) {
    throw core::InvalidInput("dart scenario: faults: injected on footage only (cameras[].source); the experiments' "
                             "generated detections have no frames to fault");
  }
  detector.validate();
  if (!(detector_sigma_px >= 0.0 && std::isfinite(detector_sigma_px)))
    throw core::InvalidInput("dart scenario: detector.sigma_px: expected a finite value >= 0");
  core::requirePositive(detector_sigma_px_floor, "dart scenario: detector.sigma_px_floor");
  core::requireFinite(gravity_w, "dart scenario: gravity");
  core::requireFinite(release_mean, "dart scenario: throw.release_mean");
  core::requireFinite(release_std, "dart scenario: throw.release_std");
  core::requireFinite(board_center, "dart scenario: throw.board_center");
  if (!(aim_std >= 0.0)) throw core::InvalidInput("dart scenario: throw.aim_std: expected >= 0");
  core::requirePositive(speed_min, "dart scenario: throw.speed_min");
  if (!(speed_max >= speed_min)) throw core::InvalidInput("dart scenario: throw.speed_max: expected >= speed_min");
  core::requireNonNegative(truth_accel_psd, "dart scenario: truth_accel_psd");
  core::requirePositive(pixel_noise_px, "dart scenario: pixel_noise_px");
  if (!(outlier_rate >= 0.0 && outlier_rate < 1.0)) throw core::InvalidInput("dart scenario: outlier_rate: expected in [0, 1)");
  core::requirePositive(dt_offset_period, "dart scenario: dt_offset_period");
  core::requirePositive(alternate_step, "dart scenario: alternate_step");
  core::requireNonNegative(late_max_delay, "dart scenario: late_max_delay");
  if (!(late_horizon >= late_max_delay)) throw core::InvalidInput("dart scenario: late_horizon: expected >= late_max_delay");
  if (single_camera >= cameras.size()) throw core::InvalidInput("dart scenario: single_camera: expected a camera index");
  core::requireNonNegative(single_offset_max, "dart scenario: single_offset_max");
  core::requirePositive(single_prior_std, "dart scenario: single_prior_std");
  core::requirePositive(single_tolerance, "dart scenario: single_tolerance");
  if (!(confidence > 0.0 && confidence < 1.0)) throw core::InvalidInput("dart scenario: confidence: expected in (0, 1)");
  trackerConfig().validate();
}

DartScenarioConfig defaultDartScenario() {
  DartScenarioConfig cfg;
  DartCameraConfig side;
  side.name = "side";
  side.eye_w = {1.2, -2.6, 1.6};
  side.target_w = {1.2, 0.0, 1.75};
  side.hfov_rad = core::deg2rad(62.0);
  side.kud = 0.03;
  DartCameraConfig rear;
  rear.name = "rear";
  rear.eye_w = {-0.9, 1.9, 2.3};
  rear.target_w = {1.3, 0.0, 1.7};
  rear.hfov_rad = core::deg2rad(62.0);
  rear.kud = -0.02;
  cfg.cameras = {side, rear};
  cfg.tracker.prior_mean << 1.0, 0.0, 1.75, 12.0, 0.0, 0.0;
  cfg.tracker.prior_cov = 100.0 * tracking::Matrix6::Identity();
  cfg.tracker.model.accel_psd = 0.0;
  return cfg;
}

namespace {

DartCameraConfig readCamera(const io::ConfigNode& c) {
  DartCameraConfig cam;
  cam.name = c.getOr<std::string>("name", cam.name);
  cam.eye_w = c.get<Eigen::Vector3d>("eye");
  cam.target_w = c.get<Eigen::Vector3d>("target");
  cam.hfov_rad = c.getAngle("hfov_deg");
  cam.width = c.getOr<unsigned>("width", cam.width);
  cam.height = c.getOr<unsigned>("height", cam.height);
  cam.kud = c.getOr<double>("kud", cam.kud);
  cam.rate_hz = c.getOr<double>("rate_hz", cam.rate_hz);
  cam.clock_drift_std = c.getOr<double>("clock_drift_std", cam.clock_drift_std);
  cam.jitter_std_s = c.getOr<double>("jitter_std_s", cam.jitter_std_s);
  if (!(cam.rate_hz > 0)) c.fail("rate_hz", "a positive number");
  cam.source = runtime::readSourceConfig(c);  // absent: sim (generated detections)
  if (cam.source.kind == runtime::SourceKind::Recording)
    throw core::InvalidInput(c.location("source") + ": cameras[].source.kind recording is not a camera's source (a "
                             "recording holds every camera's detections: the top-level source: {kind: recording})");
  return cam;
}

void readTracker(const io::ConfigNode& t, DartScenarioConfig& cfg) {
  tracking::TrackerConfig& tc = cfg.tracker;
  if (t.has("prior_position")) tc.prior_mean.head<3>() = t.get<Eigen::Vector3d>("prior_position");
  if (t.has("prior_velocity")) tc.prior_mean.tail<3>() = t.get<Eigen::Vector3d>("prior_velocity");
  if (t.has("prior_std")) {
    const double s = t.get<double>("prior_std");
    if (!(s > 0)) t.fail("prior_std", "a positive number (m and m/s)");
    tc.prior_cov = s * s * tracking::Matrix6::Identity();
  }
  tc.model.accel_psd = t.getOr<double>("accel_psd", tc.model.accel_psd);
  if (t.has("gate")) {
    tc.gate.kind = tracking::gateKindFromString(t.getChoice("gate", {"none", "directional", "mahalanobis"}),
                                                t.keyPath("gate"));
  }
  tc.gate.directional_p = t.getOr<double>("directional_p", tc.gate.directional_p);
  tc.gate.mahalanobis_alpha = t.getOr<double>("mahalanobis_alpha", tc.gate.mahalanobis_alpha);
  tc.restart_after_rejections = t.getOr<int>("restart_after_rejections", tc.restart_after_rejections);
  tc.max_coast = t.getOr<double>("max_coast_s", tc.max_coast);
  tc.history_capacity = t.getOr<unsigned>("history_capacity", static_cast<unsigned>(tc.history_capacity));
  tc.min_depth = t.getOr<double>("min_depth", tc.min_depth);
  tc.max_forward_gap = t.getOr<double>("max_forward_gap_s", tc.max_forward_gap);
  tc.image_margin_px = t.getOr<double>("image_margin_px", tc.image_margin_px);
  cfg.dt_offset_period = t.getOr<double>("dt_offset_period_s", cfg.dt_offset_period);
  if (t.has("start")) {
    const io::ConfigNode st = t.child("start");
    tracking::TrackStartConfig& sc = tc.start;
    sc.confirm_images = st.getOr<int>("confirm_images", sc.confirm_images);
    sc.max_outliers = st.getOr<int>("max_outliers", sc.max_outliers);
    sc.window = st.getOr<unsigned>("window", static_cast<unsigned>(sc.window));
    sc.probability = st.getOr<double>("probability", sc.probability);
  }
}

vision::ColorRange readHsv(const io::ConfigNode& n, const char* key) {
  const auto v = n.get<std::vector<int>>(key);
  if (v.size() != 6) n.fail(key, "[hue_lo, hue_hi, s_lo, s_hi, v_lo, v_hi]");
  return {v[0], v[1], v[2], v[3], v[4], v[5]};
}

// The marker detector on footage: the ball detector's keys (ball_catching's detector block).
void readDetector(const io::ConfigNode& d, DartScenarioConfig& cfg) {
  vision::BallDetectorConfig& k = cfg.detector;
  if (d.has("hsv")) k.hsv = readHsv(d, "hsv");
  k.min_area_px = d.getOr<double>("min_area_px", k.min_area_px);
  k.noise_area_px = d.getOr<double>("noise_area_px", k.noise_area_px);
  k.min_roundness = d.getOr<double>("min_roundness", k.min_roundness);
  k.roi_half_size_px = d.getOr<double>("roi_half_size_px", k.roi_half_size_px);
  k.open_kernel_px = d.getOr<int>("open_kernel_px", k.open_kernel_px);
  k.close_kernel_px = d.getOr<int>("close_kernel_px", k.close_kernel_px);
  cfg.detector_sigma_px_floor = d.getOr<double>("sigma_px_floor", cfg.detector_sigma_px_floor);
  cfg.detector_sigma_px = d.getOr<double>("sigma_px", cfg.detector_sigma_px);
}

void readExperiments(const io::ConfigNode& e, DartScenarioConfig& cfg) {
  cfg.alternate_step = e.getOr<double>("alternate_step_s", cfg.alternate_step);
  cfg.late_max_delay = e.getOr<double>("late_max_delay_s", cfg.late_max_delay);
  cfg.late_horizon = e.getOr<double>("late_horizon_s", cfg.late_horizon);
  cfg.single_camera = e.getOr<unsigned>("single_camera", static_cast<unsigned>(cfg.single_camera));
  cfg.single_offset_max = e.getOr<double>("single_offset_max", cfg.single_offset_max);
  cfg.single_prior_std = e.getOr<double>("single_prior_std", cfg.single_prior_std);
  cfg.single_tolerance = e.getOr<double>("single_tolerance", cfg.single_tolerance);
  cfg.nees_index = e.getOr<unsigned>("nees_index", static_cast<unsigned>(cfg.nees_index));
  cfg.settled_index = e.getOr<unsigned>("settled_index", static_cast<unsigned>(cfg.settled_index));
  cfg.confidence = e.getOr<double>("confidence", cfg.confidence);
}

}  // namespace

DartScenarioConfig dartScenarioFromNode(const io::ConfigNode& root) {
  DartScenarioConfig cfg = defaultDartScenario();
  cfg.faults = runtime::readFaultPlanConfig(root);  // first: the config reference's probe reaches it
  cfg.source = runtime::readSourceConfig(root);
  // The experiments consume detections, not images: a recording of them (dart/recording.h) can
  // replace the generator, footage cannot.
  if (!cfg.source.simulated() && cfg.source.kind != runtime::SourceKind::Recording)
    throw core::InvalidInput(root.location("source") + ": source.kind " + runtime::toString(cfg.source.kind) +
                             " is not supported by dart_tracking (sim or recording: the experiments run on "
                             "detections with their truth; footage goes per camera, cameras[].source)");
  if (root.has("cameras")) {
    cfg.cameras.clear();
    for (const io::ConfigNode& c : root.childList("cameras")) cfg.cameras.push_back(readCamera(c));
    if (cfg.cameras.empty()) root.fail("cameras", "at least one camera");
  }
  cfg.gravity_w = root.getOr<Eigen::Vector3d>("gravity", cfg.gravity_w);
  if (root.has("throw")) {
    const io::ConfigNode t = root.child("throw");
    cfg.release_mean = t.getOr<Eigen::Vector3d>("release_mean", cfg.release_mean);
    cfg.release_std = t.getOr<Eigen::Vector3d>("release_std", cfg.release_std);
    cfg.board_center = t.getOr<Eigen::Vector3d>("board_center", cfg.board_center);
    cfg.aim_std = t.getOr<double>("aim_std", cfg.aim_std);
    cfg.speed_min = t.getOr<double>("speed_min", cfg.speed_min);
    cfg.speed_max = t.getOr<double>("speed_max", cfg.speed_max);
    cfg.truth_accel_psd = t.getOr<double>("truth_accel_psd", cfg.truth_accel_psd);
  }
  cfg.pixel_noise_px = root.getOr<double>("pixel_noise_px", cfg.pixel_noise_px);
  cfg.outlier_rate = root.getOr<double>("outlier_rate", cfg.outlier_rate);
  if (root.has("tracker")) readTracker(root.child("tracker"), cfg);
  if (root.has("detector")) readDetector(root.child("detector"), cfg);
  if (root.has("experiments")) readExperiments(root.child("experiments"), cfg);
  io::finishAndValidate(root, cfg);
  return cfg;
}

DartScenarioConfig loadDartScenario(const std::string& path, const std::vector<std::string>& key_values) {
  return dartScenarioFromNode(io::loadConfigWithValues(path, key_values));
}

DartScenarioConfig dartScenarioFromString(const std::string& yaml, const std::string& name) {
  return dartScenarioFromNode(io::ConfigNode::fromString(yaml, name));
}

}  // namespace viewline::scenarios
