#include "viewline/scenarios/mobile_capture.h"

#include <algorithm>
#include <atomic>
#include <chrono>
#include <cmath>
#include <filesystem>
#include <mutex>
#include <nlohmann/json.hpp>
#include <optional>
#include <sstream>
#include <thread>

#include "viewline/core/checks.h"
#include "viewline/core/error.h"
#include "viewline/core/frames.h"
#include "viewline/core/random.h"
#include "viewline/core/statistics.h"
#include "viewline/estimation/models/unicycle.h"
#include "viewline/estimation/models/unicycle_predictor.h"
#include "viewline/estimation/nonlinear.h"
#include "viewline/robots/mobile_ground_localization.h"
#include "viewline/scenarios/simulated_rig.h"
#include "viewline/sim/effects.h"
#include "viewline/sim/physics.h"
#include "viewline/sim/renderer.h"
#include "viewline/sim/worlds.h"

namespace viewline::scenarios {

using Eigen::Vector2d;
using Eigen::Vector3d;
using Eigen::VectorXd;

// ------------------------------------------------------------------------------------------------
// Configuration.

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
  c.planner.period = c.vision_period;
  c.planner.robot_speed = c.base.max_speed;
  c.planner.reach = 0.2;
  c.planner.turn_rate = 1.5;
  c.go.max_speed = c.base.max_speed;
  c.go.max_turn_rate = c.base.max_turn_rate;
  return c;
}

