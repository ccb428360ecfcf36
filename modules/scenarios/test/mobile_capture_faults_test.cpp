// Injected faults in the mobile-capture loop: bad detections are refused, a throwing detector
// and late or lost frames are survived and counted, and the robot still captures the object.
#include <gtest/gtest.h>

#include "viewline/core/frames.h"
#include "viewline/io/config.h"
#include "viewline/scenarios/mobile_capture.h"

using namespace viewline;
using runtime::FaultKind;

TEST(MobileCaptureFaults, FaultsAreCountedRefusedOrSurvivedAndTheObjectIsStillCaptured) {
  scenarios::MobileCaptureConfig cfg =
      scenarios::loadMobileCaptureConfig(io::ConfigNode::loadFile("config/mobile_capture.yaml"));
  cfg.rig.reset();  // one perfect camera (as the short capture test)
  cfg.hfov = core::deg2rad(50.0);
  cfg.vfov = core::deg2rad(40.0);
  cfg.max_time = 45.0;
  const scenarios::MobileCaptureRun clean = scenarios::runMobileCapture(cfg, 7);
  ASSERT_TRUE(clean.captured);
  cfg.faults.faults = {{FaultKind::DetectInf, 0, 2.0, 2.5},
                       {FaultKind::DetectOutside, 0, 2.5, 3.0},
                       {FaultKind::DetectorThrow, 0, 3.0, 3.5},
                       {FaultKind::Late, 0, 3.5, 4.0, 0.01, 0.3},
                       {FaultKind::Blackout, 0, 4.0, 5.0}};
  const scenarios::MobileCaptureRun r = scenarios::runMobileCapture(cfg, 7);
  const runtime::FaultReport& f = r.faults;
  EXPECT_GT(f.of(FaultKind::DetectInf), 0u);
  EXPECT_EQ(f.outcomeOf("detections_rejected"), f.of(FaultKind::DetectInf) + f.of(FaultKind::DetectOutside));
  EXPECT_GT(f.of(FaultKind::DetectorThrow), 0u);
  EXPECT_EQ(f.outcomeOf("detector_errors"), f.of(FaultKind::DetectorThrow));
  EXPECT_GT(f.of(FaultKind::Late), 0u);
  EXPECT_EQ(f.outcomeOf("frames_late_dropped"), f.of(FaultKind::Late));  // 0.3 s late, deadline 0.05 s
  EXPECT_GT(f.of(FaultKind::Blackout), 0u);
  EXPECT_TRUE(r.captured);  // the track came back after 3 s of unusable or missing frames
  EXPECT_TRUE(clean.faults.empty());
}
