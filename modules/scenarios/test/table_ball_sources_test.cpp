// The table-ball loop on a recording of its head camera: the replay of a recorded run gives the
// same result bit for bit, lost frames included; footage (no table truth) is refused by the scored loop.
#include <gtest/gtest.h>
#include <unistd.h>

#include <filesystem>
#include <string>

#include "viewline/core/error.h"
#include "viewline/io/config_edit.h"
#include "viewline/scenarios/table_ball.h"

namespace fs = std::filesystem;
using namespace viewline;

namespace {

/// Only the wall-clock figures (processing times and their ratio) may differ between a run and its replay.
nlohmann::json withoutWallClock(nlohmann::json j) {
  for (auto it = j.begin(); it != j.end();) {
    const std::string& k = it.key();
    const bool ms = k.size() > 3 && k.compare(k.size() - 3, 3, "_ms") == 0;  // observer_frame_ms, reference_frame_ms
    if (ms || k.find("wall") != std::string::npos || k.find("ratio_to_reference") != std::string::npos)
      it = j.erase(it);
    else
      ++it;
  }
  return j;
}

}  // namespace

TEST(TableBallSources, ReplayOfARecordingGivesTheSameResultBitForBit) {
  auto cfg = scenarios::tableBallConfigFromYaml(io::loadConfigWithValues("config/table_ball.yaml", {}));
  cfg.duration = 1.2;
  const fs::path dir = fs::path(testing::TempDir()) / ("viewline_tb_" + std::to_string(::getpid()));
  fs::remove_all(dir);
  scenarios::TableBallHooks record;
  record.record_dir = dir.string();
  const auto live = scenarios::runTableBall(cfg, 5, record);
  ASSERT_TRUE(fs::exists(dir / "recording.csv"));
  ASSERT_GT(live.frames, 40);

  scenarios::TableBallHooks replay;
  replay.replay_dir = dir.string();
  const auto again = scenarios::runTableBall(cfg, 5, replay);
  EXPECT_EQ(again.frames, live.frames);
  EXPECT_EQ(withoutWallClock(scenarios::toJson(again)).dump(), withoutWallClock(scenarios::toJson(live)).dump());
  fs::remove_all(dir);
}

TEST(TableBallSources, TheScoredLoopRefusesFootage) {
  // Footage has no table truth to score against: it runs as one session (table_ball_footage_test.cpp).
  const auto cfg = scenarios::tableBallConfigFromYaml(
      io::loadConfigWithValues("config/table_ball.yaml", {"source.kind=video", "source.path=x.mp4"}));
  EXPECT_TRUE(cfg.onFootage());
  try {
    scenarios::runTableBall(cfg, 1);
    FAIL() << "the scored loop ran on a video source";
  } catch (const core::InvalidInput& e) {
    EXPECT_NE(std::string(e.what()).find("source.kind video: footage runs as one session"), std::string::npos) << e.what();
  }
}
