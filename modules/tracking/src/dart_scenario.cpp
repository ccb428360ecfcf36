#include "viewline/tracking/dart_scenario.h"

#include <Eigen/Cholesky>
#include <Eigen/LU>
#include <algorithm>
#include <chrono>
#include <cmath>

#include "viewline/core/checks.h"
#include "viewline/core/frames.h"
#include "viewline/estimation/consistency.h"
#include "viewline/tracking/image_ekf.h"

namespace viewline::tracking {

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
  core::requireFinite(gravity_w, "dart scenario: gravity");
  core::requireFinite(release_mean, "dart scenario: throw.release_mean");
  core::requireFinite(release_std, "dart scenario: throw.release_std");
  core::requireFinite(board_center, "dart scenario: throw.board_center");
  if (!(aim_std >= 0.0)) throw core::InvalidInput("dart scenario: throw.aim_std: expected >= 0");
  core::requirePositive(speed_min, "dart scenario: throw.speed_min");
  if (!(speed_max >= speed_min)) throw core::InvalidInput("dart scenario: throw.speed_max: expected >= speed_min");
  if (!(truth_accel_psd >= 0.0)) throw core::InvalidInput("dart scenario: truth_accel_psd: expected >= 0");
  core::requirePositive(pixel_noise_px, "dart scenario: pixel_noise_px");
  if (!(outlier_rate >= 0.0 && outlier_rate < 1.0)) throw core::InvalidInput("dart scenario: outlier_rate: expected in [0, 1)");
  core::requirePositive(dt_offset_period, "dart scenario: dt_offset_period");
  core::requirePositive(alternate_step, "dart scenario: alternate_step");
  if (!(late_max_delay >= 0.0)) throw core::InvalidInput("dart scenario: late_max_delay: expected >= 0");
  if (!(late_horizon >= late_max_delay)) throw core::InvalidInput("dart scenario: late_horizon: expected >= late_max_delay");
  if (single_camera >= cameras.size()) throw core::InvalidInput("dart scenario: single_camera: expected a camera index");
  if (!(single_offset_max >= 0.0)) throw core::InvalidInput("dart scenario: single_offset_max: expected >= 0");
  core::requirePositive(single_prior_std, "dart scenario: single_prior_std");
  core::requirePositive(single_tolerance, "dart scenario: single_tolerance");
  if (!(confidence > 0.0 && confidence < 1.0)) throw core::InvalidInput("dart scenario: confidence: expected in (0, 1)");
  tracker.validate();
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
  cfg.tracker.prior_cov = 100.0 * Matrix6::Identity();
  cfg.tracker.model.gravity_w = cfg.gravity_w;
  cfg.tracker.model.accel_psd = 0.0;
  return cfg;
}

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

