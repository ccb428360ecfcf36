// Injected faults in the table-ball loop: a frame the observer cannot use (lost, late, frozen, or
// its detector threw) is predicted through, counted, and the wrist stays within its limits. Short run
// (1.5 s of the shipped scenario).
#include <gtest/gtest.h>

#include <vector>

#include "viewline/io/config_edit.h"
#include "viewline/scenarios/table_ball.h"

using namespace viewline;
using runtime::FaultKind;

namespace {

scenarios::TableBallConfig shortRun(std::vector<runtime::FaultSpec> faults) {
  auto cfg = scenarios::tableBallConfigFromYaml(io::loadConfigWithValues("config/table_ball.yaml", {}));
  cfg.duration = 1.5;
  cfg.faults.faults = std::move(faults);
  return cfg;
}

}  // namespace

TEST(TableBallFaults, UnusableFramesArePredictedThroughCountedAndTheWristStaysWithinItsLimits) {
  // 50 Hz head camera (trigger jitter): four or five frames in each 0.1 s window.
  const auto cfg = shortRun({{FaultKind::Blackout, 0, 0.405, 0.505},
                             {FaultKind::DetectorThrow, 0, 0.605, 0.705},
                             {FaultKind::Late, 0, 0.805, 0.905, 0.01, 0.1},
                             {FaultKind::Freeze, 0, 1.005, 1.105},
                             {FaultKind::StampRepeat, 0, 1.205, 1.225}});
  const auto clean = scenarios::runTableBall(shortRun({}), 5);
  const auto r = scenarios::runTableBall(cfg, 5);
  const runtime::FaultReport& f = r.faults;
  for (const FaultKind k : {FaultKind::Blackout, FaultKind::DetectorThrow, FaultKind::Late, FaultKind::Freeze}) {
    EXPECT_GE(f.of(k), 4u) << runtime::toString(k);
    EXPECT_LE(f.of(k), 5u) << runtime::toString(k);
  }
  EXPECT_EQ(f.outcomeOf("detector_errors"), f.of(FaultKind::DetectorThrow));
  EXPECT_EQ(f.outcomeOf("frames_late_dropped"), f.of(FaultKind::Late));  // 0.1 s late, the deadline is 0.05 s
  EXPECT_EQ(f.of(FaultKind::StampRepeat), 1u);
  EXPECT_EQ(f.outcomeOf("frames_stale_stamp_dropped"), 1u);  // the filters only step forward
  EXPECT_EQ(r.frames, clean.frames - 1);  // the repeated stamp's frame is not scored
  // Lost, thrown and late frames: the observer predicts through them.
  // A frozen image repeats its camera's previous one bit for bit: dropped as stale.
  EXPECT_EQ(f.outcomeOf("frames_frozen_dropped"), f.of(FaultKind::Freeze));
  EXPECT_EQ(static_cast<std::uint64_t>(r.frames_dropped - clean.frames_dropped),
            f.of(FaultKind::Blackout) + f.of(FaultKind::DetectorThrow) + f.of(FaultKind::Late) + f.of(FaultKind::Freeze));
  EXPECT_TRUE(r.limits_respected);
  EXPECT_TRUE(clean.faults.empty());
  EXPECT_FALSE(scenarios::toJson(clean).contains("faults"));
  EXPECT_EQ(scenarios::toJson(r)["faults"]["injected"]["late"], f.of(FaultKind::Late));
}
