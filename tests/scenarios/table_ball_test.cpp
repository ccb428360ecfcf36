// Short seeded closed-loop runs of the table-ball scenario (the long run is the app command).
#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>
#include <string>

#include "viewline/core/error.h"
#include "viewline/core/frames.h"
#include "viewline/io/config.h"
#include "viewline/runtime/telemetry.h"
#include "viewline/scenarios/table_ball.h"

using namespace viewline;

namespace {
scenarios::TableBallConfig shortRun() {
  // The shipped scenario, shortened: start at (-0.04, 0), an 8 cm step at 1 s, no push.
  scenarios::TableBallConfig c = scenarios::tableBallConfigFromYaml(io::ConfigNode::loadFile("config/table_ball.yaml"));
  c.duration = 3.5;
  c.initial_ball = Eigen::Vector2d(-0.04, 0.0);
  c.setpoints = {{0.0, Eigen::Vector2d(-0.04, 0.0)}, {1.0, Eigen::Vector2d(0.04, 0.0)}};
  c.pushes.clear();
  c.warmup = 0.5;
  c.time_reference = false;
  c.validate();
  return c;
}

/// The summary without its wall-clock figure.
nlohmann::json seeded(const scenarios::TableBallResult& r) {
  nlohmann::json j = scenarios::toJson(r);
  j.erase("wall_seconds");
  return j;
}

/// The sink saw every update the observer's filter made, with its own NIS and gate decision:
/// the counts and the NIS mean match the summary.
void expectEveryUpdateReported(const runtime::MemorySink& sink, const scenarios::TableBallResult& r,
                               const scenarios::TableBallConfig& cfg) {
  const auto updates = sink.innovationsOf("ball");
  ASSERT_EQ(updates.size(), static_cast<std::size_t>(r.ball_detections));
  EXPECT_EQ(sink.count(tracking::GateDecision::Start, "ball"), 1u);
  EXPECT_EQ(sink.count(tracking::GateDecision::Accept, "ball"), updates.size() - 1);
  EXPECT_EQ(sink.count(tracking::GateDecision::Reject, "ball") + sink.count(tracking::GateDecision::Restart, "ball"), 0u);
  double nis_sum = 0.0;
  int nis_n = 0;
  for (const auto& u : updates) {
    EXPECT_EQ(u.rows, 2);
    if (u.decision != tracking::GateDecision::Accept) continue;
    ASSERT_EQ(u.innovation.size(), 2);
    ASSERT_EQ(u.S.rows(), 2);
    EXPECT_TRUE(std::isfinite(u.nis) && u.nis >= 0.0);
    if (u.t >= cfg.warmup) {
      nis_sum += u.nis;
      ++nis_n;
    }
  }
  ASSERT_GT(nis_n, 100);
  EXPECT_EQ(nis_sum / nis_n, r.nis_mean);
  std::size_t balls = 0, tilts = 0, inputs = 0, truths = 0;
  for (const auto& m : sink.measurements) {
    balls += m.channel == "ball";
    tilts += m.channel == "table_tilt";
    inputs += m.channel == "ball_acceleration";
  }
  for (const auto& e : sink.estimates) truths += e.channel == "truth";
  EXPECT_EQ(balls, static_cast<std::size_t>(r.ball_detections));
  EXPECT_EQ(tilts, static_cast<std::size_t>(r.table_detections));
  EXPECT_EQ(inputs, static_cast<std::size_t>(r.frames));
  EXPECT_EQ(truths, static_cast<std::size_t>(r.frames));
  EXPECT_FALSE(sink.commands.empty());
}

const std::string kMinimal = "events: {setpoints: [{t: 0.0, xy: [0.0, 0.0]}]}\ntable: {}\nwrist: {}\nobserver: {}\n"
                             "controller: {}\n";
}  // namespace

