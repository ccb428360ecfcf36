// Short seeded runs of the mobile-capture scenario's library code (issue 8). The long runs are
// the app command reported in docs/results.md.
#include <gtest/gtest.h>

#include <cmath>

#include "viewline/core/error.h"
#include "viewline/io/config.h"
#include "viewline/scenarios/mobile_capture.h"

namespace viewline::scenarios {
namespace {

MobileCaptureConfig shipped() {
  // ctest runs from the project root (viewline_add_test WORKING_DIRECTORY).
  return loadMobileCaptureConfig(io::ConfigNode::loadFile("config/mobile_capture.yaml"));
}

TEST(MobileCapture, ShortSeededCaptureFromKsStart) {
  MobileCaptureConfig cfg = shipped();
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
  EXPECT_LT(exact, 0.04);
  EXPECT_LT(exact, printed);
}

TEST(MobileCapture, FindsAnObjectBehindTheRobot) {
  MobileCaptureConfig cfg = shipped();
  cfg.robot_heading = -M_PI / 2;  // object starts behind: search (sweep + base turn) first
  cfg.max_time = 45.0;
  const MobileCaptureRun r = runMobileCapture(cfg, 3);
  EXPECT_TRUE(r.captured);
  EXPECT_GT(r.detections, 0);
}

TEST(MobileCapture, FindsTheTargetAgainAfterLosingIt) {
  // Camera covered for 4 s mid-chase: the filter predicts, the head follows the prediction, then
  // the search sweeps; the object must be found again and still be captured.
  MobileCaptureConfig cfg = shipped();
  cfg.max_time = 60.0;
  cfg.blackout_start = 6.0;
  cfg.blackout_duration = 4.0;
  int seen_after = 0;
  bool swept = false;
  MobileCaptureHooks hooks;
  hooks.on_frame = [&](const MobileCaptureFrame& f) {
    if (f.t >= 10.0 && f.detected) ++seen_after;
    if (f.t > 6.0 && f.t < 10.0 && f.mode == control::SearchMode::Sweeping) swept = true;
  };
  const MobileCaptureRun r = runMobileCapture(cfg, 7, &hooks);
  EXPECT_TRUE(swept);
  EXPECT_GE(r.longest_lost, 3.9);
  EXPECT_GT(seen_after, 10);
  EXPECT_TRUE(r.captured);
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
}

}  // namespace
}  // namespace viewline::scenarios
