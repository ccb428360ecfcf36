// Injected faults in the table-ball loop: a frame the observer cannot use (lost, late, frozen, or
// its detector threw) is predicted through, counted, and the wrist stays within its limits; a wrist
// that does not take commands (silent, limit error) holds its tilt, the loop plans from it and
// resumes within the limits. Short runs of the shipped scenario (1.5 s; 3.5 s with two pushes).
#include <gtest/gtest.h>

#include <algorithm>
#include <optional>
#include <vector>

#include "viewline/core/frames.h"
#include "viewline/io/config_edit.h"
#include "viewline/scenarios/table_ball.h"
#include "viewline/scenarios/table_ball/wrist_link.h"

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

// The wrist link on its own (no rendering): a wrist that stops answering holds its last accepted
// set point while the caller's commands fail, and when it answers again a command far from that
// set point is ramped to at the wrist's rate limit, never stepped to.
TEST(TableBallFaults, WristLinkHoldsTheLastAcceptedSetPointAndRampsBackWithinTheLimits) {
  robots::TableTiltLimits lim;  // 0.35 rad, 1.5 rad/s, 20 ms delay
  robots::SimulatedTableTilt wrist(lim);
  runtime::FaultConfig fc;
  fc.faults = {{FaultKind::RobotSilent, std::nullopt, 0.1005, 0.2005}, {FaultKind::RobotLimitError, std::nullopt, 0.3005, 0.3505}};
  runtime::FaultPlan plan(fc, 1);
  scenarios::WristLink link(wrist, plan);
  const double dt = 1e-3, rate = 1.0;  // the caller ramps θy at 1 rad/s throughout, outages or not
  Eigen::Vector2d prev = Eigen::Vector2d::Zero();
  double worst_rate = 0.0;
  for (int k = 0; k <= 600; ++k) {
    const double t = k * dt;
    const Eigen::Vector2d asked(0.0, std::min(rate * t, 0.3));
    const bool taken = link.send(t, asked);
    const bool in_window = (t >= 0.1005 && t < 0.2005) || (t >= 0.3005 && t < 0.3505);
    EXPECT_EQ(taken, !in_window) << "t " << t;
    if (taken) {
      EXPECT_EQ(link.held(), link.lastCommand());
      worst_rate = std::max(worst_rate, (link.lastCommand() - prev).cwiseAbs().maxCoeff() / dt);
      EXPECT_TRUE(lim.withinAngle(link.lastCommand()));
      prev = link.lastCommand();
    } else {
      EXPECT_EQ(link.held(), prev);  // the wrist holds what it last accepted
      EXPECT_TRUE(link.down());
    }
    // While silent the wrist comes to rest on that set point (after its delay) and stays there.
    if (t > 0.13 && t < 0.2) {
      EXPECT_NEAR(wrist.actual(t).y(), link.held().y(), 1e-9) << "t " << t;
    }
  }
  EXPECT_LE(worst_rate, lim.max_rate * (1.0 + 1e-9));
  EXPECT_GT(worst_rate, 0.99 * lim.max_rate);  // the resumes did ramp at the limit, not at the caller's 1 rad/s
  EXPECT_NEAR(link.held().y(), 0.3, 1e-12);     // and caught up with the caller
  const runtime::FaultReport f = plan.report();
  EXPECT_EQ(f.of(FaultKind::RobotSilent), 100u);
  EXPECT_EQ(f.of(FaultKind::RobotLimitError), 50u);
  EXPECT_EQ(f.outcomeOf("robot_commands_failed"), 150u);
  EXPECT_EQ(f.outcomeOf("robot_halts"), 50u);
  EXPECT_EQ(f.outcomeOf("robot_resumed"), 2u);
  // 0.1 rad behind after the silence: ramped at 1.5 rad/s for the 100 ticks to 0.3 s (the caller
  // stops at 0.3 rad there), 0.05 rad behind; still 0.05 rad after the limit error: 34 more.
  EXPECT_NEAR(static_cast<double>(f.outcomeOf("robot_commands_ramped")), 100.0 + 34.0, 1.0);
}

// The loop with the wrist silent for 0.2 s just after a push (the ball rolling at 0.25 m/s) and
// refusing commands with a limit error for 0.1 s after a second one: each failed command is
// counted, the controller plans from the tilt the wrist holds (the loop never asks for a step, so
// no command needs ramping), the wrist stays within its limits, the ball stays off the borders
// and is back within 5 mm of its set point in a bounded time after each window (without the
// faults it recovers from these pushes in 0.64 s and 0.61 s), and the run goes to its end.
// The side filters and the reference timing are off: the wrist, not the observer, is under test.
TEST(TableBallFaults, AWristThatStopsAnsweringHoldsItsTiltAndTheLoopResumesWithinTheLimits) {
  auto cfg = shortRun({{FaultKind::RobotSilent, std::nullopt, 1.0505, 1.2505},
                       {FaultKind::RobotLimitError, std::nullopt, 2.5505, 2.6505}});
  cfg.duration = 3.5;
  cfg.pushes = {{1.0, Eigen::Vector2d(0.0, 0.25)}, {2.5, Eigen::Vector2d(-0.2, 0.0)}};
  cfg.compare_tunings = false;
  cfg.time_reference = false;
  cfg.validate();
  const auto r = scenarios::runTableBall(cfg, 7);
  const runtime::FaultReport& f = r.faults;
  EXPECT_EQ(f.of(FaultKind::RobotSilent), 200u);  // one command per 1 ms physics tick
  EXPECT_EQ(f.of(FaultKind::RobotLimitError), 100u);
  EXPECT_EQ(f.outcomeOf("robot_commands_failed"), 300u);
  EXPECT_EQ(f.outcomeOf("robot_halts"), 100u);
  EXPECT_EQ(f.outcomeOf("robot_resumed"), 2u);
  EXPECT_EQ(f.outcomeOf("robot_commands_ramped"), 0u);
  EXPECT_TRUE(r.limits_respected);  // every command, in the windows and after them
  EXPECT_LE(r.max_commanded_rate_deg_s, core::rad2deg(cfg.wrist.max_rate) * (1.0 + 1e-9));
  EXPECT_EQ(r.frames, 175);  // 3.5 s at 50 Hz: to its end
  EXPECT_FALSE(r.stopped_early);
  ASSERT_EQ(r.robot_faults.size(), 2u);
  const scenarios::RobotFaultMetrics& silent = r.robot_faults[0];
  const scenarios::RobotFaultMetrics& refused = r.robot_faults[1];
  EXPECT_EQ(silent.kind, "robot_silent");
  EXPECT_EQ(refused.kind, "robot_limit_error");
  EXPECT_FALSE(silent.border_contact);  // 125 mm from the set point along y
  EXPECT_FALSE(refused.border_contact);
  EXPECT_LT(silent.peak_excursion_mm, 100.0);
  EXPECT_LT(silent.resettle_s, 1.2);
  EXPECT_LT(refused.peak_excursion_mm, 60.0);
  EXPECT_LT(refused.resettle_s, 0.8);
  EXPECT_EQ(scenarios::toJson(r)["faults"]["outcome"]["robot_resumed"], 2u);
  EXPECT_EQ(scenarios::toJson(r)["robot_faults"].size(), 2u);
}
