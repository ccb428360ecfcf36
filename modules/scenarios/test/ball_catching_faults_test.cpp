// Injected faults in the ball-catching loop: every fault is counted as injected, the loop's
// defence counts what it did with it, the throws go on to their end, and the robot is never
// commanded outside its limits. Short sessions (2 throws, one thread) on the shipped config.
#include <gtest/gtest.h>

#include <map>
#include <string>
#include <vector>

#include "viewline/io/config_edit.h"
#include "viewline/scenarios/ball_catching.h"

using namespace viewline;
using runtime::FaultKind;
using runtime::FaultSpec;

namespace {

constexpr int kThrows = 2;
constexpr std::uint64_t kSeed = 11;

scenarios::BallCatchingConfig withFaults(std::vector<FaultSpec> faults, double deadline_s = 0.05) {
  auto cfg = scenarios::loadBallCatchingConfig(io::loadConfigWithValues("config/ball_catching.yaml", {}));
  cfg.threads = 1;
  cfg.faults.faults = std::move(faults);
  cfg.faults.frame_deadline_s = deadline_s;
  return cfg;
}

// The images of each throw, in order, as the live-view hook sees them.
struct Seen {
  std::map<int, std::vector<scenarios::CatchFrame>> frames;
  scenarios::CatchHooks hooks() {
    scenarios::CatchHooks h;
    h.on_frame = [this](const scenarios::CatchFrame& f) {
      scenarios::CatchFrame copy = f;
      copy.image = nullptr;  // valid during the call only
      frames[f.throw_index].push_back(copy);
      return true;
    };
    return h;
  }
};

}  // namespace

TEST(BallCatchingFaults, WithoutFaultsTheSummaryHasNoFaultsObject) {
  const auto cfg = withFaults({});
  const auto s = scenarios::runBallCatching(cfg, 1, kSeed);
  EXPECT_TRUE(s.faults.empty());
  EXPECT_FALSE(scenarios::summaryJson(s, cfg).contains("faults"));
}

TEST(BallCatchingFaults, BadDetectionsAreRejectedAThrowingDetectorIsSurvivedAndTheTrackComesBack) {
  // Camera 0 reports NaN centres, camera 1's detector throws, both over [0.20, 0.30) s of each throw.
  const auto cfg = withFaults({{FaultKind::DetectNan, 0, 0.20, 0.30}, {FaultKind::DetectorThrow, 1, 0.20, 0.30}});
  Seen seen;
  const auto s = scenarios::runBallCatching(cfg, kThrows, kSeed, seen.hooks());
  ASSERT_EQ(static_cast<int>(s.results.size()), kThrows);  // no throw ended by the exceptions
  const runtime::FaultReport& f = s.faults;
  EXPECT_GT(f.of(FaultKind::DetectNan), 0u);
  EXPECT_GT(f.of(FaultKind::DetectorThrow), 0u);
  EXPECT_EQ(f.outcomeOf("detections_rejected"), f.of(FaultKind::DetectNan));
  EXPECT_EQ(f.outcomeOf("detector_errors"), f.of(FaultKind::DetectorThrow));
  EXPECT_EQ(s.limit_violations, 0u);
  // After the window, each camera that saw the ball before it detects it again within 3 images,
  // and the tracker has an estimate then.
  for (const auto& [index, frames] : seen.frames) {
    for (std::size_t cam = 0; cam < 2; ++cam) {
      bool seen_before = false;
      int after = 0;
      bool back = false;
      for (const auto& fr : frames) {
        if (fr.camera != cam) continue;
        if (fr.t < 0.20) seen_before = seen_before || fr.detection.has_value();
        if (fr.t >= 0.20 && fr.t < 0.30) {
          EXPECT_FALSE(fr.detection.has_value()) << "throw " << index;
        }
        if (fr.t < 0.30 || after >= 3) continue;
        ++after;
        if (fr.detection && fr.estimate) back = true;
      }
      if (seen_before) {
        EXPECT_TRUE(back) << "throw " << index << " camera " << cam;
      }
    }
  }
}