void MobileCaptureConfig::validate() const {
  core::requireFinite(robot_start, "robot_start");
  core::requireFinite(object_start, "object_start");
  core::requireFinite(robot_heading, "robot_heading");
  core::requireFinite(object_heading, "object_heading");
  core::requirePositive(max_time, "max_time");
  core::requirePositive(floor_size, "floor_size");
  core::requirePositive(vision_period, "vision_period");
  core::requirePositive(control_period, "control_period");
  const double ratio = vision_period / control_period;
  if (std::abs(ratio - std::round(ratio)) > 1e-9 || ratio < 1.0) {
    throw core::InvalidInput("vision_period: expected an integer multiple of control_period");
  }
  if (std::abs(base.control_period - control_period) > 1e-12) {
    throw core::InvalidInput("base.control_period: expected equal to control_period");
  }
  if (std::abs(planner.period - vision_period) > 1e-12) {
    throw core::InvalidInput("planner.period: expected equal to vision_period");
  }
  if (width < 16 || height < 16) throw core::InvalidInput("camera width/height: expected >= 16 px");
  core::requirePositive(hfov, "camera hfov");
  core::requirePositive(vfov, "camera vfov");
  if (sensor_noise < 0.0) throw core::InvalidInput("sensor_noise: expected >= 0");
  if (supersampling < 1) throw core::InvalidInput("supersampling: expected >= 1");
  head.validate();
  base.validate();
  detector.validate();
  core::requirePositive(pixel_sigma, "pixel_sigma");
  core::requirePositive(floor_sigma, "floor_sigma");
  core::requirePositive(object_height, "object_height");
  if (q_v < 0.0 || q_w < 0.0) throw core::InvalidInput("q_v/q_w: expected >= 0");
  core::requirePositive(init_speed_sigma, "init_speed_sigma");
  core::requirePositive(init_turn_sigma, "init_turn_sigma");
  if (!(gate_probability > 0.0 && gate_probability < 1.0)) throw core::InvalidInput("gate_probability: expected in (0, 1)");
  if (predictor_window < 2) throw core::InvalidInput("predictor_window: expected >= 2");
  if (!(max_accel_v >= 0.0) || !(max_accel_omega >= 0.0)) throw core::InvalidInput("max_accel_v/max_accel_omega: expected >= 0");
  if (horizon_steps < 1) throw core::InvalidInput("horizon_steps: expected >= 1");
  planner.validate();
  go.validate();
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
    readOpt(t, "control_period", c.control_period);
    positive(t, "control_period", c.control_period);
  }
  c.base.control_period = c.control_period;
  c.planner.period = c.vision_period;
  if (root.has("camera")) {
    const auto cam = root.child("camera");
    if (root.has("rig")) {
      for (const char* key : {"width", "height", "hfov_deg", "vfov_deg"}) {
        if (cam.has(key)) {
          throw core::InvalidInput(cam.location(key) + ": key '" + cam.keyPath(key) +
                                   "': not allowed with 'rig' (the rig's truth.yaml and rig.yaml set the camera)");
        }
      }
    }
    readOpt(cam, "width", c.width);
    readOpt(cam, "height", c.height);
    readAngle(cam, "hfov_deg", c.hfov);
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
  }
  c.go.max_speed = c.base.max_speed;
  c.go.max_turn_rate = c.base.max_turn_rate;
  c.planner.robot_speed = c.base.max_speed;
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
    readOpt(d, "object_height", c.object_height);
  }
  if (root.has("filter")) {
    const auto f = root.child("filter");
    readOpt(f, "q_v", c.q_v);
    readOpt(f, "q_w", c.q_w);
    readOpt(f, "init_speed", c.init_speed);
    readOpt(f, "init_speed_sigma", c.init_speed_sigma);
    readOpt(f, "init_turn_sigma", c.init_turn_sigma);
    readOpt(f, "gate_probability", c.gate_probability);
    readOpt(f, "predictor_window", c.predictor_window);
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
  root.finish();
  try {
    c.validate();
  } catch (const core::InvalidInput& e) {
    throw core::InvalidInput(root.fileName() + ": " + e.what());
  }
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

// ------------------------------------------------------------------------------------------------
// Pieces shared by the loops.

namespace {

/// The camera that renders (truth) and the one estimators use (calibrated with a rig; the same
/// perfect pinhole camera without).
core::Camera makeCamera(const MobileCaptureConfig& cfg) {
  if (cfg.rig) return cfg.rig->truth;
  core::Camera cam;
  cam.name = "head";
  cam.width = cfg.width;
  cam.height = cfg.height;
  const double px = 0.5 * cfg.width / std::tan(0.5 * cfg.hfov);
  const double py = 0.5 * cfg.height / std::tan(0.5 * cfg.vfov);
  cam.intrinsics = vpCameraParameters(px, py, 0.5 * cfg.width, 0.5 * cfg.height);
  return cam;
}
core::Camera makeEstimatorCamera(const MobileCaptureConfig& cfg) {
  return cfg.rig ? cfg.rig->calibrated : makeCamera(cfg);
}
/// The two cameras at the true head joints q and base pose: the true one renders the DH head,
/// the estimators' adds the calibrated mount correction c'_M_c.
void placeCameras(const MobileCaptureConfig& cfg, const robots::MobilePanTilt& head, const robots::PanTiltJoints& q,
                  double x, double y, double theta, core::Camera& truth, core::Camera& estimator) {
  truth.c_M_w = robots::headCamera_c_M_w(head, q, x, y, theta);
  estimator.c_M_w = cfg.rig ? cfg.rig->cal_M_c * truth.c_M_w : truth.c_M_w;
}

sim::GroundTargetParams targetParams(const MobileCaptureConfig& cfg, sim::GroundProfile profile, double duration) {
  sim::GroundTargetParams p;
  p.profile = profile;
  p.profile_period = cfg.vision_period;
  p.start = cfg.object_start;
  p.heading = cfg.object_heading;
  p.duration = duration;
  p.substep = cfg.control_period;
  p.noise = cfg.object_noise;
  return p;
}

double targetDuration(const MobileCaptureConfig& cfg) {
  return cfg.max_time + (cfg.horizon_steps + 2) * cfg.vision_period + 1.0;
}

// Independent random streams of one run, all derived from the run seed.
struct Streams {
  core::Rng object, room, render, drive;
  explicit Streams(std::uint64_t seed)
      : object(core::makeRng(core::deriveSeed(seed, 1))),
        room(core::makeRng(core::deriveSeed(seed, 2))),
        render(core::makeRng(core::deriveSeed(seed, 3))),
        drive(core::makeRng(core::deriveSeed(seed, 4))) {}
};

Vector2d toRobot(const robots::BasePose& pose, const Vector2d& p_w) {
  const Vector2d d = p_w - Vector2d(pose.x, pose.y);
  const double c = std::cos(pose.theta), s = std::sin(pose.theta);
  return {c * d.x() + s * d.y(), -s * d.x() + c * d.y()};
}

// The curvilinear target filter: EKF on estimation::UnicycleModel with a two-point start and
// an innovation gate; re-started after repeated rejections.
class TargetFilter {
public:
  TargetFilter(const estimation::UnicycleModel& model, double init_speed_sigma, double init_turn_sigma,
               double gate_probability, int predictor_window)
      : model_(model),
        init_speed_sigma_(init_speed_sigma),
        init_turn_sigma_(init_turn_sigma),
        gate_(core::chiSquareQuantile(2.0, gate_probability)),
        predictor_(static_cast<std::size_t>(predictor_window)) {}

  bool valid() const { return valid_; }
  const estimation::StateEstimate& state() const { return est_; }
  const estimation::UnicycleTrajectoryPredictor& predictor() const { return predictor_; }

  /// Time update to t (no-op when t <= current time).
  void predictTo(double t) {
    if (!valid_ || t <= est_.t() + 1e-12) return;
    estimation::ekfPredict(est_, model_.transition(t - est_.t()));
  }

  /// NIS of the last measurement against the predicted track (2 dof), fused or gated out; NaN when the
  /// last update had no track to test it against (start or restart).
  double lastNis() const { return last_nis_; }

  /// Measurement (x, y) with covariance R at time t. Returns true when it was fused.
  bool update(double t, const Vector2d& y, const Eigen::Matrix2d& R) {
    last_nis_ = std::numeric_limits<double>::quiet_NaN();
    if (!valid_) {
      if (first_ && t - first_t_ <= 0.5 && t > first_t_) {
        const Vector2d d = y - *first_;
        const double dt = t - first_t_;
        VectorXd x(5);
        x << y.x(), y.y(), std::atan2(d.y(), d.x()), d.norm() / dt, 0.0;
        const double pos_var = R.trace() / 2.0;
        const double dist = std::max(d.norm(), 1e-3);
        const double th_sigma = std::min(M_PI, std::sqrt(2.0 * pos_var) / dist + 0.2);
        const double v_sigma = std::sqrt(2.0 * pos_var) / dt + init_speed_sigma_ * 0.5;
        Eigen::MatrixXd P = Eigen::MatrixXd::Zero(5, 5);
        P.topLeftCorner<2, 2>() = R;
        P(2, 2) = th_sigma * th_sigma;
        P(3, 3) = v_sigma * v_sigma;
        P(4, 4) = init_turn_sigma_ * init_turn_sigma_;
        est_ = estimation::StateEstimate(x, P, t);
        valid_ = true;
        rejected_ = 0;
        predictor_.clear();
        predictor_.add(t, x[3], x[4]);
        first_.reset();
        return true;
      }
      first_ = y;
      first_t_ = t;
      return false;
    }
    predictTo(t);
    estimation::NonlinearMeasurement m = estimation::UnicycleModel::positionMeasurement(y, 1.0);
    m.R = R;
    // Gate before fusing: d' S⁻¹ d with S = R + H P H'.
    const Eigen::Matrix2d S = R + est_.P().topLeftCorner<2, 2>();
    const Vector2d d = y - est_.x().head<2>();
    const double nis = d.dot(S.ldlt().solve(d));
    last_nis_ = nis;
    if (nis > gate_) {
      if (++rejected_ >= 5) {  // the track is wrong, not the measurements: start again
        valid_ = false;
        first_ = y;
        first_t_ = t;
      }
      return false;
    }
    rejected_ = 0;
    estimation::ekfUpdate(est_, m);
    keepSpeedPositive();
    predictor_.add(t, est_.x()[3], est_.x()[4]);
    return true;
  }

  /// (θ, v) and (θ + π, -v) describe the same motion; when the object nearly stops the EKF can
  /// slide to the negative-speed twin. Map it back (exact reparametrisation: J = diag(1,1,1,-1,1)
  /// on the covariance, θ shifted by π) so that θ is the heading of the object.
  void keepSpeedPositive() {
    if (est_.x()[3] >= 0.0) return;
    VectorXd x = est_.x();
    x[2] = estimation::wrapAngle(x[2] + M_PI);
    x[3] = -x[3];
    Eigen::MatrixXd P = est_.P();
    P.row(3) *= -1.0;
    P.col(3) *= -1.0;
    est_.setMean(x);
    est_.setCovariance(P);
    predictor_.clear();  // the speed history had the other sign
  }

  /// Mean propagated to time t without touching the filter (for head pointing between frames).
  Vector2d positionAt(double t) const {
    VectorXd x = est_.x();
    const double dt = t - est_.t();
    if (dt > 1e-9) x = model_.propagate(x, dt);
    return x.head<2>();
  }

private:
  estimation::UnicycleModel model_;
  double init_speed_sigma_, init_turn_sigma_, gate_;
  double last_nis_ = std::numeric_limits<double>::quiet_NaN();
  estimation::UnicycleTrajectoryPredictor predictor_;
  estimation::StateEstimate est_;
  bool valid_ = false;
  int rejected_ = 0;
  std::optional<Vector2d> first_;
  double first_t_ = -1.0;
};

// Everything of one simulated robot that the two loops (ours, oracle) share.
struct RobotSim {
  const MobileCaptureConfig& cfg;
  robots::MobilePanTilt head;
  robots::DifferentialDrive base;
  robots::PanTiltJoints q;
  RobotSim(const MobileCaptureConfig& c)
      : cfg(c), head(c.head), base(c.base, {c.robot_start.x(), c.robot_start.y(), c.robot_heading}) {
    q = head.pointAtBest(Vector3d(2.0, 0.0, 0.0));
  }
  void stepHead(const robots::PanTiltJoints& target) {
    const auto t = head.clampToLimits(target);
    q.tilt = robots::JointRateLimiter::step(q.tilt, t.tilt, cfg.head.tilt_rate_max, cfg.control_period);
    q.pan = robots::JointRateLimiter::step(q.pan, t.pan, cfg.head.pan_rate_max, cfg.control_period);
  }
};

// [K] eqs 27-29 with the LS accelerations of the predictor, used once its window is full and
// clamped to plausible bounds (early slopes from a few noisy estimates are wild).
std::vector<Vector2d> predictPath(const TargetFilter& filter, const MobileCaptureConfig& cfg) {
  const auto& pred = filter.predictor();
  estimation::UnicycleTrajectoryPredictor::Accelerations acc;
  if (pred.size() >= pred.window()) {
    acc = pred.fitAccelerations();
    acc.a_v = std::clamp(acc.a_v, -cfg.max_accel_v, cfg.max_accel_v);
    acc.a_omega = std::clamp(acc.a_omega, -cfg.max_accel_omega, cfg.max_accel_omega);
  }
  return estimation::UnicycleTrajectoryPredictor::rollForward(filter.state().x(), acc, cfg.vision_period,
                                                              cfg.horizon_steps);
}

std::vector<Vector2d> truePath(const sim::GroundTarget& target, double t, double T, int M) {
  std::vector<Vector2d> out;
  out.reserve(static_cast<std::size_t>(M));
  const double end = target.params().duration;
  for (int m = 1; m <= M; ++m) {
    const auto s = target.state(std::min(end, t + m * T));
    out.emplace_back(s.x, s.y);
  }
  return out;
}

}  // namespace

// ------------------------------------------------------------------------------------------------
// Oracle.

OracleResult runOracle(const MobileCaptureConfig& cfg, std::uint64_t seed) {
  cfg.validate();
  Streams rng(seed);
  const sim::GroundTarget target(targetParams(cfg, sim::GroundProfile::Capture, targetDuration(cfg)), rng.object);
  RobotSim robot(cfg);
  const long steps = std::lround(cfg.max_time / cfg.control_period);
  const long vision_every = std::lround(cfg.vision_period / cfg.control_period);
  planning::CapturePlan plan;
  for (long i = 0; i <= steps; ++i) {
    const double t = i * cfg.control_period;
    const auto s = target.state(t);
    const Vector2d obj(s.x, s.y);
    if (cfg.trigger.contains(toRobot(robot.base.pose(), obj))) return {true, t};
    if (i % vision_every == 0) {
      const auto& p = robot.base.pose();
      plan = planning::planCapture(truePath(target, t, cfg.vision_period, cfg.horizon_steps),
                                   {{p.x, p.y}, p.theta}, cfg.planner);
    }
    const control::BaseCommand c = control::goToPoint(robot.base.pose(), plan.point, cfg.go);
    robot.base.setCommand(c.v, c.omega);
    robot.base.step(rng.drive);
  }
  return {false, cfg.max_time};
}

// ------------------------------------------------------------------------------------------------
// Our loop.

MobileCaptureRun runMobileCapture(const MobileCaptureConfig& cfg, std::uint64_t seed, const MobileCaptureHooks* hooks) {
  cfg.validate();
  MobileCaptureRun run;
  run.seed = seed;
  Streams rng(seed);
  const sim::GroundTarget target(targetParams(cfg, sim::GroundProfile::Capture, targetDuration(cfg)), rng.object);
  sim::RoomParams room;
  room.floor_size = cfg.floor_size;
  room.walls = false;
  room.floor_texture.resolution = 2048;
  room.floor_texture.base_cells = 12;
  const sim::GroundWorld world(target, sim::makeRoom(room, rng.room));
  sim::RenderSettings rs;
  rs.supersampling = cfg.supersampling;
  rs.max_cached_cameras = 1;
  sim::Renderer renderer(rs);
  std::optional<sim::NoisePool> noise;
  if (cfg.sensor_noise > 0.0) noise.emplace(sim::SensorNoise{cfg.sensor_noise, 1u << 18}, rng.render);
  vision::BallDetector detector(cfg.detector);
  core::Camera true_camera = makeCamera(cfg);        // renders
  core::Camera camera = makeEstimatorCamera(cfg);    // detection ROI, ground localisation
  const robots::AnglePerPixel printed{cfg.hfov, cfg.vfov, robots::AngleRange::PrintedSlant};
  const robots::AnglePerPixel horizontal{cfg.hfov, cfg.vfov, robots::AngleRange::Horizontal};
  const double plane_z = 0.5 * cfg.object_height;

  estimation::UnicycleModel model;
  model.q_v = cfg.q_v;
  model.q_w = cfg.q_w;
  TargetFilter filter(model, cfg.init_speed_sigma, cfg.init_turn_sigma, cfg.gate_probability, cfg.predictor_window);
  const control::SearchPattern search(cfg.search);
  RobotSim robot(cfg);

  io::LogDirectory* log = hooks ? hooks->log : nullptr;
  io::CsvWriter* log_truth = nullptr;
  io::CsvWriter* log_meas = nullptr;
  io::CsvWriter* log_est = nullptr;
  io::CsvWriter* log_plan = nullptr;
  if (log && log->enabled()) {
    log_truth = &log->stream("truth", {"t", "object_x", "object_y", "object_theta", "object_v", "object_omega",
                                       "robot_x", "robot_y", "robot_theta", "tilt", "pan"});
    log_meas = &log->stream("measurements", {"t", "u", "v", "exact_x", "exact_y", "printed_x", "printed_y",
                                             "horizontal_x", "horizontal_y", "fused"});
    log_est = &log->stream("estimates", {"t", "x", "y", "theta", "v", "omega", "sx", "sy", "stheta", "sv", "somega"});
    log_plan = &log->stream("plan", {"t", "reachable", "steps", "capture_x", "capture_y", "mode"});
  }

  const long steps = std::lround(cfg.max_time / cfg.control_period);
  const long vision_every = std::lround(cfg.vision_period / cfg.control_period);
  double last_seen = -1.0, first_seen = -1.0, sweep_start = -1.0, last_grasp = -1e9;
  double centre_bearing = 0.0;  // robot frame, for the search
  bool have_bearing = false;
  planning::CapturePlan plan;
  std::vector<Vector2d> prediction;
  control::SearchMode mode = control::SearchMode::Sweeping;
  cv::Mat image;

  for (long i = 0; i <= steps; ++i) {
    const double t = i * cfg.control_period;
    const auto truth = target.state(t);
    const Vector2d obj(truth.x, truth.y);
    const robots::BasePose pose = robot.base.pose();

    // Grasp.
    if (filter.valid() && t - last_grasp >= cfg.grasp_cooldown &&
        cfg.trigger.contains(toRobot(pose, filter.positionAt(t)))) {
      ++run.grasp_attempts;
      last_grasp = t;
      if (cfg.jaws.contains(toRobot(pose, obj))) {
        run.captured = true;
        run.capture_time = t;
        break;
      }
    }

    // Vision, filter, prediction, plan.
    if (i % vision_every == 0) {
      ++run.frames;
      placeCameras(cfg, robot.head, robot.q, pose.x, pose.y, pose.theta, true_camera, camera);
      image = renderer.render(world, true_camera, sim::ExposureSpec{t, 0.0, 1});
      if (noise) noise->apply(image, rng.render);
      std::optional<Vector2d> predicted_px;
      if (filter.valid()) {
        const Vector2d p = filter.positionAt(t);
        predicted_px = camera.project(Vector3d(p.x(), p.y(), plane_z));
      }
      const bool blackout = cfg.blackout_start >= 0.0 && t >= cfg.blackout_start &&
                            t < cfg.blackout_start + cfg.blackout_duration;
      if (blackout) image.setTo(cv::Scalar(0, 0, 0));
      const auto det = detector.detect(image, t, predicted_px);
      bool detected = false, fused = false;
      double nis = std::numeric_limits<double>::quiet_NaN();
      Vector2d pixel = Vector2d::Zero();
      if (det.ok()) {
        pixel = det.value().blob_center;
        const auto exact = robots::groundPointExact(camera, pixel, plane_z);
        const auto cov = robots::groundPointCovariance(
            camera, pixel, cfg.pixel_sigma * cfg.pixel_sigma * Eigen::Matrix2d::Identity(), plane_z);
        if (exact && cov) {
          detected = true;
          ++run.detections;
          if (last_seen >= 0.0) run.longest_lost = std::max(run.longest_lost, t - last_seen);
          if (first_seen < 0.0) first_seen = t;
          last_seen = t;
          const auto a = robots::groundPointAnglePerPixel(camera, pixel, printed, plane_z);
          const auto h = robots::groundPointAnglePerPixel(camera, pixel, horizontal, plane_z);
          if (a && h) {
            run.localization.sse_exact += (*exact - obj).squaredNorm();
            run.localization.sse_printed += (*a - obj).squaredNorm();
            run.localization.sse_horizontal += (*h - obj).squaredNorm();
            ++run.localization.count;
          }
          const Eigen::Matrix2d R = *cov + cfg.floor_sigma * cfg.floor_sigma * Eigen::Matrix2d::Identity();
          fused = filter.update(t, *exact, R);
          nis = filter.lastNis();
          if (log_meas) {
            const double nan = std::numeric_limits<double>::quiet_NaN();
            log_meas->row({t, pixel.x(), pixel.y(), exact->x(), exact->y(), a ? a->x() : nan, a ? a->y() : nan,
                           h ? h->x() : nan, h ? h->y() : nan, fused ? 1.0 : 0.0});
          }
        }
      }
      filter.predictTo(t);
      if (filter.valid()) {
        prediction = predictPath(filter, cfg);
        plan = planning::planCapture(prediction, {{pose.x, pose.y}, pose.theta}, cfg.planner);
        const Vector2d rel = toRobot(pose, filter.state().x().head<2>());
        centre_bearing = std::atan2(rel.y(), rel.x());
        have_bearing = true;
      }
      if (log_truth) {
        log_truth->row({t, truth.x, truth.y, truth.theta, truth.v, truth.omega, pose.x, pose.y, pose.theta,
                        robot.q.tilt, robot.q.pan});
        if (filter.valid()) {
          const VectorXd& x = filter.state().x();
          const VectorXd sd = filter.state().P().diagonal().cwiseSqrt();
          log_est->row({t, x[0], x[1], x[2], x[3], x[4], sd[0], sd[1], sd[2], sd[3], sd[4]});
        }
        log_plan->row({t, plan.reachable ? 1.0 : 0.0, static_cast<double>(plan.steps), plan.point.x(), plan.point.y(),
                       static_cast<double>(static_cast<int>(mode))});
      }
      if (hooks && hooks->on_frame) {
        MobileCaptureFrame f;
        f.t = t;
        f.image = &image;
        f.detected = detected;
        f.pixel = pixel;
        f.robot = pose;
        f.joints = robot.q;
        f.object_true = obj;
        f.fused = fused;
        f.nis = nis;
        f.estimate_valid = filter.valid();
        if (filter.valid()) f.estimate = filter.state().x();
        f.prediction = prediction;
        f.plan = plan;
        f.mode = mode;
        hooks->on_frame(f);
      }
    }

    // Control.
    const control::SearchMode new_mode = filter.valid() ? search.mode(t, last_seen) : control::SearchMode::Sweeping;
    if (new_mode == control::SearchMode::Sweeping && mode != control::SearchMode::Sweeping) sweep_start = t;
    if (sweep_start < 0.0) sweep_start = t;
    mode = new_mode;
    control::BaseCommand cmd;
    robots::PanTiltJoints head_target = robot.q;
    if (mode != control::SearchMode::Sweeping) {
      cmd = control::goToPoint(pose, plan.point, cfg.go);
      const Vector2d p = filter.positionAt(t + cfg.control_period);
      head_target = control::headSetPoint(robot.head, pose, Vector3d(p.x(), p.y(), plane_z));
    } else {
      head_target = search.sweep(robot.head, t, sweep_start, have_bearing ? centre_bearing : 0.0);
      cmd = search.baseWhileSearching(centre_bearing, have_bearing);
      if (have_bearing) {
        // The base turns towards the bearing; it is expressed in the robot frame at the last
        // estimate, so update it with the base's own rotation.
        centre_bearing = std::remainder(centre_bearing - robot.base.turnRate() * cfg.control_period, 2.0 * M_PI);
      }
    }
    robot.stepHead(head_target);
    robot.base.setCommand(cmd.v, cmd.omega);
    robot.base.step(rng.drive);
  }
  if (!run.captured) run.capture_time = cfg.max_time;
  if (log) log->flush();

  const OracleResult oracle = runOracle(cfg, seed);
  run.oracle_captured = oracle.captured;
  run.oracle_time = oracle.time;
  return run;
}

// ------------------------------------------------------------------------------------------------
// Filter test ([K] §3.2).

FilterTestResult runFilterTest(const MobileCaptureConfig& cfg, std::uint64_t seed) {
  cfg.validate();
  Streams rng(seed);
  MobileCaptureConfig c = cfg;
  c.object_noise = true;
  const sim::GroundTarget target(
      targetParams(c, sim::GroundProfile::FilterTest, cfg.filter_test_duration + 1.0), rng.object);
  estimation::UnicycleModel model;
  model.q_v = cfg.filter_test_q_v;
  model.q_w = cfg.filter_test_q_w;
  const double sigma = std::sqrt(cfg.filter_test_measurement_var) * 0.01;  // cm² -> m
  const Eigen::Matrix2d R = sigma * sigma * Eigen::Matrix2d::Identity();
  TargetFilter filter(model, cfg.init_speed_sigma, cfg.init_turn_sigma, 1.0 - 1e-9, cfg.predictor_window);
  FilterTestResult r;
  double se_thm = 0;
  long n_moving = 0;
  double se_th = 0, se_v = 0, se_w = 0, se_vn = 0, se_wn = 0, se_p = 0, se_m = 0;
  long n = 0;
  const long steps = std::lround(cfg.filter_test_duration / cfg.vision_period);
  for (long k = 0; k <= steps; ++k) {
    const double t = k * cfg.vision_period;
    const auto s = target.state(t);
    const Vector2d y(s.x + core::gaussian(rng.render, sigma), s.y + core::gaussian(rng.render, sigma));
    filter.update(t, y, R);
    if (!filter.valid()) continue;
    const VectorXd& x = filter.state().x();
    const double e_th = estimation::wrapAngle(x[2] - s.theta), e_v = x[3] - s.v, e_w = x[4] - s.omega;
    r.t.push_back(t);
    r.err_theta.push_back(e_th);
    r.err_v.push_back(e_v);
    r.err_omega.push_back(e_w);
    if (t >= cfg.convergence_time) {
      const Vector2d nom = sim::GroundTarget::nominal(sim::GroundProfile::FilterTest, static_cast<double>(k));
      se_th += e_th * e_th, se_v += e_v * e_v, se_w += e_w * e_w;
      if (s.v >= 0.05) se_thm += e_th * e_th, ++n_moving;
      se_vn += (x[3] - nom.x()) * (x[3] - nom.x()), se_wn += (x[4] - nom.y()) * (x[4] - nom.y());
      se_p += (x.head<2>() - Vector2d(s.x, s.y)).squaredNorm();
      se_m += (y - Vector2d(s.x, s.y)).squaredNorm();
      ++n;
    }
  }
  if (n == 0) throw core::NumericalError("runFilterTest: no sample after the convergence time");
  const double dn = static_cast<double>(n);
  r.rmse_theta = std::sqrt(se_th / dn);
  r.rmse_theta_moving = n_moving > 0 ? std::sqrt(se_thm / static_cast<double>(n_moving)) : 0.0;
  r.rmse_v = std::sqrt(se_v / dn);
  r.rmse_omega = std::sqrt(se_w / dn);
  r.rmse_v_nominal = std::sqrt(se_vn / dn);
  r.rmse_omega_nominal = std::sqrt(se_wn / dn);
  r.rmse_position = std::sqrt(se_p / dn);
  r.rmse_measurement = std::sqrt(se_m / dn);
  return r;
}

// ------------------------------------------------------------------------------------------------
// Field-of-view sweep of the ground localisation.

FovSweepResult compareGroundLocalization(const MobileCaptureConfig& cfg, std::uint64_t seed) {
  cfg.validate();
  core::Rng rng = core::makeRng(core::deriveSeed(seed, 99));
  const robots::MobilePanTilt head(cfg.head);
  core::Camera true_camera = makeCamera(cfg);      // makes the floor points of the pixels
  core::Camera camera = makeEstimatorCamera(cfg);  // locates them
  const robots::AnglePerPixel printed{cfg.hfov, cfg.vfov, robots::AngleRange::PrintedSlant};
  const robots::AnglePerPixel horizontal{cfg.hfov, cfg.vfov, robots::AngleRange::Horizontal};
  const double plane_z = 0.5 * cfg.object_height;
  FovSweepResult r;
  for (int pose = 0; pose < cfg.fov_sweep_poses; ++pose) {
    // A head looking at a floor point 0.5-4 m ahead within ±45° (what the chase produces).
    const double range = core::uniform(rng, 0.5, 4.0), bearing = core::uniform(rng, -0.8, 0.8);
    const auto q = head.pointAtBest(Vector3d(range * std::cos(bearing), range * std::sin(bearing), plane_z));
    placeCameras(cfg, head, q, 0.0, 0.0, 0.0, true_camera, camera);
    int done = 0;
    for (int attempt = 0; attempt < 50 * cfg.fov_sweep_points && done < cfg.fov_sweep_points; ++attempt) {
      const Vector2d uv(core::uniform(rng, 0.0, cfg.width - 1.0), core::uniform(rng, 0.0, cfg.height - 1.0));
      const auto p = robots::groundPointExact(true_camera, uv, plane_z);
      if (!p || (p->norm() > 5.0)) continue;  // the chase happens within 5 m; beyond, the object is a few pixels
      const Vector2d noisy = uv + Vector2d(core::gaussian(rng, cfg.fov_sweep_pixel_sigma),
                                           core::gaussian(rng, cfg.fov_sweep_pixel_sigma));
      const auto e = robots::groundPointExact(camera, noisy, plane_z);
      const auto a = robots::groundPointAnglePerPixel(camera, noisy, printed, plane_z);
      const auto h = robots::groundPointAnglePerPixel(camera, noisy, horizontal, plane_z);
      if (!e || !a || !h) continue;
      LocalizationErrors one;
      one.sse_exact = (*e - *p).squaredNorm();
      one.sse_printed = (*a - *p).squaredNorm();
      one.sse_horizontal = (*h - *p).squaredNorm();
      one.count = 1;
      r.all.add(one);
      const bool centre = std::abs(uv.x() - 0.5 * cfg.width) < cfg.width / 6.0 &&
                          std::abs(uv.y() - 0.5 * cfg.height) < cfg.height / 6.0;
      (centre ? r.centre : r.border).add(one);
      ++done;
    }
  }
  return r;
}

// ------------------------------------------------------------------------------------------------
// Batch and summary.

double percentile(std::vector<double> v, double p) {
  if (v.empty()) throw core::InvalidInput("percentile: empty sample");
  std::sort(v.begin(), v.end());
  const double pos = std::clamp(p, 0.0, 1.0) * (v.size() - 1);
  const auto lo = static_cast<std::size_t>(std::floor(pos));
  const std::size_t hi = std::min(lo + 1, v.size() - 1);
  return v[lo] + (pos - lo) * (v[hi] - v[lo]);
}

MobileCaptureSummary runMobileCaptureBatch(const MobileCaptureConfig& cfg, int runs, std::uint64_t seed,
                                           const std::function<void(int, int)>& progress) {
  cfg.validate();
  if (runs < 1) throw core::InvalidInput("runs: expected >= 1");
  const auto start = std::chrono::steady_clock::now();
  MobileCaptureSummary s;
  s.runs.resize(static_cast<std::size_t>(runs));
  std::atomic<int> next{0}, done{0};
  std::mutex mutex;
  std::exception_ptr error;
  auto worker = [&]() {
    for (;;) {
      const int i = next++;
      if (i >= runs) return;
      try {
        s.runs[static_cast<std::size_t>(i)] = runMobileCapture(cfg, core::deriveSeed(seed, static_cast<std::uint64_t>(i)));
      } catch (...) {
        std::lock_guard<std::mutex> lock(mutex);
        if (!error) error = std::current_exception();
        next = runs;
        return;
      }
      const int d = ++done;
      if (progress) {
        std::lock_guard<std::mutex> lock(mutex);
        progress(d, runs);
      }
    }
  };
  std::vector<std::thread> pool;
  const int n_threads = std::min(cfg.threads, runs);
  for (int k = 0; k < n_threads; ++k) pool.emplace_back(worker);
  for (auto& th : pool) th.join();
  if (error) std::rethrow_exception(error);

  std::vector<double> ratios, times, oracle_times;
  int ok = 0, oracle_ok = 0;
  for (const auto& r : s.runs) {
    ok += r.captured;
    oracle_ok += r.oracle_captured;
    s.localization.add(r.localization);
    if (r.captured) times.push_back(r.capture_time);
    if (r.oracle_captured) oracle_times.push_back(r.oracle_time);
    if (r.captured && r.oracle_captured) ratios.push_back(r.capture_time / r.oracle_time);
  }
  s.success_rate = static_cast<double>(ok) / runs;
  s.oracle_success_rate = static_cast<double>(oracle_ok) / runs;
  s.ratio_runs = static_cast<int>(ratios.size());
  if (!ratios.empty()) {
    s.ratio_median = percentile(ratios, 0.5);
    s.ratio_p95 = percentile(ratios, 0.95);
  }
  if (!times.empty()) {
    s.time_median = percentile(times, 0.5);
    s.time_p95 = percentile(times, 0.95);
  }
  if (!oracle_times.empty()) s.oracle_time_median = percentile(oracle_times, 0.5);

  for (int k = 0; k < cfg.filter_test_runs; ++k) {
    FilterTestResult f = runFilterTest(cfg, core::deriveSeed(seed, 100000 + static_cast<std::uint64_t>(k)));
    s.filter_rmse_theta += f.rmse_theta / cfg.filter_test_runs;
    s.filter_rmse_theta_moving += f.rmse_theta_moving / cfg.filter_test_runs;
    s.filter_rmse_v += f.rmse_v / cfg.filter_test_runs;
    s.filter_rmse_omega += f.rmse_omega / cfg.filter_test_runs;
    s.filter_rmse_v_nominal += f.rmse_v_nominal / cfg.filter_test_runs;
    s.filter_rmse_omega_nominal += f.rmse_omega_nominal / cfg.filter_test_runs;
    s.filter_rmse_position += f.rmse_position / cfg.filter_test_runs;
    s.filter_rmse_measurement += f.rmse_measurement / cfg.filter_test_runs;
    if (k == 0) s.filter_first = std::move(f);
  }
  s.fov = compareGroundLocalization(cfg, seed);
  s.wall_time = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  return s;
}

namespace {
double rms(double sse, long n) { return n > 0 ? std::sqrt(sse / static_cast<double>(n)) : 0.0; }
nlohmann::json locJson(const LocalizationErrors& e) {
  return {{"exact_m", rms(e.sse_exact, e.count)},
          {"angle_per_pixel_printed_m", rms(e.sse_printed, e.count)},
          {"angle_per_pixel_horizontal_m", rms(e.sse_horizontal, e.count)},
          {"samples", e.count}};
}
}  // namespace

std::string summaryJson(const MobileCaptureSummary& s, const MobileCaptureConfig& cfg, int indent) {
  nlohmann::json j;
  j["runs"] = s.runs.size();
  j["capture_success_rate"] = s.success_rate;
  j["capture_time_ratio_to_oracle"] = {{"median", s.ratio_median}, {"p95", s.ratio_p95}, {"runs", s.ratio_runs}};
  j["capture_time_s"] = {{"median", s.time_median}, {"p95", s.time_p95}};
  j["oracle_capture_time_s"] = {{"median", s.oracle_time_median}};
  j["oracle_success_rate"] = s.oracle_success_rate;
  int attempts = 0, frames = 0, detections = 0;
  double longest = 0.0;
  for (const auto& r : s.runs) {
    attempts += r.grasp_attempts, frames += r.frames, detections += r.detections;
    longest = std::max(longest, r.longest_lost);
  }
  j["grasp_attempts_per_run"] = s.runs.empty() ? 0.0 : static_cast<double>(attempts) / s.runs.size();
  j["detection_rate"] = frames > 0 ? static_cast<double>(detections) / frames : 0.0;
  j["longest_lost_s"] = longest;
  j["ground_localization_rms"] = locJson(s.localization);
  j["ground_localization_fov_sweep"] = {{"all", locJson(s.fov.all)},
                                        {"image_centre", locJson(s.fov.centre)},
                                        {"image_border", locJson(s.fov.border)},
                                        {"pixel_sigma", cfg.fov_sweep_pixel_sigma}};
  j["filter_test"] = {{"runs", cfg.filter_test_runs},
                      {"convergence_time_s", cfg.convergence_time},
                      {"rmse_theta_rad", s.filter_rmse_theta},
                      {"rmse_theta_when_moving_rad", s.filter_rmse_theta_moving},
                      {"rmse_v_m_s", s.filter_rmse_v},
                      {"rmse_omega_rad_s", s.filter_rmse_omega},
                      {"rmse_v_vs_nominal_m_s", s.filter_rmse_v_nominal},
                      {"rmse_omega_vs_nominal_rad_s", s.filter_rmse_omega_nominal},
                      {"rmse_position_m", s.filter_rmse_position},
                      {"rmse_measurement_m", s.filter_rmse_measurement}};
  j["rig"] = cfg.rig ? nlohmann::json(cfg.rig->folder) : nlohmann::json(nullptr);
  j["wall_time_s"] = s.wall_time;
  return j.dump(indent);
}

}  // namespace viewline::scenarios