// The CI guard of the headline figures (docs/results.md "Table-ball balancing"), on a short
// seeded run of the shipped config: an 8 cm step. The bounds sit about 20 % above what this
// run gives (2-D settling 0.68 s, observer RMSE 0.097 mm = 0.30 of the raw measurement's,
// steady state 0.061 mm, sampled NIS 2.36 in its band of 30 samples), so a regression of the
// method fails here; the telemetry sink sees every update.
TEST(TableBallScenario, ShortClosedLoopRunGuardsTheHeadlineFigures) {
  const scenarios::TableBallConfig cfg = shortRun();
  runtime::MemorySink sink;
  scenarios::TableBallHooks hooks;
  hooks.telemetry = &sink;
  const scenarios::TableBallResult r = scenarios::runTableBall(cfg, 7, hooks);
  expectEveryUpdateReported(sink, r, cfg);
  EXPECT_EQ(r.frames, 175);
  EXPECT_GE(r.ball_detections, 160);
  EXPECT_GE(r.table_detections, 160);
  EXPECT_TRUE(r.limits_respected);
  EXPECT_LE(r.max_commanded_angle_deg, core::rad2deg(cfg.wrist.max_angle) + 1e-9);
  // The observer (table pose filter and ball filter) beats the raw detections on their own
  // frame's table pose; both stay well under a millimetre (the table-plane depth: the
  // known-radius model gave 1.9 mm).
  EXPECT_LT(r.observer_rmse_mm, 0.35 * r.measurement_rmse_mm);
  // [M]'s tunings ran beside the loop on the same measurements.
  EXPECT_TRUE(std::isfinite(r.observer_rmse_mm_M_sw1_sv1));
  EXPECT_TRUE(std::isfinite(r.observer_rmse_mm_M_sw1_sv0005));
  ASSERT_EQ(r.steps.size(), 1u);
  EXPECT_LE(r.steps[0].overshoot_pct, 10.0);
  EXPECT_LE(r.settling_time_2d_s, 0.80);
  EXPECT_LE(r.observer_rmse_mm, 0.115);
  EXPECT_LE(r.steady_state_error_mm, 0.075);
  // The shipped observer's NIS, sampled 0.1 s apart, inside its two-sided 99 % band.
  ASSERT_GE(r.nis_sampled.count(), 25u);
  EXPECT_TRUE(r.nis_sampled.consistent(0.99)) << r.nis_sampled.mean();
  const nlohmann::json j = scenarios::toJson(r);
  for (const char* key : {"observer_rmse_mm", "measurement_rmse_mm", "fused_measurement_rmse_mm", "overshoot_pct", "settling_time_s", "settling_time_2d_s",
                          "steady_state_error_mm", "push_recovery_s", "frame_time_ratio_to_reference", "nis_sampled",
                          "nees_position_velocity"}) {
    EXPECT_TRUE(j.contains(key)) << key;
  }
}

// The scheduler only decides when events run on the wall clock, never what runs or in which
// order: a run paced at 20x real time (and without a sink) equals the one as fast as possible
// (same seed), bit for bit.
TEST(TableBallScenario, PacedRunEqualsTheFastOne) {
  scenarios::TableBallConfig cfg = shortRun();
  cfg.duration = 1.0;
  cfg.compare_tunings = false;
  const auto fast = scenarios::runTableBall(cfg, 3);
  scenarios::TableBallHooks paced;
  paced.pacing = runtime::Pacing{20.0};
  const auto slow = scenarios::runTableBall(cfg, 3, paced);
  EXPECT_EQ(seeded(fast).dump(), seeded(slow).dump());
  EXPECT_GE(slow.wall_seconds, 0.9 * cfg.duration / 20.0);  // it was paced
}

// A run shorter than the warm-up scores no error: the summary says so instead of printing nan.
TEST(TableBallScenario, ShortRunSaysWhatWasNotScored) {
  scenarios::TableBallConfig cfg = shortRun();
  cfg.duration = 0.2;
  cfg.compare_tunings = false;
  const scenarios::TableBallResult r = scenarios::TableBallMetrics(cfg).result(2);  // nothing recorded
  EXPECT_TRUE(std::isnan(r.observer_rmse_mm));
  std::FILE* f = std::tmpfile();
  ASSERT_NE(f, nullptr);
  scenarios::printTableBallSummary(f, r, cfg);
  std::rewind(f);
  std::string text;
  char buf[512];
  while (std::fgets(buf, sizeof buf, f) != nullptr) text += buf;
  std::fclose(f);
  EXPECT_EQ(text.find("nan"), std::string::npos) << text;
  EXPECT_NE(text.find("not scored (run shorter than the warm-up"), std::string::npos) << text;
}

TEST(TableBallScenario, ConfigErrorsNameTheKey) {
  const std::string base = kMinimal + "camera: {}\n";
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

TEST(TableBallScenario, InlineCameraKeys) {
  // Defaults: [M]'s 320x240 camera with a 90° field of view.
  const auto d = scenarios::tableBallConfigFromYaml(io::ConfigNode::fromString(kMinimal + "camera: {}\n", "d.yaml"));
  EXPECT_EQ(d.width, 320u);
  EXPECT_EQ(d.hfov, core::deg2rad(90.0));
  EXPECT_FALSE(d.cx.has_value());
  const auto c = scenarios::tableBallConfigFromYaml(
      io::ConfigNode::fromString(kMinimal + "camera: {width: 400, cx: 210.5, hfov_deg: 80}\n", "c.yaml"));
  EXPECT_EQ(c.width, 400u);
  EXPECT_EQ(*c.cx, 210.5);
  EXPECT_DOUBLE_EQ(c.hfov, core::deg2rad(80.0));
  try {
    scenarios::tableBallConfigFromYaml(io::ConfigNode::fromString(kMinimal + "camera: {kud: 0.1}\n", "kud.yaml"));
    FAIL() << "distortion accepted for the inline camera";
  } catch (const core::InvalidInput& e) {
    EXPECT_NE(std::string(e.what()).find("camera.kud"), std::string::npos) << e.what();
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
