// Injected faults in the pan-tilt loop: the detections it cannot use are refused, a throwing
// detector is survived, a unit that stops answering keeps its last command and one that reports
// a limit error is halted, and no command ever leaves the unit's limits. Short runs (0.9 s, ours).
#include <gtest/gtest.h>

#include <string>
#include <vector>

#include "viewline/io/config_edit.h"
#include "viewline/scenarios/pan_tilt/loop.h"

using namespace viewline;
using runtime::FaultKind;

namespace {

scenarios::PanTiltScenarioConfig shortRun(std::vector<runtime::FaultSpec> faults) {
  auto cfg = scenarios::loadPanTiltScenarioConfig(io::loadConfigWithValues(
      "config/pan_tilt_circle.yaml", {"run.duration=0.9", "run.metrics_start=0.2", "run.baseline=false"}));
  cfg.faults.faults = std::move(faults);
  return cfg;
}

void expectWithinLimits(const scenarios::PanTiltRunMetrics& m) {
  EXPECT_EQ(m.unsafe_commands, 0u);
  EXPECT_EQ(m.rate_violations, 0u);
  EXPECT_EQ(m.limit_hits, 0u);
}

}  // namespace

TEST(PanTiltFaults, BadDetectionsAreRefusedAndAThrowingDetectorIsSurvived) {
  const auto cfg = shortRun({{FaultKind::DetectNan, 0, 0.21, 0.31},
                             {FaultKind::DetectOutside, 0, 0.31, 0.41},
                             {FaultKind::DetectorThrow, 0, 0.41, 0.51}});
  const auto clean = scenarios::runPanTiltComparison(shortRun({}), 3).ours;
  const auto r = scenarios::runPanTiltComparison(cfg, 3).ours;
  const runtime::FaultReport& f = r.faults;
  EXPECT_EQ(r.frames, clean.frames);  // the run went to its end
  EXPECT_EQ(f.of(FaultKind::DetectNan), 3u);  // 30 fps: three frames in each 0.1 s window
  EXPECT_EQ(f.of(FaultKind::DetectOutside), 3u);
  EXPECT_EQ(f.of(FaultKind::DetectorThrow), 3u);
  EXPECT_EQ(f.outcomeOf("detections_rejected"), 6u);
  EXPECT_EQ(f.outcomeOf("detector_errors"), 3u);
  EXPECT_EQ(r.detections, clean.detections - 9);
  EXPECT_TRUE(std::isfinite(r.image_error_rms_px));
  expectWithinLimits(r);
  EXPECT_TRUE(clean.faults.empty());
  EXPECT_FALSE(clean.toJson().contains("faults"));
}

TEST(PanTiltFaults, ASilentUnitKeepsItsLastCommandALimitErrorHaltsItAndNeitherLeavesTheLimits) {
  const auto cfg = shortRun({{FaultKind::RobotSilent, std::nullopt, 0.26, 0.36},
                             {FaultKind::RobotLimitError, std::nullopt, 0.51, 0.61}});
  const auto r = scenarios::runPanTiltComparison(cfg, 3).ours;
  const runtime::FaultReport& f = r.faults;
  EXPECT_EQ(f.of(FaultKind::RobotSilent), 3u);  // one command per frame, 30 fps
  EXPECT_EQ(f.of(FaultKind::RobotLimitError), 3u);
  EXPECT_EQ(f.outcomeOf("robot_commands_failed"), 6u);
  EXPECT_EQ(f.outcomeOf("robot_halts"), 3u);
  expectWithinLimits(r);
  const nlohmann::json j = r.toJson();
  EXPECT_EQ(j["faults"]["outcome"]["robot_halts"], 3);
}

TEST(PanTiltFaults, LostLateAndFrozenFramesAreCountedAndTheTrackGoesOn) {
  const auto cfg = shortRun({{FaultKind::Blackout, 0, 0.21, 0.31},
                             {FaultKind::Late, 0, 0.41, 0.51, 0.01, 0.2},
                             {FaultKind::Freeze, 0, 0.61, 0.71},
                             {FaultKind::StampBackwards, 0, 0.76, 0.81, 0.01}});
  const auto clean = scenarios::runPanTiltComparison(shortRun({}), 3).ours;
  const auto r = scenarios::runPanTiltComparison(cfg, 3).ours;
  const runtime::FaultReport& f = r.faults;
  EXPECT_EQ(f.of(FaultKind::Blackout), 3u);
  EXPECT_EQ(f.of(FaultKind::Late), 3u);
  EXPECT_EQ(f.outcomeOf("frames_late_dropped"), 3u);  // 0.2 s late, the deadline is 0.05 s
  EXPECT_EQ(f.of(FaultKind::Freeze), 3u);
  EXPECT_EQ(f.outcomeOf("frames_frozen_dropped"), 3u);  // each repeats the previous image bit for bit
  EXPECT_GE(f.of(FaultKind::StampBackwards), 1u);
  EXPECT_EQ(r.frames, clean.frames - 9);  // the lost, late and frozen frames are not processed
  // After the last window the filter still accepts the detections (no stuck gate).
  EXPECT_GT(r.detections, clean.detections - 12);
  expectWithinLimits(r);
}
