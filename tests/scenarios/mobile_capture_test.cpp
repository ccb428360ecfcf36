// Short seeded runs of the mobile-capture scenario's library code. The long runs are the app
// command reported in docs/results.md.
#include <gtest/gtest.h>

#include <Eigen/Cholesky>
#include <algorithm>
#include <chrono>
#include <cmath>
#include <future>
#include <vector>

#include "viewline/core/error.h"
#include "viewline/core/frames.h"
#include "viewline/core/statistics.h"
#include "viewline/io/config.h"
#include "viewline/runtime/telemetry.h"
#include "viewline/scenarios/mobile_capture.h"

namespace viewline::scenarios {
namespace {

MobileCaptureConfig shipped() {
  // ctest runs from the project root (viewline_add_test WORKING_DIRECTORY).
  return loadMobileCaptureConfig(io::ConfigNode::loadFile("config/mobile_capture.yaml"));
}

MobileCaptureConfig perfectCamera() {
  // The shipped scenario on one perfect pinhole camera (inline keys: 50° x 40°, no distortion)
  // shared by the renderer and the estimators.
  MobileCaptureConfig cfg = shipped();
  cfg.rig.reset();
  cfg.hfov = core::deg2rad(50.0);
  cfg.vfov = core::deg2rad(40.0);
  return cfg;
}

TEST(MobileCapture, HeadlineGuardOnSeedsTheNoiseWasNotTunedOn) {
  // The shipped config (calibrated rig) on 3 seeds; its noise was tuned on the runs of seed 1000
  // (config/mobile_capture.yaml). docs/results.md "Mobile capture": success 1.00, median time
  // ratio to the oracle ~1.13, NIS and position NEES inside their 99 % bands. The thresholds fail
  // at a ~20 % regression: a missed capture, a median ratio above 1.35, a NIS mean outside its
  // band (with ~500 samples the band is ±12 % of 2).
  const MobileCaptureConfig cfg = shipped();
  ASSERT_TRUE(cfg.rig.has_value());
  // The three chases run concurrently (each is independent and thread-safe, as in the batch).
  const std::vector<std::uint64_t> seeds{21u, 22u, 23u};
  std::vector<int> frames_seen(seeds.size(), 0);
  std::vector<std::future<MobileCaptureRun>> runs;
  for (std::size_t k = 0; k < seeds.size(); ++k) {
    runs.push_back(std::async(std::launch::async, [&cfg, &frames_seen, &seeds, k] {
      MobileCaptureHooks hooks;
      hooks.on_frame = [&frames_seen, k](const MobileCaptureFrame& f) {
        ++frames_seen[k];
        EXPECT_TRUE(f.image != nullptr && f.image->cols == 320 && f.image->rows == 240);
      };
      return runMobileCapture(cfg, seeds[k], &hooks);
    }));
  }
  std::vector<double> ratios;
  double nis = 0.0, nees = 0.0;
  long n_nis = 0, n_nees = 0;
  for (std::size_t k = 0; k < seeds.size(); ++k) {
    SCOPED_TRACE(seeds[k]);
    const MobileCaptureRun r = runs[k].get();
    EXPECT_TRUE(r.captured);
    EXPECT_TRUE(r.oracle_captured);
    EXPECT_EQ(frames_seen[k], r.frames);
    EXPECT_GT(r.detections, 0.9 * r.frames);  // the head keeps the object in view
    ASSERT_GT(r.oracle_time, 0.0);
    ratios.push_back(r.capture_time / r.oracle_time);
    // Ground localisation in the loop: exact back-projection beats [K]'s angle per pixel; the
    // calibrated rig adds its calibration error (world rays ~1 px off: several cm at 3-4 m from a
    // camera 0.44 m high).
    ASSERT_GT(r.localization.count, 50);
    const double exact = std::sqrt(r.localization.sse_exact / r.localization.count);
    EXPECT_LT(exact, std::sqrt(r.localization.sse_printed / r.localization.count));
    EXPECT_LT(exact, 0.10);
    nis += r.nis_sum, n_nis += r.nis_count, nees += r.nees_sum, n_nees += r.nees_count;
  }
  std::sort(ratios.begin(), ratios.end());
  EXPECT_GT(ratios[1], 0.8);  // the oracle has perfect knowledge: not beaten by much
  EXPECT_LT(ratios[1], 1.35);
  ASSERT_GT(n_nis, 300);
  ASSERT_GT(n_nees, 20);
  const core::Interval nis_band = core::averagedChiSquareInterval(2.0, static_cast<double>(n_nis), 0.99);
  const core::Interval nees_band = core::averagedChiSquareInterval(2.0, static_cast<double>(n_nees), 0.99);
  EXPECT_TRUE(nis_band.contains(nis / n_nis)) << nis / n_nis << " not in [" << nis_band.lo << ", " << nis_band.hi << "]";
  EXPECT_TRUE(nees_band.contains(nees / n_nees)) << nees / n_nees << " not in [" << nees_band.lo << ", " << nees_band.hi << "]";
}

TEST(MobileCapture, ShortSeededCaptureFromKsStart) {
  // On a perfect camera (the calibrated rig: HeadlineGuardOnSeedsTheNoiseWasNotTunedOn).
  for (const bool calibrated : {false}) {
    SCOPED_TRACE(calibrated ? "calibrated rig" : "perfect camera");
    MobileCaptureConfig cfg = calibrated ? shipped() : perfectCamera();
    ASSERT_EQ(cfg.rig.has_value(), calibrated);
    cfg.max_time = 45.0;
    int frames_seen = 0;
    MobileCaptureHooks hooks;
    hooks.on_frame = [&](const MobileCaptureFrame& f) {
      ++frames_seen;
      ASSERT_NE(f.image, nullptr);
      EXPECT_EQ(f.image->cols, 320);
      EXPECT_EQ(f.image->rows, 240);
    };
    const MobileCaptureRun r = runMobileCapture(cfg, 7, &hooks);
    EXPECT_TRUE(r.captured);
    EXPECT_TRUE(r.oracle_captured);
    EXPECT_EQ(frames_seen, r.frames);
    EXPECT_GT(r.detections, 0.9 * r.frames);  // the head keeps the object in view
    ASSERT_GT(r.oracle_time, 0.0);
    // The oracle is the same planner with perfect knowledge: we cannot beat it by much, and must
    // not be far behind it.
    EXPECT_GT(r.capture_time / r.oracle_time, 0.8);
    EXPECT_LT(r.capture_time / r.oracle_time, 1.5);
    // Ground localisation in the loop: exact back-projection beats [K]'s angle per pixel.
    ASSERT_GT(r.localization.count, 50);
    const double exact = std::sqrt(r.localization.sse_exact / r.localization.count);
    const double printed = std::sqrt(r.localization.sse_printed / r.localization.count);
    EXPECT_LT(exact, printed);
    // Perfect camera: the method's own error (blob centroid vs box centre, pixel noise). The
    // calibrated rig adds its calibration error: world rays ~1 px (0.17°) off, i.e. several cm at
    // 3-4 m from a camera 0.44 m high (docs/results.md, mobile capture on the calibrated rig).
    EXPECT_LT(exact, calibrated ? 0.10 : 0.04);
  }
}

TEST(MobileCapture, PacedAndUnpacedRunsThroughTheSchedulerAreIdentical) {
  // Pacing changes when events run, never what they compute: the same run as fast as possible
  // and at 20 simulated seconds per wall second (--realtime 20) gives the same records.
  MobileCaptureConfig cfg = shipped();
  cfg.max_time = 2.0;
  runtime::MemorySink fast_sink, paced_sink;
  MobileCaptureHooks fast, paced;
  fast.telemetry = &fast_sink;
  paced.telemetry = &paced_sink;
  paced.pacing = runtime::Pacing{20.0};
  const MobileCaptureRun a = runMobileCapture(cfg, 7, &fast);
  const auto start = std::chrono::steady_clock::now();
  const MobileCaptureRun b = runMobileCapture(cfg, 7, &paced);
  const double wall = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  EXPECT_GE(wall, 0.9 * cfg.max_time / 20.0);  // it was paced
  EXPECT_EQ(a.captured, b.captured);
  EXPECT_EQ(a.capture_time, b.capture_time);
  EXPECT_EQ(a.frames, b.frames);
  EXPECT_EQ(a.detections, b.detections);
  EXPECT_EQ(a.grasp_attempts, b.grasp_attempts);
  EXPECT_EQ(a.localization.sse_exact, b.localization.sse_exact);
  EXPECT_EQ(a.gate.total(), b.gate.total());
  EXPECT_EQ(a.frames, 21);  // frames at t = 0, 0.1, ..., 2.0
  ASSERT_EQ(fast_sink.estimates.size(), paced_sink.estimates.size());
  for (std::size_t i = 0; i < fast_sink.estimates.size(); ++i) {
    EXPECT_EQ(fast_sink.estimates[i].t, paced_sink.estimates[i].t);
    EXPECT_EQ(fast_sink.estimates[i].x, paced_sink.estimates[i].x) << i;
  }
  ASSERT_EQ(fast_sink.commands.size(), paced_sink.commands.size());
  for (std::size_t i = 0; i < fast_sink.commands.size(); ++i) EXPECT_EQ(fast_sink.commands[i].u, paced_sink.commands[i].u);
  ASSERT_EQ(fast_sink.innovations.size(), paced_sink.innovations.size());
  for (std::size_t i = 0; i < fast_sink.innovations.size(); ++i) {
    EXPECT_EQ(fast_sink.innovations[i].decision, paced_sink.innovations[i].decision);
    if (std::isfinite(fast_sink.innovations[i].nis)) {
      EXPECT_EQ(fast_sink.innovations[i].nis, paced_sink.innovations[i].nis);
    }
  }
}

TEST(MobileCapture, FindsAnObjectBehindTheRobot) {
  MobileCaptureConfig cfg = shipped();
  cfg.robot_heading = -M_PI / 2;  // object starts behind: search (sweep + base turn) first
  cfg.max_time = 45.0;
  const MobileCaptureRun r = runMobileCapture(cfg, 3);
  EXPECT_TRUE(r.captured);
  EXPECT_GT(r.detections, 0);
}

TEST(MobileCapture, FindsTheTargetAgainAfterLosingItAndTheSinkSeesEveryGateDecision) {
  // Camera covered for 4 s mid-chase: the filter predicts, the head follows the prediction, then
  // the search sweeps; the object must be found again and still be captured. The track coasts
  // through the blackout and its first frames after it are tested against a stale prediction:
  // the telemetry sink's innovation records must count exactly the gate decisions the run
  // reports, each with the update's own NIS.
  namespace channel = mobile_capture::channel;
  using tracking::GateDecision;
  MobileCaptureConfig cfg = shipped();
  cfg.max_time = 60.0;
  cfg.blackout_start = 6.0;
  cfg.blackout_duration = 4.0;
  int seen_after = 0;
  bool swept = false;
  runtime::MemorySink sink;
  MobileCaptureHooks hooks;
  hooks.telemetry = &sink;
  hooks.on_frame = [&](const MobileCaptureFrame& f) {
    if (f.t >= 10.0 && f.detected) ++seen_after;
    if (f.t > 6.0 && f.t < 10.0 && f.mode == control::SearchMode::Sweeping) swept = true;
  };
  const MobileCaptureRun r = runMobileCapture(cfg, 7, &hooks);
  EXPECT_TRUE(swept);
  EXPECT_GE(r.longest_lost, 3.9);
  EXPECT_GT(seen_after, 10);
  EXPECT_TRUE(r.captured);

  EXPECT_GE(r.gate.starts, 1u);
  EXPECT_GT(r.gate.accepted, 50u);
  EXPECT_EQ(sink.count(GateDecision::Start, channel::kObject), r.gate.starts);
  EXPECT_EQ(sink.count(GateDecision::Accept, channel::kObject), r.gate.accepted);
  EXPECT_EQ(sink.count(GateDecision::Reject, channel::kObject), r.gate.rejected);
  EXPECT_EQ(sink.count(GateDecision::Restart, channel::kObject), r.gate.restarts);
  EXPECT_EQ(sink.innovationsOf(channel::kObject).size(), r.gate.total());
  for (const auto& i : sink.innovationsOf(channel::kObject)) {
    EXPECT_EQ(i.rows, 2);
    if (i.decision == GateDecision::Start) continue;
    ASSERT_EQ(i.innovation.size(), 2);
    EXPECT_NEAR(i.nis, i.innovation.dot(i.S.ldlt().solve(i.innovation)), 1e-9 * (1.0 + i.nis));
  }
  // One floor measurement per detection, one truth record per frame, a base command per tick.
  std::size_t floor = 0, truth = 0, base = 0;
  for (const auto& m : sink.measurements) floor += m.channel == channel::kFloor;
  for (const auto& e : sink.estimates) truth += e.channel == channel::kTruthObject;
  for (const auto& c : sink.commands) base += c.channel == channel::kBase;
  EXPECT_EQ(floor, static_cast<std::size_t>(r.detections));
  EXPECT_EQ(truth, static_cast<std::size_t>(r.frames));
  EXPECT_GE(base, 10u * (static_cast<std::size_t>(r.frames) - 1u));  // 100 Hz control, 10 Hz vision
}

TEST(MobileCapture, OracleIsDeterministicPerSeed) {
  const MobileCaptureConfig cfg = shipped();
  const OracleResult a = runOracle(cfg, 11), b = runOracle(cfg, 11);
  EXPECT_TRUE(a.captured);
  EXPECT_DOUBLE_EQ(a.time, b.time);
}

TEST(MobileCapture, KsFilterTestConverges) {
  // [K] §3.2: FilterTest profile, measurement variance 2 cm². After convergence the speed error is
  // a few cm/s and the heading (where observable) about 0.1 rad; the filtered position beats the
  // raw measurements.
  const FilterTestResult f = runFilterTest(shipped(), 5);
  EXPECT_LT(f.rmse_v, 0.04);
  EXPECT_LT(f.rmse_theta_moving, 0.25);
  EXPECT_LT(f.rmse_omega_nominal, 0.3);
  EXPECT_LT(f.rmse_position, f.rmse_measurement);
  ASSERT_FALSE(f.t.empty());
  EXPECT_EQ(f.t.size(), f.err_theta.size());
}

TEST(MobileCapture, FieldOfViewSweepRanksTheMethods) {
  MobileCaptureConfig cfg = shipped();
  cfg.fov_sweep_poses = 10;
  const FovSweepResult r = compareGroundLocalization(cfg, 1);
  ASSERT_GT(r.all.count, 1000);
  EXPECT_LT(r.all.sse_exact, r.all.sse_horizontal);
  EXPECT_LT(r.all.sse_exact, r.all.sse_printed);
  // The angle-per-pixel approximation is worse at the image border than at the centre.
  EXPECT_GT(r.border.sse_horizontal / r.border.count, r.centre.sse_horizontal / r.centre.count);
}

TEST(MobileCapture, ConfigErrorsNameTheKey) {
  const std::string base = "world:\n  max_time: 10\n";
  EXPECT_NO_THROW(loadMobileCaptureConfig(io::ConfigNode::fromString(base, "t.yaml")));
  try {
    loadMobileCaptureConfig(io::ConfigNode::fromString(base + "planner:\n  horizon: 5\n", "t.yaml"));
    FAIL() << "unknown key accepted";
  } catch (const core::InvalidInput& e) {
    EXPECT_NE(std::string(e.what()).find("planner.horizon"), std::string::npos) << e.what();
  }
  try {
    loadMobileCaptureConfig(io::ConfigNode::fromString("world:\n  max_time: -1\n", "t.yaml"));
    FAIL() << "negative time accepted";
  } catch (const core::InvalidInput& e) {
    EXPECT_NE(std::string(e.what()).find("world.max_time"), std::string::npos) << e.what();
  }
  EXPECT_THROW(loadMobileCaptureConfig(io::ConfigNode::fromString("timing:\n  vision_period: 0.015\n", "t.yaml")),
               core::InvalidInput);
  // The shared camera keys the head camera has no use for are refused, not ignored.
  try {
    loadMobileCaptureConfig(io::ConfigNode::fromString(base + "camera:\n  cx: 150\n", "t.yaml"));
    FAIL() << "camera.cx accepted";
  } catch (const core::InvalidInput& e) {
    EXPECT_NE(std::string(e.what()).find("camera.cx"), std::string::npos) << e.what();
  }
}

TEST(MobileCapture, ShippedConfigRendersWithTheTruthAndEstimatesWithTheCalibratedRig) {
  const MobileCaptureConfig cfg = shipped();
  ASSERT_TRUE(cfg.rig.has_value());
  // truth.yaml's camera is the DH head at tilt 30° (down), pan 0 (its own comment).
  EXPECT_NEAR(core::rad2deg(cfg.rig->q0.tilt), 30.0, 0.01);
  EXPECT_NEAR(core::rad2deg(cfg.rig->q0.pan), 0.0, 0.01);
  // Calibrated, hence imperfect, but close: a mount correction of millimetres and tenths of a degree.
  const double mm = 1000.0 * cfg.rig->cal_M_c.translation().norm();
  const double deg = core::rad2deg(core::rotationAngle(cfg.rig->cal_M_c.linear(), Eigen::Matrix3d::Identity()));
  EXPECT_GT(mm, 0.1);
  EXPECT_LT(mm, 10.0);
  EXPECT_GT(deg, 0.01);
  EXPECT_LT(deg, 1.0);
  EXPECT_NE(cfg.rig->truth.intrinsics.get_px(), cfg.rig->calibrated.intrinsics.get_px());
  EXPECT_NEAR(cfg.hfov, 2.0 * std::atan(160.0 / cfg.rig->calibrated.intrinsics.get_px()), 1e-12);
  // Inline camera geometry beside a rig is ambiguous: an error naming the key.
  try {
    loadMobileCaptureConfig(io::ConfigNode::fromString("rig: calib/rigs/mobile\ncamera:\n  hfov_deg: 50\n", "r.yaml"));
    FAIL() << "camera.hfov_deg accepted beside rig";
  } catch (const core::InvalidInput& e) {
    EXPECT_NE(std::string(e.what()).find("camera.hfov_deg"), std::string::npos) << e.what();
  }
  // A head whose DH chain cannot hold truth.yaml's camera is refused.
  try {
    loadMobileCaptureConfig(io::ConfigNode::fromString("rig: calib/rigs/mobile\nhead:\n  l1: 0.5\n", "h.yaml"));
    FAIL() << "rig accepted on a different head";
  } catch (const core::InvalidInput& e) {
    EXPECT_NE(std::string(e.what()).find("not the head's DH camera"), std::string::npos) << e.what();
  }
}

}  // namespace
}  // namespace viewline::scenarios
