// Injected faults in the mobile-capture loop: bad detections are refused, a throwing detector
// and late or lost frames are survived and counted, and the track takes the object up again
// after them. The first 7 s of a run (the view's quit ends it there, without the oracle).
#include <gtest/gtest.h>

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
