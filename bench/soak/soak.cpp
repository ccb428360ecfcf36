// soak: one long simulated session, to show that nothing drifts or grows.
//
// A ball moves in a room for updates x dt seconds of simulated time (dt = 1 ms): a 3-D
// spring-damper driven by white acceleration noise (stable, so the session can run for hours
// without the truth leaving the room). Every step, a noisy 3-D position measurement updates the
// estimation module's square-root Kalman filter (predict + update, input validation on: the code
// every tracker is built on); every updates/frames steps, one of two cameras renders the room and
// the ball (sim::Renderer, 160x120) and vision::BallDetector finds it (in a window around its last
// detection, as a tracking loop does). Checked over the session:
//
//   * the covariance stays positive definite: the square-root factor L (P = L Lᵀ) has a finite,
//     positive diagonal after every update, and every 1000 updates P's Cholesky succeeds;
//   * NEES stays in its band: one NEES sample every 250 updates (0.25 s, several filter time
//     constants apart, so the samples are close to independent); the session is cut into windows and
//     each window's mean is compared with its two-sided 99 % chi-square band (Bar-Shalom et al.,
//     "Estimation with Applications to Tracking and Navigation", §5.4). A consistent filter leaves
//     1 % of the windows outside by chance; more than 5 % outside, or any window outside the
//     1 - 1e-6 band (a divergence, not chance), fails;
//   * resident memory is flat: VmRSS (/proc/self/status) at the start (after 1 % of the session:
//     caches and buffers warm), the middle and the end; growth over 1 % fails.
//
//   soak_session [--updates 10000000] [--frames 1000000] [--windows 100] [--seed 1] [--json FILE]
//
// Exit status 0 when every check passes, 1 when one fails (the JSON and stdout say which), 2 usage.

#include <CLI/CLI.hpp>
#include <Eigen/Cholesky>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <fstream>
#include <limits>
#include <optional>
#include <string>
#include <vector>

#include "viewline/core/camera.h"
#include "viewline/core/frames.h"
#include "viewline/core/random.h"
#include "viewline/estimation/consistency.h"
#include "viewline/estimation/discretization.h"
#include "viewline/estimation/kalman_filter.h"
#include "viewline/io/files.h"
#include "viewline/sim/renderer.h"
#include "viewline/sim/scene.h"
#include "viewline/sim/worlds.h"
#include "viewline/vision/ball_detector.h"

using namespace viewline;

namespace {

constexpr double kDt = 0.001;              // s between filter updates
constexpr double kOmega = 2.0 * M_PI * 0.2;  // rad/s, natural frequency of the spring-damper
constexpr double kZeta = 0.3;              // damping ratio
constexpr double kQc = 0.5;                // m²/s³, spectral density of the acceleration noise
constexpr double kSigma = 0.005;           // m, measurement noise per axis
constexpr int kNeesEvery = 250;            // updates between NEES samples
constexpr double kBallRadius = 0.1;        // m (a 3-4 px radius at 3-5 m in the 160x120 images)

/// VmRSS of this process in kB (0 when /proc is not there).
long residentKb() {
  std::ifstream f("/proc/self/status");
  std::string key;
  while (f >> key) {
    if (key == "VmRSS:") {
      long kb = 0;
      f >> kb;
      return kb;
    }
    std::getline(f, key);
  }
  return 0;
}

/// The continuous model ẋ = A x + G w of the ball about the room's centre c (the offset p − c is the state).
estimation::ContinuousLinearModel springDamper() {
  estimation::ContinuousLinearModel m;
  m.A = Eigen::MatrixXd::Zero(6, 6);
  m.A.topRightCorner(3, 3).setIdentity();
  m.A.bottomLeftCorner(3, 3) = -kOmega * kOmega * Eigen::Matrix3d::Identity();
  m.A.bottomRightCorner(3, 3) = -2.0 * kZeta * kOmega * Eigen::Matrix3d::Identity();
  m.G = Eigen::MatrixXd::Zero(6, 3);
  m.G.bottomRows(3).setIdentity();
  m.Qc = kQc * Eigen::Matrix3d::Identity();
  return m;
}

core::Camera camera160(const std::string& name, const Eigen::Vector3d& eye) {
  core::Camera c;
  c.name = name;
  c.width = 160;
  c.height = 120;
  c.intrinsics = vpCameraParameters(150.0, 150.0, 80.0, 60.0);
  c.c_M_w = core::lookAt(eye, {0.0, 0.0, 1.5}, Eigen::Vector3d::UnitZ());
  return c;
}

}  // namespace

