// Short seeded closed-loop runs of the table-ball scenario (the long run is the app command).
#include <gtest/gtest.h>

#include <cmath>

#include "viewline/core/error.h"
#include "viewline/core/frames.h"
#include "viewline/io/config.h"
#include "viewline/scenarios/table_ball.h"

using namespace viewline;

namespace {
scenarios::TableBallConfig shortRun() {
  // The shipped scenario, shortened: settle at (-0.04, 0), an 8 cm step at 1.5 s, no push.
  scenarios::TableBallConfig c = scenarios::tableBallConfigFromYaml(io::ConfigNode::loadFile("config/table_ball.yaml"));
  c.duration = 5.0;
  c.initial_ball = Eigen::Vector2d(-0.04, 0.0);
  c.setpoints = {{0.0, Eigen::Vector2d(-0.04, 0.0)}, {1.5, Eigen::Vector2d(0.04, 0.0)}};
  c.pushes.clear();
  c.warmup = 0.5;
  c.time_reference = false;
  return c;
}
}  // namespace

TEST(TableBallScenario, ShortClosedLoopRunTracksAndSettles) {
  const scenarios::TableBallConfig cfg = shortRun();
  const scenarios::TableBallResult r = scenarios::runTableBall(cfg, 7);
  EXPECT_EQ(r.frames, 250);
  EXPECT_GE(r.ball_detections, 230);
  EXPECT_GE(r.table_detections, 230);
  EXPECT_TRUE(r.limits_respected);
  EXPECT_LE(r.max_commanded_angle_deg, core::rad2deg(cfg.wrist.max_angle) + 1e-9);
  // The observer beats the raw detections and stays within a few millimetres of the truth.
  EXPECT_LT(r.observer_rmse_mm, 3.0);
  EXPECT_LE(r.observer_rmse_mm, r.measurement_rmse_mm * 1.05);
  // Both of [M]'s tunings ran beside the loop on the same measurements.
  EXPECT_TRUE(std::isfinite(r.observer_rmse_mm_M_sw1_sv1));
  EXPECT_TRUE(std::isfinite(r.observer_rmse_mm_M_sw1_sv0005));
  ASSERT_EQ(r.steps.size(), 1u);
  EXPECT_LE(r.steps[0].overshoot_pct, 15.0);
  EXPECT_LE(r.steps[0].settling_time_s, 2.5);
  EXPECT_LE(r.steps[0].steady_state_error_mm, 3.0);
  const nlohmann::json j = scenarios::toJson(r);
  for (const char* key : {"observer_rmse_mm", "measurement_rmse_mm", "overshoot_pct", "settling_time_s",
                          "steady_state_error_mm", "push_recovery_s", "frame_time_ratio_to_reference"}) {
    EXPECT_TRUE(j.contains(key)) << key;
  }
}

TEST(TableBallScenario, SameSeedSameRun) {
  scenarios::TableBallConfig cfg = shortRun();
  cfg.duration = 1.0;
  cfg.compare_tunings = false;
  const auto a = scenarios::runTableBall(cfg, 3);
  const auto b = scenarios::runTableBall(cfg, 3);
  EXPECT_EQ(a.ball_detections, b.ball_detections);
  EXPECT_EQ(a.frames_dropped, b.frames_dropped);
  EXPECT_EQ(a.observer_rmse_mm, b.observer_rmse_mm);
  EXPECT_EQ(a.measurement_rmse_mm, b.measurement_rmse_mm);
}

TEST(TableBallScenario, ConfigErrorsNameTheKey) {
  const std::string base = "events: {setpoints: [{t: 0.0, xy: [0.0, 0.0]}]}\ntable: {}\nwrist: {}\ncamera: {}\n"
                           "observer: {}\ncontroller: {}\n";
  EXPECT_NO_THROW(scenarios::tableBallConfigFromYaml(io::ConfigNode::fromString(base, "ok.yaml")));
  try {
    scenarios::tableBallConfigFromYaml(io::ConfigNode::fromString(base + "metrics: {warmpu: 1.0}\n", "typo.yaml"));
    FAIL() << "unknown key accepted";
  } catch (const core::InvalidInput& e) {
    EXPECT_NE(std::string(e.what()).find("metrics.warmpu"), std::string::npos) << e.what();
  }
  try {
    scenarios::tableBallConfigFromYaml(io::ConfigNode::fromString(
        "events: {setpoints: [{t: 0.0, xy: [0.2, 0.0]}]}\ntable: {}\nwrist: {}\ncamera: {}\nobserver: {}\ncontroller: {}\n",
        "far.yaml"));
    FAIL() << "unreachable set point accepted";
  } catch (const core::InvalidInput& e) {
    EXPECT_NE(std::string(e.what()).find("events.setpoints[0].xy"), std::string::npos) << e.what();
  }
}

TEST(TableBallScenario, ShippedConfigRunsOnTheCalibratedRig) {
  const scenarios::TableBallConfig c = scenarios::tableBallConfigFromYaml(io::ConfigNode::loadFile("config/table_ball.yaml"));
  ASSERT_TRUE(c.rig.has_value());
  const core::Camera& truth = c.rig->truth;
  const core::Camera& cal = c.rig->calibrated;
  EXPECT_EQ(truth.width, 320u);
  EXPECT_EQ(c.width, 320u);
  EXPECT_DOUBLE_EQ(truth.intrinsics.get_px(), 160.0);  // [M]'s camera, 90° horizontal field of view
  // Calibrated, not copied: close to the truth, not equal.
  EXPECT_NE(cal.intrinsics.get_px(), truth.intrinsics.get_px());
  EXPECT_LT(std::abs(cal.intrinsics.get_px() / truth.intrinsics.get_px() - 1.0), 0.005);
  const double rot = core::rad2deg(core::rotationAngle(cal.c_M_w.linear(), truth.c_M_w.linear()));
  EXPECT_GT(rot, 0.001);
  EXPECT_LT(rot, 0.5);
  // Inline camera geometry beside a rig is ambiguous: an error naming the key.
  const std::string yaml = "rig: calib/rigs/table\nevents: {setpoints: [{t: 0.0, xy: [0.0, 0.0]}]}\ntable: {}\n"
                           "wrist: {}\ncamera: {hfov_deg: 90}\nobserver: {}\ncontroller: {}\n";
  try {
    scenarios::tableBallConfigFromYaml(io::ConfigNode::fromString(yaml, "rig.yaml"));
    FAIL() << "camera.hfov_deg accepted beside rig";
  } catch (const core::InvalidInput& e) {
    EXPECT_NE(std::string(e.what()).find("camera.hfov_deg"), std::string::npos) << e.what();
  }
}
