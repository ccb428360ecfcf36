// The dart experiments on recorded detections (dart/recording.h): the trackers rerun on a recording
// give the same summary bit for bit (the wall-clock figures aside); a replay with another seed, or of
// a recording whose draws do not fit the config, is refused.
#include <gtest/gtest.h>
#include <unistd.h>

#include <filesystem>
#include <string>

#include "viewline/core/error.h"
#include "viewline/scenarios/dart/loop.h"
#include "scenario_test_util.h"

namespace fs = std::filesystem;
using namespace viewline;

using viewline::scenarios::test::errorOf;

namespace {

/// Only the wall-clock figures may differ between a run and its replay.
nlohmann::json withoutWallClock(nlohmann::json j) {
  j.erase("runtime_s");
  j["async"].erase("update_time_us");
  return j;
}

}  // namespace

TEST(DartRecording, ReplayOfRecordedDetectionsGivesTheSameSummaryBitForBit) {
  const auto cfg = scenarios::loadDartScenario("config/dart_tracking.yaml");
  const fs::path dir = fs::path(testing::TempDir()) / ("viewline_dart_rec_" + std::to_string(::getpid()));
  fs::remove_all(dir);
  scenarios::DartRunCallbacks record;
  record.record_dir = dir.string();
  const auto live = scenarios::runDartExperiments(cfg, 3, 4, record);
  ASSERT_TRUE(fs::exists(dir / "run_003.json"));
  ASSERT_GT(live.measurements_per_flight, 10.0);

  scenarios::DartRunCallbacks replay;
  replay.replay_dir = dir.string();
  const auto again = scenarios::runDartExperiments(cfg, 3, 4, replay);
  EXPECT_EQ(withoutWallClock(scenarios::summaryToJson(again, cfg)).dump(),
            withoutWallClock(scenarios::summaryToJson(live, cfg)).dump());

  // The same recording named by the config's source.
  const auto from_config = scenarios::loadDartScenario("config/dart_tracking.yaml",
                                                       {"source.kind=recording", "source.path=" + dir.string()});
  EXPECT_EQ(withoutWallClock(scenarios::summaryToJson(scenarios::runDartExperiments(from_config, 3, 4), cfg)).dump(),
            withoutWallClock(scenarios::summaryToJson(live, cfg)).dump());

  EXPECT_NE(errorOf([&] { scenarios::runDartExperiments(cfg, 4, 4, replay); }).find("replay with --seed 3"),
            std::string::npos);
  EXPECT_NE(errorOf([&] { scenarios::runDartExperiments(cfg, 3, 5, replay); }).find("holds 4 runs"), std::string::npos);
  EXPECT_NE(errorOf([&] { scenarios::runDartExperiments(cfg, 3, 1, record); }).find("is not empty"), std::string::npos);
  fs::remove_all(dir);
}

TEST(DartRecording, FootageIsRefused) {
  const std::string e = errorOf([] {
    scenarios::loadDartScenario("config/dart_tracking.yaml", {"source.kind=video", "source.path=x.mp4"});
  });
  EXPECT_NE(e.find("source.kind video is not supported by dart_tracking"), std::string::npos) << e;
}