int main(int argc, char** argv) {
  CLI::App app{"soak: a long simulated session (filter updates and rendered frames); covariance, NEES and memory checked"};
  long updates = 10'000'000, frames = 1'000'000;
  int windows = 100;
  std::uint64_t seed = 1;
  std::string json_path;
  app.add_option("--updates", updates, "filter updates (1 ms apart)")->check(CLI::Range(10'000L, 2'000'000'000L));
  app.add_option("--frames", frames, "rendered and detected frames, spread evenly over the session")->check(CLI::Range(1L, 1'000'000'000L));
  app.add_option("--windows", windows, "NEES windows the session is cut into")->check(CLI::Range(1, 100000));
  app.add_option("--seed", seed, "random seed");
  app.add_option("--json", json_path, "the figures as JSON (written atomically)");
  try {
    app.parse(argc, argv);
  } catch (const CLI::ParseError& e) {
    return app.exit(e) == 0 ? 0 : 2;
  }
  if (frames > updates) {
    std::fprintf(stderr, "soak: --frames (%ld) must not exceed --updates (%ld)\n", frames, updates);
    return 2;
  }
  const long samples_total = updates / kNeesEvery;
  if (samples_total < windows) {
    std::fprintf(stderr, "soak: %ld NEES samples cannot fill %d windows (more --updates or fewer --windows)\n",
                 samples_total, windows);
    return 2;
  }

  try {
    const auto wall0 = std::chrono::steady_clock::now();
    core::Rng rng = core::makeRng(seed);
    const estimation::LinearTransition tr = estimation::discretize(springDamper(), kDt);
    const Eigen::MatrixXd Lq = tr.Q.llt().matrixL();
    estimation::LinearMeasurement meas;
    meas.C = Eigen::MatrixXd::Zero(3, 6);
    meas.C.leftCols(3).setIdentity();
    meas.R = kSigma * kSigma * Eigen::Matrix3d::Identity();
    const Eigen::Vector3d centre(0.0, 0.0, 1.5);

    // Truth starts at rest at the centre; the filter starts there with a generous prior.
    Eigen::VectorXd x_true = Eigen::VectorXd::Zero(6);
    Eigen::MatrixXd P0 = Eigen::MatrixXd::Identity(6, 6);
    P0.topLeftCorner(3, 3) *= 0.25;
    estimation::StateEstimate est(Eigen::VectorXd::Zero(6), P0, 0.0);

    core::Rng room_rng = core::makeRng(core::deriveSeed(seed, 1));
    sim::RoomParams room;
    room.floor_size = 8.0;
    room.wall_height = 4.0;
    Eigen::Vector3d ball_w = centre;
    const sim::SceneWorld world(sim::makeRoom(room, room_rng), [&ball_w](double, std::vector<sim::Primitive>& out) {
      out.push_back(sim::makeSphere("ball", ball_w, kBallRadius, Eigen::Vector3d(0.08, 0.45, 0.95)));
    });
    const std::vector<core::Camera> cams{camera160("left", {-2.5, -3.0, 1.8}), camera160("right", {2.5, -3.0, 1.8})};
    sim::Renderer renderer;
    vision::BallDetectorConfig dcfg;
    dcfg.hsv = {5, 22, 120, 255, 40, 255};  // orange, as config/ball_catching.yaml
    dcfg.roi_half_size_px = 24.0;           // tracking mode: a window around the camera's last detection
    std::vector<vision::BallDetector> detectors;
    for (const auto& c : cams) detectors.emplace_back(dcfg, c);
    std::vector<std::optional<Eigen::Vector2d>> last_px(cams.size());

    const long frame_every = updates / frames;
    const long samples_per_window = samples_total / windows;
    std::vector<estimation::ConsistencyStats> window_stats(static_cast<std::size_t>(windows));
    estimation::ConsistencyStats all_nees;
    long pd_failures = 0, pd_checks = 0, frames_done = 0, detected = 0, detected_within_2px = 0, in_view = 0;
    double max_detection_error_px = 0.0;
    long rss_start = 0, rss_mid = 0, rss_end = 0;
    double min_diag_L = std::numeric_limits<double>::infinity();
    const long start_at = updates / 100, mid_at = updates / 2;
    long next_report = updates / 10;

    for (long k = 0; k < updates; ++k) {
      // Truth and its measurement.
      Eigen::VectorXd n(6);
      for (int i = 0; i < 6; ++i) n(i) = core::gaussian(rng);
      x_true = tr.Phi * x_true + Lq * n;
      meas.y = x_true.head(3);
      for (int i = 0; i < 3; ++i) meas.y(i) += core::gaussian(rng, kSigma);

      estimation::predict(est, tr);
      estimation::update(est, meas);

      // Positive definiteness: the factor's diagonal every update, P's Cholesky every 1000.
      double dmin = std::numeric_limits<double>::infinity();
      bool finite = true;
      for (Eigen::Index i = 0; i < 6; ++i) {
        const double di = std::abs(est.sqrtP()(i, i));
        finite = finite && std::isfinite(di);
        dmin = std::min(dmin, di);
      }
      if (!(dmin > 0.0) || !finite) ++pd_failures;
      min_diag_L = std::min(min_diag_L, dmin);
      if (k % 1000 == 0) {
        ++pd_checks;
        if (est.P().llt().info() != Eigen::Success) ++pd_failures;
      }
      if ((k + 1) % kNeesEvery == 0) {
        const long s = (k + 1) / kNeesEvery - 1;
        const double e = estimation::nees(est, x_true);
        all_nees.add(e, 6.0);
        const long w = s / samples_per_window;
        if (w < windows) window_stats[static_cast<std::size_t>(w)].add(e, 6.0);
      }

      if (k % frame_every == 0 && frames_done < frames) {
        const std::size_t ci = static_cast<std::size_t>(frames_done % 2);
        ball_w = centre + x_true.head(3);
        const double t = static_cast<double>(k) * kDt;
        const cv::Mat img = renderer.render(world, cams[ci], {t, 0.0, 1});
        const auto truth_px = cams[ci].project(ball_w);
        const bool visible = truth_px && cams[ci].inImage(*truth_px, 3.0);
        if (visible) ++in_view;
        const auto r = detectors[ci].detect(img, t, last_px[ci]);
        last_px[ci].reset();
        if (r.ok()) {
          last_px[ci] = r.value().pixel;
          ++detected;
          if (visible) {
            const double err = (r.value().pixel - *truth_px).norm();
            max_detection_error_px = std::max(max_detection_error_px, err);
            if (err <= 2.0) ++detected_within_2px;
          }
        }
        ++frames_done;
      }

      if (k + 1 == start_at) rss_start = residentKb();
      if (k + 1 == mid_at) rss_mid = residentKb();
      if (k + 1 == next_report) {
        std::fprintf(stderr, "  soak %ld / %ld updates, %ld frames, VmRSS %ld kB\n", k + 1, updates, frames_done,
                     residentKb());
        next_report += updates / 10;
      }
    }
    rss_end = residentKb();

    long windows_out = 0, windows_far_out = 0;
    double worst_ratio = 0.0;
    for (const auto& w : window_stats) {
      if (w.count() == 0) continue;
      if (!w.bounds(0.99).contains(w.mean())) ++windows_out;
      if (!w.bounds(1.0 - 1e-6).contains(w.mean())) ++windows_far_out;
      worst_ratio = std::max(worst_ratio, std::abs(w.mean() / 6.0 - 1.0));
    }
    const double growth_mid = rss_start > 0 ? static_cast<double>(rss_mid - rss_start) / rss_start : 0.0;
    const double growth_end = rss_start > 0 ? static_cast<double>(rss_end - rss_start) / rss_start : 0.0;
    const double out_fraction = static_cast<double>(windows_out) / windows;
    const bool pd_ok = pd_failures == 0;
    const bool nees_ok = out_fraction <= 0.05 && windows_far_out == 0;
    const bool rss_ok = rss_start > 0 && growth_mid <= 0.01 && growth_end <= 0.01;
    const double wall_s = std::chrono::duration<double>(std::chrono::steady_clock::now() - wall0).count();

    nlohmann::json j;
    j["updates"] = updates;
    j["frames"] = frames_done;
    j["simulated_s"] = static_cast<double>(updates) * kDt;
    j["seed"] = seed;
    j["covariance"] = {{"pd_failures", pd_failures}, {"cholesky_checks", pd_checks}, {"min_diag_sqrtP", min_diag_L}};
    const core::Interval band = all_nees.bounds(0.99);
    j["nees"] = {{"samples", all_nees.count()},
                 {"mean", all_nees.mean()},
                 {"band99", {band.lo, band.hi}},
                 {"windows", windows},
                 {"samples_per_window", samples_per_window},
                 {"windows_outside_band99", windows_out},
                 {"windows_outside_band_1e-6", windows_far_out},
                 {"worst_window_mean_over_dof_minus_1", worst_ratio}};
    j["vmrss_kb"] = {{"start", rss_start}, {"middle", rss_mid}, {"end", rss_end},
                     {"growth_middle", growth_mid}, {"growth_end", growth_end}};
    j["detection"] = {{"in_view", in_view}, {"detected", detected}, {"within_2px", detected_within_2px},
                      {"max_error_px", max_detection_error_px}};
    j["wall_s"] = wall_s;
    j["pass"] = {{"covariance_pd", pd_ok}, {"nees_band", nees_ok}, {"memory_flat", rss_ok}};
    if (!json_path.empty()) io::writeJsonFile(json_path, j);

    std::printf("soak: %ld filter updates (%.0f s simulated), %ld frames rendered and detected, %.0f s wall\n", updates,
                static_cast<double>(updates) * kDt, frames_done, wall_s);
    std::printf("  covariance: %ld PD failures (%ld Cholesky checks, min diag of sqrtP %.3g)  %s\n", pd_failures, pd_checks,
                min_diag_L, pd_ok ? "ok" : "FAIL");
    std::printf("  NEES: mean %.3f over %zu samples (99%% band [%.3f, %.3f]); %ld of %d windows outside their 99%% band, "
                "%ld outside 1-1e-6  %s\n",
                all_nees.mean(), all_nees.count(), band.lo, band.hi, windows_out, windows, windows_far_out,
                nees_ok ? "ok" : "FAIL");
    std::printf("  VmRSS: start %ld kB, middle %ld kB (%+.2f %%), end %ld kB (%+.2f %%)  %s\n", rss_start, rss_mid,
                100.0 * growth_mid, rss_end, 100.0 * growth_end, rss_ok ? "ok" : "FAIL");
    std::printf("  detection: %ld of %ld frames with the ball in view detected within 2 px (%ld detections, max error %.2f px)\n",
                detected_within_2px, in_view, detected, max_detection_error_px);
    return pd_ok && nees_ok && rss_ok ? 0 : 1;
  } catch (const std::exception& e) {
    std::fprintf(stderr, "soak: error: %s\n", e.what());
    return 1;
  }
}
