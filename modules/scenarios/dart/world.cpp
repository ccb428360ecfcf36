#include "viewline/scenarios/dart/world.h"

#include <Eigen/LU>
#include <algorithm>

#include "viewline/core/frames.h"
#include "viewline/tracking/image_ekf.h"
#include "viewline/tracking/viewline.h"

namespace viewline::scenarios {

using tracking::Matrix6;
using tracking::Vector6;

std::vector<core::Camera> makeDartCameras(const DartScenarioConfig& cfg) {
  std::vector<core::Camera> cams;
  const Eigen::Vector3d up = -cfg.gravity_w.normalized();
  for (const DartCameraConfig& c : cfg.cameras) {
    core::Camera cam;
    cam.name = c.name;
    cam.width = c.width;
    cam.height = c.height;
    const vpCameraParameters pin = core::intrinsicsFromFov(c.hfov_rad, c.width, c.height);
    cam.intrinsics = vpCameraParameters(pin.get_px(), pin.get_py(), pin.get_u0(), pin.get_v0(), c.kud, -c.kud);
    cam.c_M_w = core::lookAt(c.eye_w, c.target_w, up);
    cams.push_back(cam);
  }
  return cams;
}

namespace {

struct Capture {
  double t;
  std::size_t camera;
};

std::vector<Capture> captureTimes(const DartScenarioConfig& cfg, DartClockMode mode, double duration, core::Rng& rng) {
  std::vector<Capture> caps;
  if (mode == DartClockMode::Alternating) {
    for (int k = 1;; ++k) {
      const double t = k * cfg.alternate_step;
      if (t > duration) break;
      caps.push_back({t, (k % 2 == 1) ? 0u : 1u % cfg.cameras.size()});
    }
    return caps;
  }
  for (std::size_t i = 0; i < cfg.cameras.size(); ++i) {
    if (mode == DartClockMode::SingleCamera && i != cfg.single_camera) continue;
    const DartCameraConfig& c = cfg.cameras[i];
    const double period = (1.0 + core::gaussian(rng, c.clock_drift_std)) / c.rate_hz;
    const double phase = core::uniform(rng, 0.0, period);
    for (int n = 0;; ++n) {
      const double t = phase + n * period + core::gaussian(rng, c.jitter_std_s);
      if (t > duration) break;
      if (t > 0.0) caps.push_back({t, i});
    }
  }
  std::stable_sort(caps.begin(), caps.end(), [](const Capture& a, const Capture& b) { return a.t < b.t; });
  return caps;
}

}  // namespace

DartFlight simulateDartFlight(const DartScenarioConfig& cfg, const std::vector<core::Camera>& cameras,
                              DartClockMode mode, double outlier_rate, core::Rng& rng, std::uint64_t first_id) {
  // The throw: release point, aim point on the board, speed -> flight time and initial velocity.
  Vector6 x;
  Eigen::Vector3d p0;
  for (int k = 0; k < 3; ++k) p0[k] = cfg.release_mean[k] + core::gaussian(rng, cfg.release_std[k]);
  Eigen::Vector3d aim = cfg.board_center;
  aim.y() += core::gaussian(rng, cfg.aim_std);
  aim.z() += core::gaussian(rng, cfg.aim_std);
  const double speed = core::uniform(rng, cfg.speed_min, cfg.speed_max);
  const double T = (aim - p0).norm() / speed;
  x.head<3>() = p0;
  x.tail<3>() = (aim - p0 - 0.5 * T * T * cfg.gravity_w) / T;

  DartFlight flight;
  flight.duration = T;
  tracking::BallisticModel truth_model;
  truth_model.gravity_w = cfg.gravity_w;
  truth_model.accel_psd = cfg.truth_accel_psd;
  const std::vector<Capture> caps = captureTimes(cfg, mode, T, rng);
  double t = 0.0;
  std::uint64_t id = first_id;
  for (const Capture& c : caps) {
    const double dt = c.t - t;
    x = truth_model.propagate(x, dt);
    if (cfg.truth_accel_psd > 0.0 && dt > 0.0) {
      const Eigen::VectorXd w = core::sampleGaussian(rng, Eigen::VectorXd::Zero(6), truth_model.processNoise(dt));
      x += w;
    }
    t = c.t;
    const core::Camera& cam = cameras[c.camera];
    const double u_out = core::uniform(rng, 0.0, 1.0);
    const Eigen::Vector2d noise(core::gaussian(rng, cfg.pixel_noise_px), core::gaussian(rng, cfg.pixel_noise_px));
    const Eigen::Vector2d rnd_px(core::uniform(rng, 0.0, cam.width - 1.0), core::uniform(rng, 0.0, cam.height - 1.0));
    const Eigen::Vector3d pc = cam.c_M_w * x.head<3>();
    if (pc.z() < 0.1) continue;
    const Eigen::Vector2d uv_true = tracking::exactPixelOf(cam, {pc.x() / pc.z(), pc.y() / pc.z()});
    if (!cam.inImage(uv_true, 2.0)) continue;
    DartDetection d;
    d.truth = x;
    d.outlier = u_out < outlier_rate;
    d.m.id = id++;
    d.m.camera = c.camera;
    d.m.t = c.t;
    d.m.sigma_px = cfg.pixel_noise_px;
    d.m.uv = d.outlier ? rnd_px : Eigen::Vector2d(uv_true + noise);
    flight.detections.push_back(d);
  }
  return flight;
}

std::vector<double> positionPcrlb(const DartScenarioConfig& cfg, const std::vector<core::Camera>& cameras,
                                  const DartFlight& flight) {
  tracking::BallisticModel model;
  model.gravity_w = cfg.gravity_w;
  model.accel_psd = cfg.truth_accel_psd;
  std::vector<double> out;
  Matrix6 Pb = cfg.tracker.prior_cov;  // J⁻¹
  double t = flight.detections.empty() ? 0.0 : flight.detections.front().m.t;
  const double inv_var = 1.0 / (cfg.pixel_noise_px * cfg.pixel_noise_px);
  for (const DartDetection& d : flight.detections) {
    const double dt = d.m.t - t;
    t = d.m.t;
    if (dt > 0.0) {
      Matrix6 Phi = Matrix6::Identity();
      Phi.topRightCorner<3, 3>() = dt * Eigen::Matrix3d::Identity();
      Pb = Phi * Pb * Phi.transpose() + model.processNoise(dt);
    }
    Eigen::Vector2d uv;
    Eigen::Matrix<double, 2, 3> Hp;
    if (tracking::pixelJacobian(cameras[d.m.camera], d.truth.head<3>(), uv, Hp)) {
      Eigen::Matrix<double, 2, 6> H = Eigen::Matrix<double, 2, 6>::Zero();
      H.leftCols<3>() = Hp;
      // (J_pred + Hᵀ R⁻¹ H)⁻¹ in covariance form: P − P Hᵀ (R + H P Hᵀ)⁻¹ H P (no prior inversion).
      const Eigen::Matrix2d S = H * Pb * H.transpose() + (1.0 / inv_var) * Eigen::Matrix2d::Identity();
      const Eigen::Matrix<double, 6, 2> K = Pb * H.transpose() * S.inverse();
      Pb = Pb - K * H * Pb;
      Pb = 0.5 * (Pb + Pb.transpose()).eval();
    }
    out.push_back(Pb.topLeftCorner<3, 3>().trace());
  }
  return out;
}

}  // namespace viewline::scenarios