std::vector<Capture> captureTimes(const DartScenarioConfig& cfg, ClockMode mode, double duration, core::Rng& rng) {
  std::vector<Capture> caps;
  if (mode == ClockMode::Alternating) {
    for (int k = 1;; ++k) {
      const double t = k * cfg.alternate_step;
      if (t > duration) break;
      caps.push_back({t, (k % 2 == 1) ? 0u : 1u % cfg.cameras.size()});
    }
    return caps;
  }
  for (std::size_t i = 0; i < cfg.cameras.size(); ++i) {
    if (mode == ClockMode::SingleCamera && i != cfg.single_camera) continue;
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

SimFlight simulateFlight(const DartScenarioConfig& cfg, const std::vector<core::Camera>& cameras,
                         ClockMode mode, double outlier_rate, core::Rng& rng, std::uint64_t first_id) {
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

  SimFlight flight;
  flight.duration = T;
  BallisticModel truth_model;
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
    const Eigen::Vector2d uv_true = exactPixelOf(cam, {pc.x() / pc.z(), pc.y() / pc.z()});
    if (!cam.inImage(uv_true, 2.0)) continue;
    SimDetection d;
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
                                  const SimFlight& flight) {
  BallisticModel model;
  model.gravity_w = cfg.gravity_w;
  model.accel_psd = cfg.truth_accel_psd;
  std::vector<double> out;
  Matrix6 Pb = cfg.tracker.prior_cov;  // J⁻¹
  double t = flight.detections.empty() ? 0.0 : flight.detections.front().m.t;
  const double inv_var = 1.0 / (cfg.pixel_noise_px * cfg.pixel_noise_px);
  for (const SimDetection& d : flight.detections) {
    const double dt = d.m.t - t;
    t = d.m.t;
    if (dt > 0.0) {
      Matrix6 Phi = Matrix6::Identity();
      Phi.topRightCorner<3, 3>() = dt * Eigen::Matrix3d::Identity();
      Pb = Phi * Pb * Phi.transpose() + model.processNoise(dt);
    }
    Eigen::Vector2d uv;
    Eigen::Matrix<double, 2, 3> Hp;
    if (pixelJacobian(cameras[d.m.camera], d.truth.head<3>(), uv, Hp)) {
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

namespace {

struct Pooled {
  double se = 0.0;
  double bound = 0.0;
  double nees = 0.0;
  std::size_t n = 0;
  double rmse() const { return n ? std::sqrt(se / static_cast<double>(n)) : 0.0; }
};

double positionNees(const estimation::StateEstimate& s, const Vector6& truth) {
  return estimation::nees(s, truth, {0, 1, 2});
}

void countGate(GateFigures& g, const ViewlineTracker& tr, const SimFlight& f) {
  for (const SimDetection& d : f.detections) {
    const auto o = tr.outcome(d.m.id);
    if (!o) continue;  // refused before processing (e.g. outside the image)
    const bool rejected = o->fate != Fate::Fused;
    if (d.outlier) {
      ++g.outliers;
      if (rejected) ++g.outliers_rejected;
    } else {
      ++g.inliers;
      if (rejected) ++g.inliers_rejected;
    }
  }
}

void finishGate(GateFigures& g, const Pooled& p) {
  g.outlier_rejected_fraction = g.outliers ? static_cast<double>(g.outliers_rejected) / static_cast<double>(g.outliers) : 1.0;
  g.inlier_rejected_fraction = g.inliers ? static_cast<double>(g.inliers_rejected) / static_cast<double>(g.inliers) : 0.0;
  g.rmse_position = p.rmse();
}

double percentile(std::vector<double> v, double q) {
  if (v.empty()) return 0.0;
  std::sort(v.begin(), v.end());
  const auto k = static_cast<std::size_t>(std::ceil(q * static_cast<double>(v.size())));
  return v[std::min(v.size() - 1, k == 0 ? 0 : k - 1)];
}

Eigen::Vector3d randomDirection(core::Rng& rng) {
  Eigen::Vector3d v(core::gaussian(rng), core::gaussian(rng), core::gaussian(rng));
  return v.normalized();
}

}  // namespace

DartSummary runDartExperiments(const DartScenarioConfig& cfg_in, std::uint64_t seed, int runs,
                               const DartRunCallbacks& cb) {
  DartScenarioConfig cfg = cfg_in;
  cfg.tracker.model.gravity_w = cfg.gravity_w;
  cfg.validate();
  if (runs < 1) throw core::InvalidInput("dart scenario: runs: expected >= 1");
  const auto t_start = std::chrono::steady_clock::now();
  const std::vector<core::Camera> cams = makeDartCameras(cfg);

  TrackerConfig exact = cfg.tracker;
  exact.time_mode = TimeMode::Exact;
  exact.late_horizon = cfg.late_horizon;
  TrackerConfig offset = exact;
  offset.time_mode = TimeMode::DtOffset;
  offset.sample_period = cfg.dt_offset_period;

  DartSummary sum;
  sum.seed = seed;
  sum.runs = runs;
  estimation::ConsistencyStats nees6, nees3;
  Pooled a_settled, a_final, b_dir, b_mah, b_ekf, c_exact, c_offset, c_ekf, d_scenario;
  sum.gate_directional.gate = "directional";
  sum.gate_mahalanobis.gate = "mahalanobis";
  sum.scenario_gate.gate = toString(cfg.tracker.gate.kind);
  double update_time = 0.0;
  std::size_t update_count = 0, measurements = 0;
  std::vector<double> convergence;

  auto accumulate = [&](Pooled& p, std::size_t i, const estimation::StateEstimate& s, const SimDetection& d) {
    if (i < cfg.settled_index) return;
    p.se += (s.x().head<3>() - d.truth.head<3>()).squaredNorm();
    p.nees += positionNees(s, d.truth);
    ++p.n;
  };
  auto log = [&](const char* exp, int run, const SimDetection& d, Fate fate, const estimation::StateEstimate& s) {
    if (!cb.log || s.dim() != 6) return;
    cb.log(DartLogRow{exp, run, d, fate, s.x()});
  };

  for (int run = 0; run < runs; ++run) {
    const std::uint64_t run_seed = core::deriveSeed(seed, static_cast<std::uint64_t>(run));
    // ---- A: alternating cameras, no outliers: NEES and RMSE / PCRLB.
    {
      core::Rng rng = core::makeRng(core::deriveSeed(run_seed, 1));
      const SimFlight f = simulateFlight(cfg, cams, ClockMode::Alternating, 0.0, rng);
      const std::vector<double> bound = positionPcrlb(cfg, cams, f);
      ViewlineTracker tr(cams, exact);
      measurements += f.detections.size();
      for (std::size_t i = 0; i < f.detections.size(); ++i) {
        const SimDetection& d = f.detections[i];
        tr.submit(d.m);
        const auto& s = tr.state();
        log("A_alternating", run, d, tr.outcome(d.m.id) ? tr.outcome(d.m.id)->fate : Fate::Gated, s);
        if (i >= cfg.settled_index) {
          a_settled.se += (s.x().head<3>() - d.truth.head<3>()).squaredNorm();
          a_settled.bound += bound[i];
          ++a_settled.n;
        }
        if (i == cfg.nees_index) {
          nees6.add(estimation::nees(s, d.truth), 6.0);
          nees3.add(positionNees(s, d.truth), 3.0);
        }
        if (i + 1 == f.detections.size()) {
          a_final.se += (s.x().head<3>() - d.truth.head<3>()).squaredNorm();
          a_final.bound += bound[i];
          ++a_final.n;
        }
      }
    }
    // ---- B: alternating cameras with outliers: both gates, image EKF.
    {
      core::Rng rng = core::makeRng(core::deriveSeed(run_seed, 2));
      const SimFlight f = simulateFlight(cfg, cams, ClockMode::Alternating, cfg.outlier_rate, rng);
      for (GateKind kind : {GateKind::Directional, GateKind::Mahalanobis}) {
        TrackerConfig tc = exact;
        tc.gate.kind = kind;
        ViewlineTracker tr(cams, tc);
        Pooled& p = kind == GateKind::Directional ? b_dir : b_mah;
        for (std::size_t i = 0; i < f.detections.size(); ++i) {
          tr.submit(f.detections[i].m);
          accumulate(p, i, tr.state(), f.detections[i]);
        }
        countGate(kind == GateKind::Directional ? sum.gate_directional : sum.gate_mahalanobis, tr, f);
      }
      ImageSpaceEkf ekf(cams, exact);
      for (std::size_t i = 0; i < f.detections.size(); ++i) {
        ekf.submit(f.detections[i].m);
        accumulate(b_ekf, i, ekf.state(), f.detections[i]);
      }
    }
    // ---- C: free-running clocks with jitter, no outliers: exact vs Δt-offset vs image EKF.
    {
      core::Rng rng = core::makeRng(core::deriveSeed(run_seed, 3));
      const SimFlight f = simulateFlight(cfg, cams, ClockMode::FreeRunning, 0.0, rng);
      ViewlineTracker tr_exact(cams, exact), tr_offset(cams, offset);
      ImageSpaceEkf ekf(cams, exact);
      for (std::size_t i = 0; i < f.detections.size(); ++i) {
        const SimDetection& d = f.detections[i];
        const auto t0 = std::chrono::steady_clock::now();
        tr_exact.submit(d.m);
        update_time += std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
        ++update_count;
        tr_offset.submit(d.m);
        ekf.submit(d.m);
        accumulate(c_exact, i, tr_exact.state(), d);
        // The Δt-offset estimate lives at a grid instant: compare with the truth at the capture time.
        accumulate(c_offset, i, tr_offset.predictAt(d.m.t), d);
        accumulate(c_ekf, i, ekf.state(), d);
      }
    }
    // ---- D: the full scenario (free-running clocks, jitter, outliers) in capture order and in
    // arrival order (capture + U(0, late_max_delay)).
    {
      core::Rng rng = core::makeRng(core::deriveSeed(run_seed, 5));
      const SimFlight f = simulateFlight(cfg, cams, ClockMode::FreeRunning, cfg.outlier_rate, rng);
      ViewlineTracker tr_exact(cams, exact);
      for (std::size_t i = 0; i < f.detections.size(); ++i) {
        const SimDetection& d = f.detections[i];
        tr_exact.submit(d.m);
        accumulate(d_scenario, i, tr_exact.state(), d);
        const auto o = tr_exact.outcome(d.m.id);
        log("D_scenario", run, d, o ? o->fate : Fate::Gated, tr_exact.state());
      }
      countGate(sum.scenario_gate, tr_exact, f);
      std::vector<std::pair<double, std::size_t>> arrival;
      for (std::size_t i = 0; i < f.detections.size(); ++i)
        arrival.emplace_back(f.detections[i].m.t + core::uniform(rng, 0.0, cfg.late_max_delay), i);
      std::sort(arrival.begin(), arrival.end());
      ViewlineTracker tr_late(cams, exact);
      for (const auto& a : arrival)
        if (tr_late.submit(f.detections[a.second].m) != Refusal::None) ++sum.late_refused;
      sum.late_inserted += tr_late.lateInserted();
      if (tr_exact.initialised() && tr_late.initialised()) {
        const double dx = (tr_exact.state().x() - tr_late.state().x()).cwiseAbs().maxCoeff();
        const double dP = (tr_exact.state().P() - tr_late.state().P()).cwiseAbs().maxCoeff();
        const double dt = std::abs(tr_exact.state().t() - tr_late.state().t());
        sum.late_vs_inorder_max_diff = std::max({sum.late_vs_inorder_max_diff, dx, dP, dt});
      }
      for (const SimDetection& d : f.detections) {
        const auto a = tr_exact.outcome(d.m.id), b = tr_late.outcome(d.m.id);
        if (a.has_value() != b.has_value() || (a && a->fate != b->fate)) ++sum.late_outcome_mismatches;
      }
    }
    // ---- E: one camera, prior far off, against a filter started at the truth.
    {
      core::Rng rng = core::makeRng(core::deriveSeed(run_seed, 4));
      const SimFlight f = simulateFlight(cfg, cams, ClockMode::SingleCamera, 0.0, rng);
      if (!f.detections.empty()) {
        TrackerConfig ref = exact, off = exact;
        ref.prior_mean = f.detections.front().truth;
        ref.prior_cov = cfg.single_prior_std * cfg.single_prior_std * Matrix6::Identity();
        off.prior_cov = ref.prior_cov;
        off.prior_mean = ref.prior_mean;
        off.prior_mean.head<3>() += core::uniform(rng, 0.0, cfg.single_offset_max) * randomDirection(rng);
        off.prior_mean.tail<3>() += core::uniform(rng, 0.0, cfg.single_offset_max) * randomDirection(rng);
        ViewlineTracker tr_ref(cams, ref), tr_off(cams, off);
        std::size_t converged_after = 0;  // number of measurements after which it stays within tolerance
        for (std::size_t i = 0; i < f.detections.size(); ++i) {
          tr_ref.submit(f.detections[i].m);
          tr_off.submit(f.detections[i].m);
          const double diff = (tr_ref.state().x().head<3>() - tr_off.state().x().head<3>()).norm();
          if (diff > cfg.single_tolerance) converged_after = i + 2;
        }
        if (converged_after > f.detections.size()) ++sum.single_camera_not_converged;
        convergence.push_back(static_cast<double>(std::max<std::size_t>(converged_after, 1)));
      }
    }
    if (cb.progress) cb.progress(run + 1, runs);
  }

  sum.nees_samples = nees6.count();
  if (nees6.count() > 0) {
    sum.nees_mean = nees6.mean();
    sum.nees_bounds = nees6.bounds(cfg.confidence);
    sum.nees_position_mean = nees3.mean();
    sum.nees_position_bounds = nees3.bounds(cfg.confidence);
  }
  sum.rmse_position = a_settled.rmse();
  sum.pcrlb_position = a_settled.n ? std::sqrt(a_settled.bound / static_cast<double>(a_settled.n)) : 0.0;
  sum.rmse_to_pcrlb = sum.pcrlb_position > 0 ? sum.rmse_position / sum.pcrlb_position : 0.0;
  const double final_bound = a_final.n ? std::sqrt(a_final.bound / static_cast<double>(a_final.n)) : 0.0;
  sum.rmse_to_pcrlb_final = final_bound > 0 ? a_final.rmse() / final_bound : 0.0;
  sum.measurements_per_flight = static_cast<double>(measurements) / runs;
  finishGate(sum.gate_directional, b_dir);
  finishGate(sum.gate_mahalanobis, b_mah);
  // The better gate: fewest errors of both kinds (outliers let through + inliers rejected).
  auto errors = [](const GateFigures& g) {
    return (1.0 - g.outlier_rejected_fraction) + g.inlier_rejected_fraction;
  };
  const GateFigures& better =
      errors(sum.gate_mahalanobis) <= errors(sum.gate_directional) ? sum.gate_mahalanobis : sum.gate_directional;
  sum.better_gate = better.gate;
  sum.outlier_rejected_fraction = better.outlier_rejected_fraction;
  sum.inlier_rejected_fraction = better.inlier_rejected_fraction;
  sum.rmse_image_ekf_alternating = b_ekf.rmse();
  sum.rmse_async_exact = c_exact.rmse();
  sum.rmse_async_dt_offset = c_offset.rmse();
  sum.rmse_async_image_ekf = c_ekf.rmse();
  sum.nees_async_exact = c_exact.n ? c_exact.nees / static_cast<double>(c_exact.n) : 0.0;
  sum.nees_async_dt_offset = c_offset.n ? c_offset.nees / static_cast<double>(c_offset.n) : 0.0;
  finishGate(sum.scenario_gate, d_scenario);
  sum.update_time_us = update_count ? 1e6 * update_time / static_cast<double>(update_count) : 0.0;
  sum.single_camera_convergence_p95 = percentile(convergence, 0.95);
  sum.single_camera_convergence_median = percentile(convergence, 0.5);
  sum.runtime_s = std::chrono::duration<double>(std::chrono::steady_clock::now() - t_start).count();
  return sum;
}

}  // namespace viewline::tracking
