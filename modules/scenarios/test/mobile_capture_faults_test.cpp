// Injected faults in the mobile-capture loop: bad detections are refused, a throwing detector
// and late or lost frames are survived and counted, and the track takes the object up again
// after them. The first 7 s of a run (the view's quit ends it there, without the oracle).
#include <gtest/gtest.h>

#include <cmath>
#include <optional>
#include <vector>

#include "viewline/core/frames.h"
#include "viewline/io/config.h"
#include "viewline/scenarios/mobile_capture.h"

using namespace viewline;
using runtime::FaultKind;

TEST(MobileCaptureFaults, FaultsAreCountedRefusedOrSurvivedAndTheTrackTakesTheObjectUpAgain) {
  scenarios::MobileCaptureConfig cfg =
      scenarios::loadMobileCaptureConfig(io::ConfigNode::loadFile("config/mobile_capture.yaml"));
  cfg.rig.reset();  // one perfect camera (as the short capture test)
  cfg.hfov = core::deg2rad(50.0);
  cfg.vfov = core::deg2rad(40.0);
  cfg.faults.faults = {{FaultKind::StampRepeat, 0, 1.0, 1.1},
                       {FaultKind::DetectInf, 0, 2.0, 2.5},
                       {FaultKind::DetectOutside, 0, 2.5, 3.0},
                       {FaultKind::DetectorThrow, 0, 3.0, 3.5},
                       {FaultKind::Late, 0, 3.5, 4.0, 0.01, 0.3},
                       {FaultKind::Blackout, 0, 4.0, 5.0}};
  struct Seen {
    double t;
    bool detected, fused;
  };
  std::vector<Seen> seen;
  double last_t = 0.0;
  scenarios::MobileCaptureHooks hooks;
  hooks.on_frame = [&](const scenarios::MobileCaptureFrame& f) {
    seen.push_back({f.t, f.detected, f.fused});
    last_t = f.t;
  };
  hooks.quit_requested = [&] { return last_t > 7.0; };
  const scenarios::MobileCaptureRun r = scenarios::runMobileCapture(cfg, 7, &hooks);
  const runtime::FaultReport& f = r.faults;
  EXPECT_GT(f.of(FaultKind::DetectInf), 0u);
  EXPECT_GT(f.of(FaultKind::DetectOutside), 0u);
  EXPECT_EQ(f.outcomeOf("detections_rejected"), f.of(FaultKind::DetectInf) + f.of(FaultKind::DetectOutside));
  EXPECT_GT(f.of(FaultKind::DetectorThrow), 0u);
  EXPECT_EQ(f.outcomeOf("detector_errors"), f.of(FaultKind::DetectorThrow));
  EXPECT_GT(f.of(FaultKind::Late), 0u);
  EXPECT_EQ(f.outcomeOf("frames_late_dropped"), f.of(FaultKind::Late));  // 0.3 s late, deadline 0.05 s
  EXPECT_GT(f.of(FaultKind::Blackout), 0u);
  EXPECT_GT(f.of(FaultKind::StampRepeat), 0u);
  EXPECT_EQ(f.outcomeOf("frames_stale_stamp_dropped"), f.of(FaultKind::StampRepeat));  // the track only steps forward
  // Tracked before the faults, nothing detected during them, fused again within 5 frames after.
  int fused_before = 0, detected_during = 0, frames_after = 0, first_fused_after = -1;
  for (const Seen& s : seen) {
    if (s.t < 2.0) fused_before += s.fused;
    else if (s.t < 5.0) detected_during += s.detected;
    else if (first_fused_after < 0) {
      if (s.fused) first_fused_after = frames_after;
      ++frames_after;
    }
  }
  EXPECT_GT(fused_before, 5);
  EXPECT_EQ(detected_during, 0);
  EXPECT_GE(first_fused_after, 0);
  EXPECT_LT(first_fused_after, 5);
}

// Robot faults: a base that stops answering for 1 s keeps its last command until its watchdog
// (base.command_timeout, 0.5 s) brakes it to rest; a limit error stops it at once; both are
// counted per command, the loop resumes when the robot answers, and the track goes on.
TEST(MobileCaptureFaults, ASilentBaseBrakesOnItsWatchdogALimitErrorStopsItAndTheLoopResumes) {
  scenarios::MobileCaptureConfig cfg =
      scenarios::loadMobileCaptureConfig(io::ConfigNode::loadFile("config/mobile_capture.yaml"));
  cfg.rig.reset();
  cfg.hfov = core::deg2rad(50.0);
  cfg.vfov = core::deg2rad(40.0);
  ASSERT_DOUBLE_EQ(cfg.base.command_timeout, 0.5);
  const auto run = [&](const std::vector<runtime::FaultSpec>& faults, std::vector<scenarios::MobileCaptureFrame>& frames) {
    scenarios::MobileCaptureConfig c = cfg;
    c.faults.faults = faults;
    double last_t = 0.0;
    scenarios::MobileCaptureHooks hooks;
    hooks.on_frame = [&](const scenarios::MobileCaptureFrame& f) {
      scenarios::MobileCaptureFrame copy = f;
      copy.image = nullptr;  // not kept past the callback
      frames.push_back(copy);
      last_t = f.t;
    };
    hooks.quit_requested = [&] { return last_t > 7.0; };
    return scenarios::runMobileCapture(c, 7, &hooks);
  };
  std::vector<scenarios::MobileCaptureFrame> clean, faulty;
  run({}, clean);
  const scenarios::MobileCaptureRun r =
      run({{FaultKind::RobotSilent, std::nullopt, 2.0, 3.0}, {FaultKind::RobotLimitError, std::nullopt, 4.0, 4.1}}, faulty);
  const runtime::FaultReport& f = r.faults;
  EXPECT_EQ(f.of(FaultKind::RobotSilent), 100u);  // one command per 10 ms control period
  EXPECT_EQ(f.of(FaultKind::RobotLimitError), 10u);
  EXPECT_EQ(f.outcomeOf("robot_commands_failed"), 110u);
  EXPECT_EQ(f.outcomeOf("robot_halts"), 10u);
  EXPECT_EQ(f.outcomeOf("base_watchdog_stops"), 1u);
  EXPECT_EQ(f.outcomeOf("robot_resumed"), 2u);
  // Distance the base covered between the frames nearest t0 and t1.
  const auto moved = [](const std::vector<scenarios::MobileCaptureFrame>& fs, double t0, double t1) {
    const scenarios::MobileCaptureFrame *a = nullptr, *b = nullptr;
    for (const auto& fr : fs) {
      if (!a && fr.t >= t0 - 1e-9) a = &fr;
      if (!b && fr.t >= t1 - 1e-9) b = &fr;
    }
    if (!a || !b) return -1.0;
    return std::hypot(b->robot.x - a->robot.x, b->robot.y - a->robot.y);
  };
  // Until the watchdog the base rolls on (as in the clean run), then it is at rest.
  EXPECT_GT(moved(clean, 2.7, 3.0), 0.03);
  EXPECT_GT(moved(faulty, 2.0, 2.4), 0.5 * moved(clean, 2.0, 2.4));
  EXPECT_LT(moved(faulty, 2.8, 3.0), 0.003);
  // After the robot answers again the loop drives and tracks on.
  EXPECT_GT(moved(faulty, 5.0, 6.0), 0.1);
  int fused_after = 0;
  for (const auto& fr : faulty) fused_after += fr.t > 5.0 && fr.fused;
  EXPECT_GT(fused_after, 5);
}
