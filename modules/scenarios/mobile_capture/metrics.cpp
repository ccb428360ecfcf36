#include "viewline/scenarios/mobile_capture/metrics.h"

#include <algorithm>
#include <atomic>
#include <chrono>
#include <cstdio>
#include <cmath>
#include <mutex>
#include <nlohmann/json.hpp>
#include <string>
#include <thread>

#include "viewline/core/error.h"
#include "viewline/core/interrupt.h"
#include "viewline/core/random.h"
#include "viewline/core/statistics.h"
#include "viewline/estimation/models/unicycle.h"
#include "viewline/robots/mobile_ground_localization.h"
#include "viewline/scenarios/mobile_capture/world.h"
#include "viewline/tracking/unicycle_tracker.h"

namespace viewline::scenarios {

using Eigen::Vector2d;
using Eigen::Vector3d;
using Eigen::VectorXd;
using namespace mobile_capture;

// ------------------------------------------------------------------------------------------------
// Filter test ([K] §3.2).

FilterTestResult runFilterTest(const MobileCaptureConfig& cfg, std::uint64_t seed) {
  cfg.validate();
  Streams rng(seed);
  MobileCaptureConfig c = cfg;
  c.object_noise = true;
  const sim::GroundTarget target(
      targetParams(c, sim::GroundProfile::FilterTest, cfg.filter_test_duration + 1.0), rng.object);
  tracking::UnicycleTrackerConfig tc = cfg.filter;
  tc.model.q_v = cfg.filter_test_q_v;
  tc.model.q_w = cfg.filter_test_q_w;
  tc.gate.probability = 1.0 - 1e-9;  // every measurement is the truth plus the stated noise
  const double sigma = std::sqrt(cfg.filter_test_measurement_var) * 0.01;  // cm² -> m
  const Eigen::Matrix2d R = sigma * sigma * Eigen::Matrix2d::Identity();
  tracking::UnicycleTracker filter(tc);
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
  r.rmse_theta = core::rmsFromSum(se_th, n);
  r.rmse_theta_moving = n_moving > 0 ? core::rmsFromSum(se_thm, n_moving) : 0.0;
  r.rmse_v = core::rmsFromSum(se_v, n);
  r.rmse_omega = core::rmsFromSum(se_w, n);
  r.rmse_v_nominal = core::rmsFromSum(se_vn, n);
  r.rmse_omega_nominal = core::rmsFromSum(se_wn, n);
  r.rmse_position = core::rmsFromSum(se_p, n);
  r.rmse_measurement = core::rmsFromSum(se_m, n);
  return r;
}

// ------------------------------------------------------------------------------------------------
// Field-of-view sweep of the ground localisation.

FovSweepResult compareGroundLocalization(const MobileCaptureConfig& cfg, std::uint64_t seed) {
  cfg.validate();
  core::Rng rng = core::makeRng(core::deriveSeed(seed, 99));
  const robots::MobilePanTilt head(cfg.head);
  core::Camera true_camera = renderCamera(cfg);  // makes the floor points of the pixels
  core::Camera camera = estimatorCamera(cfg);    // locates them
  const robots::AnglePerPixel printed{cfg.hfov, cfg.vfov, robots::AngleRange::PrintedSlant};
  const robots::AnglePerPixel horizontal{cfg.hfov, cfg.vfov, robots::AngleRange::Horizontal};
  const double plane_z = 0.5 * cfg.object_height;
  FovSweepResult r;
  for (int pose = 0; pose < cfg.fov_sweep_poses; ++pose) {
    if (core::interruptRequested()) break;  // the batch then reports no sweep (runMobileCaptureBatch)
    // A head looking at a floor point 0.5-4 m ahead within ±45° (what the chase produces).
    const double range = core::uniform(rng, 0.5, 4.0), bearing = core::uniform(rng, -0.8, 0.8);
    const auto q = head.pointAtBest(Vector3d(range * std::cos(bearing), range * std::sin(bearing), plane_z));
    true_camera.c_M_w = trueCamera_c_M_w(head, q, 0.0, 0.0, 0.0);
    camera.c_M_w = estimatorCamera_c_M_w(cfg, true_camera.c_M_w);
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

MobileCaptureSummary runMobileCaptureBatch(const MobileCaptureConfig& cfg, int runs, std::uint64_t seed,
                                           const std::function<void(int, int)>& progress,
                                           const MobileCaptureSessionIo& io) {
  cfg.validate();
  if (runs < 1) throw core::InvalidInput("runs: expected >= 1");
  const std::string replay_root = mobileCaptureReplayRoot(cfg, io);
  if (!io.record_dir.empty())
    runtime::beginSessionRecording(io.record_dir, {"mobile_capture", seed, runs, "run"}, io.config_text);
  if (!replay_root.empty()) runtime::checkSessionReplay(replay_root, "mobile_capture", seed, runs);
  const auto start = std::chrono::steady_clock::now();
  MobileCaptureSummary s;
  s.runs.resize(static_cast<std::size_t>(runs));
  std::atomic<int> next{0}, done{0};
  std::atomic<bool> stopped{false};
  std::vector<char> completed(static_cast<std::size_t>(runs), 0);
  std::mutex mutex;
  std::exception_ptr error;
  // A stop request (SIGINT/SIGTERM) ends the batch after the runs in flight: they return early
  // (their scheduler polls the request) and are dropped, no new run starts, and the summary is
  // over the runs that completed.
  auto worker = [&]() {
    for (;;) {
      if (core::interruptRequested()) {
        stopped = true;
        return;
      }
      const int i = next++;
      if (i >= runs) return;
      try {
        auto& r = s.runs[static_cast<std::size_t>(i)];
        MobileCaptureHooks files;  // the run's folders in a session recording
        if (!io.record_dir.empty()) files.record_dir = mobileCaptureRunDir(io.record_dir, i);
        if (!replay_root.empty()) files.replay_dir = mobileCaptureRunDir(replay_root, i);
        const bool with_files = !files.record_dir.empty() || !files.replay_dir.empty();
        r = runMobileCapture(cfg, core::deriveSeed(seed, static_cast<std::uint64_t>(i)), with_files ? &files : nullptr);
        if (r.interrupted) {
          stopped = true;
          return;
        }
        completed[static_cast<std::size_t>(i)] = 1;
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
  std::vector<MobileCaptureRun> finished;
  for (std::size_t k = 0; k < s.runs.size(); ++k)
    if (completed[k]) finished.push_back(std::move(s.runs[k]));
  s.runs = std::move(finished);
  s.interrupted = stopped;
  const auto kept = static_cast<double>(s.runs.size());

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
  // No completed run (stopped at once): the rates are not scored (NaN, JSON null).
  s.success_rate = ok / kept;
  s.oracle_success_rate = oracle_ok / kept;
  s.ratio_runs = static_cast<int>(ratios.size());
  if (!ratios.empty()) {
    s.ratio_median = core::percentile(ratios, 0.5);
    s.ratio_p95 = core::percentile(ratios, 0.95);
  }
  if (!times.empty()) {
    s.time_median = core::percentile(times, 0.5);
    s.time_p95 = core::percentile(times, 0.95);
  }
  if (!oracle_times.empty()) s.oracle_time_median = core::percentile(oracle_times, 0.5);

  // The filter test and the field-of-view sweep are long: not after a stop request, and a request
  // that comes while they run ends them (their figures are then not reported, summaryJson).
  const auto stop = [&] {
    if (core::interruptRequested()) stopped = true;
    if (!stopped) return false;
    s.interrupted = true;
    s.wall_time = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
    return true;
  };
  if (stop()) return s;
  for (int k = 0; k < cfg.filter_test_runs; ++k) {
    if (stop()) return s;
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
  if (stop()) return s;
  s.fov = compareGroundLocalization(cfg, seed);
  if (stop()) return s;
  s.wall_time = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  return s;
}

namespace {
// An empty accumulator prints 0 (as it always has), not core::rmsFromSum's NaN (JSON null).
double rms(double sse, long n) { return n > 0 ? core::rmsFromSum(sse, n) : 0.0; }
/// Mean of `sum` over `n` samples of `dof` degrees of freedom with its two-sided 99 % chi-square
/// band (samples counted as independent) and the verdict.
nlohmann::json bandJson(double sum, long n, double dof) {
  if (n <= 0) return {{"mean", nullptr}, {"bounds", nullptr}, {"samples", 0}, {"dof", dof}, {"verdict", "n/a"}};
  const double mean = sum / static_cast<double>(n);
  const core::Interval b = core::averagedChiSquareInterval(dof, static_cast<double>(n), 0.99);
  const char* verdict = mean > b.hi ? "overconfident" : mean < b.lo ? "underconfident" : "consistent";
  return {{"mean", mean}, {"bounds", {b.lo, b.hi}}, {"samples", n}, {"dof", dof}, {"verdict", verdict}};
}
/// NIS and position NEES pooled over the runs (MobileCaptureRun).
nlohmann::json consistencyJson(const MobileCaptureSummary& s) {
  double nis = 0.0, nees = 0.0;
  long n_nis = 0, n_nees = 0;
  for (const auto& r : s.runs) nis += r.nis_sum, n_nis += r.nis_count, nees += r.nees_sum, n_nees += r.nees_count;
  return {{"nis", bandJson(nis, n_nis, 2.0)},
          {"position_nees", bandJson(nees, n_nees, 2.0)},
          {"settle_s", kConsistencySettle},
          {"nees_spacing_s", kNeesSpacing},
          {"confidence", 0.99}};
}
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
  // A figure over no run is not scored: null, not 0.
  const bool any_capture = std::any_of(s.runs.begin(), s.runs.end(), [](const MobileCaptureRun& r) { return r.captured; });
  const bool any_oracle =
      std::any_of(s.runs.begin(), s.runs.end(), [](const MobileCaptureRun& r) { return r.oracle_captured; });
  auto scored = [](bool ok, double v) { return ok ? nlohmann::json(v) : nlohmann::json(nullptr); };
  j["capture_time_ratio_to_oracle"] = {{"median", scored(s.ratio_runs > 0, s.ratio_median)},
                                       {"p95", scored(s.ratio_runs > 0, s.ratio_p95)},
                                       {"runs", s.ratio_runs}};
  j["capture_time_s"] = {{"median", scored(any_capture, s.time_median)}, {"p95", scored(any_capture, s.time_p95)}};
  j["oracle_capture_time_s"] = {{"median", scored(any_oracle, s.oracle_time_median)}};
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
  if (s.interrupted) {  // not run after a stop request
    j["ground_localization_fov_sweep"] = nullptr;
    j["filter_test"] = nullptr;
  }
  j["consistency"] = consistencyJson(s);
  j["rig"] = cfg.rig ? nlohmann::json(cfg.rig->folder) : nlohmann::json(nullptr);
  j["wall_time_s"] = s.wall_time;
  if (!cfg.faults.faults.empty()) {  // only with injected faults: reference summaries unchanged
    runtime::FaultReport total;
    for (const MobileCaptureRun& r : s.runs) total.add(r.faults);
    j["faults"] = runtime::toJson(total);
  }
  return j.dump(indent);
}

std::string summaryText(const MobileCaptureSummary& s, const MobileCaptureConfig& cfg, int runs, std::uint64_t seed) {
  std::string out;
  char line[512];
  if (s.interrupted)
    std::snprintf(line, sizeof line, "mobile_capture: %zu of %d runs (interrupted), seed %llu, %.0f s wall\n",
                  s.runs.size(), runs, static_cast<unsigned long long>(seed), s.wall_time);
  else
    std::snprintf(line, sizeof line, "mobile_capture: %d runs, seed %llu, %.0f s wall\n", runs,
                  static_cast<unsigned long long>(seed), s.wall_time);
  out += line;
  if (cfg.rig) {
    std::snprintf(line, sizeof line, "  camera: rig %s (renders with truth.yaml; estimators use rig.yaml + ground.yaml)\n",
                  cfg.rig->folder.c_str());
    out += line;
  } else {
    out += "  camera: inline config keys (one perfect camera)\n";
  }
  const bool any_capture = std::any_of(s.runs.begin(), s.runs.end(), [](const MobileCaptureRun& r) { return r.captured; });
  const bool any_oracle =
      std::any_of(s.runs.begin(), s.runs.end(), [](const MobileCaptureRun& r) { return r.oracle_captured; });
  if (s.runs.empty()) {
    out += "  no run completed: nothing scored\n";
    return out;
  }
  std::snprintf(line, sizeof line, "  capture success %.3f (oracle %.3f); ", s.success_rate, s.oracle_success_rate);
  out += line;
  if (any_capture) {
    std::snprintf(line, sizeof line, "time median %.1f s, p95 %.1f s; ", s.time_median, s.time_p95);
    out += line;
  } else {
    out += "time not scored (no capture); ";
  }
  if (any_oracle) {
    std::snprintf(line, sizeof line, "oracle median %.1f s\n", s.oracle_time_median);
    out += line;
  } else {
    out += "oracle time not scored (the oracle captured in no run)\n";
  }
  if (s.ratio_runs > 0) {
    std::snprintf(line, sizeof line, "  capture time / oracle: median %.3f, p95 %.3f (%d runs)\n", s.ratio_median,
                  s.ratio_p95, s.ratio_runs);
  } else {
    std::snprintf(line, sizeof line, "  capture time / oracle: not scored (no run where both captured)\n");
  }
  out += line;
  const nlohmann::json c = consistencyJson(s);
  for (const char* k : {"nis", "position_nees"}) {
    const nlohmann::json& x = c[k];
    if (x["samples"].get<long>() == 0) continue;
    std::snprintf(line, sizeof line, "  %s %.3f in its 99 %% band [%.3f, %.3f] (%ld samples, 2 dof): %s\n",
                  k == std::string("nis") ? "NIS" : "position NEES", x["mean"].get<double>(),
                  x["bounds"][0].get<double>(), x["bounds"][1].get<double>(), x["samples"].get<long>(),
                  x["verdict"].get<std::string>().c_str());
    out += line;
  }
  const LocalizationErrors& l = s.localization;
  std::snprintf(line, sizeof line,
                "  ground localisation RMS in the loop: exact %.3f m, [K] angle/pixel printed %.3f m, "
                "horizontal range %.3f m\n",
                rms(l.sse_exact, l.count), rms(l.sse_printed, l.count), rms(l.sse_horizontal, l.count));
  out += line;
  if (!cfg.faults.faults.empty()) {
    runtime::FaultReport total;
    for (const MobileCaptureRun& r : s.runs) total.add(r.faults);
    out += "  " + runtime::summaryLine(total) + "\n";
  }
  if (s.interrupted) {
    out += "  FOV sweep and filter test: not run (interrupted)\n";
    return out;
  }
  const LocalizationErrors& f = s.fov.all;
  std::snprintf(line, sizeof line, "  FOV sweep RMS: exact %.3f m, printed %.3f m, horizontal %.3f m\n",
                rms(f.sse_exact, f.count), rms(f.sse_printed, f.count), rms(f.sse_horizontal, f.count));
  out += line;
  std::snprintf(line, sizeof line,
                "  filter test RMSE after %.0f s: theta %.3f rad (%.3f while moving >= 5 cm/s), v %.4f m/s, "
                "omega %.3f rad/s (vs nominal profile: v %.4f, omega %.3f)\n",
                cfg.convergence_time, s.filter_rmse_theta, s.filter_rmse_theta_moving, s.filter_rmse_v,
                s.filter_rmse_omega, s.filter_rmse_v_nominal, s.filter_rmse_omega_nominal);
  out += line;
  return out;
}

void logFilterTest(const FilterTestResult& f, io::LogDirectory& log) {
  if (!log.enabled()) return;
  auto& csv = log.stream("filter_test", {"t", "err_theta", "err_v", "err_omega"});
  for (std::size_t i = 0; i < f.t.size(); ++i) csv.row({f.t[i], f.err_theta[i], f.err_v[i], f.err_omega[i]});
  log.flush();
}

}  // namespace viewline::scenarios
