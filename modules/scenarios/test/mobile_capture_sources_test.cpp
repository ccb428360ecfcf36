// Mobile capture on a recording of its runs (mobile_capture/recording.h): a recorded batch replayed
// with the same config and seed gives the same summary bit for bit (the wall-clock time aside); a
// replay whose simulated object is not the recorded one is refused; footage kinds are read for the
// footage session (mobile_capture/footage.h).
#include <gtest/gtest.h>
#include <unistd.h>

#include <filesystem>
#include <string>

#include <nlohmann/json.hpp>

#include "viewline/core/error.h"
#include "viewline/io/config_edit.h"
#include "viewline/scenarios/mobile_capture.h"
#include "viewline/scenarios/mobile_capture/footage.h"
#include "scenario_test_util.h"

namespace fs = std::filesystem;
using namespace viewline;

using viewline::scenarios::test::errorOf;

namespace {

/// Only the wall-clock time may differ between a run and its replay.
nlohmann::json withoutWallClock(const std::string& text) {
  nlohmann::json j = nlohmann::json::parse(text);
  j.erase("wall_time_s");
  return j;
}

// A short batch: a few simulated seconds per run, and the summary's filter test and sweep small.
const std::vector<std::string> kShort = {"world.max_time=8", "filter_test.runs=1", "filter_test.duration=20",
                                         "fov_sweep.poses=5"};

}  // namespace

TEST(MobileCaptureSources, ReplayOfARecordingGivesTheSameSummaryBitForBit) {
  const auto cfg = scenarios::loadMobileCaptureConfig(io::loadConfigWithValues("config/mobile_capture.yaml", kShort));
  const fs::path dir = fs::path(testing::TempDir()) / ("viewline_mc_rec_" + std::to_string(::getpid()));
  fs::remove_all(dir);
  scenarios::MobileCaptureSessionIo record;
  record.record_dir = dir.string();
  const auto live = scenarios::runMobileCaptureBatch(cfg, 2, 7, nullptr, record);
  ASSERT_EQ(scenarios::recordedMobileCaptureRuns(dir.string()), 2);
  ASSERT_TRUE(fs::exists(dir / "run_001" / "recording.csv"));
  ASSERT_TRUE(fs::exists(dir / "run_000" / "camera0.xml"));
  ASSERT_GT(live.runs.at(0).frames, 20);

  scenarios::MobileCaptureSessionIo replay;
  replay.replay_dir = dir.string();
  const auto again = scenarios::runMobileCaptureBatch(cfg, 2, 7, nullptr, replay);
  EXPECT_EQ(withoutWallClock(scenarios::summaryJson(again, cfg)).dump(),
            withoutWallClock(scenarios::summaryJson(live, cfg)).dump());

  // The object's path is simulated from the seed in a replay: another object start is refused at the first frame.
  auto moved = scenarios::loadMobileCaptureConfig(
      io::loadConfigWithValues("config/mobile_capture.yaml", {"world.max_time=8", "world.object_start=[-2.0, 3.0]"}));
  EXPECT_NE(errorOf([&] { scenarios::runMobileCaptureBatch(moved, 1, 7, nullptr, replay); })
                .find("the recorded object is not on the path"),
            std::string::npos);
  EXPECT_NE(errorOf([&] { scenarios::runMobileCaptureBatch(cfg, 1, 8, nullptr, replay); }).find("replay with --seed 7"),
            std::string::npos);
  fs::remove_all(dir);
}

TEST(MobileCaptureSources, FootageSourcesAreReadForTheFootageSession) {
  // images, video and v4l2 run one session on footage (mobile_capture/footage.h), not the batch.
  const auto cfg = scenarios::loadMobileCaptureConfig(
      io::loadConfigWithValues("config/mobile_capture.yaml", {"source.kind=images", "source.pattern=x%04d.png"}));
  EXPECT_EQ(cfg.source.kind, runtime::SourceKind::Images);
  EXPECT_TRUE(scenarios::mobileCaptureOnFootage(cfg));
  EXPECT_NE(errorOf([] {
              scenarios::loadMobileCaptureConfig(
                  io::loadConfigWithValues("config/mobile_capture.yaml", {"source.kind=film"}));
            }).find("source.kind"),
            std::string::npos);
}