TEST(BallCatchingFaults, FramesPastTheirDeadlineAreDroppedAndCounted) {
  // Camera 0's frames of the window arrive 80 ms late, past the 50 ms deadline.
  const auto cfg = withFaults({{FaultKind::Late, 0, 0.10, 0.20, 0.01, 0.08}});
  const auto s = scenarios::runBallCatching(cfg, kThrows, kSeed);
  const runtime::FaultReport& f = s.faults;
  EXPECT_GE(f.of(FaultKind::Late), static_cast<std::uint64_t>(4 * kThrows));  // 50 Hz: 5 frames in 0.1 s
  EXPECT_EQ(f.outcomeOf("frames_late_dropped"), f.of(FaultKind::Late));
  EXPECT_EQ(s.limit_violations, 0u);
}

TEST(BallCatchingFaults, ASilentRobotHoldsAndResumesOrHaltsNeverBeyondItsLimits) {
  // Windows between two control ticks (every 4 ms from 0), so the count is exact.
  const auto cfg = withFaults({{FaultKind::RobotSilent, std::nullopt, 0.202, 0.262}});
  const auto s = scenarios::runBallCatching(cfg, kThrows, kSeed);
  const runtime::FaultReport& f = s.faults;
  // 250 Hz set points: 15 commands of each throw fall in the 60 ms window.
  EXPECT_EQ(f.of(FaultKind::RobotSilent), static_cast<std::uint64_t>(15 * kThrows));
  EXPECT_EQ(f.outcomeOf("robot_commands_failed"), f.of(FaultKind::RobotSilent));
  EXPECT_EQ(f.outcomeOf("robot_resumed") + f.outcomeOf("robot_halts"), static_cast<std::uint64_t>(kThrows));
  EXPECT_EQ(s.limit_violations, 0u);
  EXPECT_EQ(s.refused_setpoints, 0u);
}

TEST(BallCatchingFaults, ALimitErrorHaltsOrHoldsAndFrozenOrRestampedImagesAreCounted) {
  const auto cfg = withFaults({{FaultKind::RobotLimitError, std::nullopt, 0.302, 0.322},
                               {FaultKind::Freeze, 1, 0.20, 0.30},
                               {FaultKind::StampRepeat, 0, 0.20, 0.24},
                               {FaultKind::Blackout, 0, 0.30, 0.40}});
  const auto s = scenarios::runBallCatching(cfg, kThrows, kSeed);
  const runtime::FaultReport& f = s.faults;
  EXPECT_EQ(f.of(FaultKind::RobotLimitError), static_cast<std::uint64_t>(5 * kThrows));
  EXPECT_EQ(f.outcomeOf("robot_commands_failed"), f.of(FaultKind::RobotLimitError));
  EXPECT_GT(f.of(FaultKind::Freeze), 0u);
  EXPECT_EQ(f.outcomeOf("frames_frozen_dropped"), f.of(FaultKind::Freeze));  // stale images, not fused
  EXPECT_GT(f.of(FaultKind::StampRepeat), 0u);
  // 50 Hz cameras: five images of camera 0 in the 0.1 s blackout of each throw, lost.
  EXPECT_GE(f.of(FaultKind::Blackout), static_cast<std::uint64_t>(4 * kThrows));
  EXPECT_LE(f.of(FaultKind::Blackout), static_cast<std::uint64_t>(6 * kThrows));
  // A repeated stamp on a camera whose previous image was fused is refused as a duplicate.
  EXPECT_LE(f.outcomeOf("tracker_refused_duplicate"), f.of(FaultKind::StampRepeat));
  EXPECT_EQ(s.limit_violations, 0u);
  const nlohmann::json j = scenarios::summaryJson(s, cfg);
  EXPECT_EQ(j["faults"]["injected"]["blackout"], f.of(FaultKind::Blackout));
}
