// Ball catching on a recording of its throws (ball_catching/recording.h): a recorded session
// replayed with the same config and seed gives the same summary bit for bit (the wall-clock figures
// aside); footage at the top level is refused (it goes per camera: footage.h); a replay with another seed, or of
// a folder that is not a recording, is refused with a message.
#include <gtest/gtest.h>
#include <unistd.h>

#include <filesystem>
#include <fstream>
#include <string>

#include "viewline/core/error.h"
#include "viewline/io/config_edit.h"
#include "viewline/scenarios/ball_catching.h"
#include "viewline/scenarios/ball_catching/recording.h"
#include "scenario_test_util.h"

namespace fs = std::filesystem;
using namespace viewline;

using viewline::scenarios::test::errorOf;

namespace {

/// Only the wall-clock figures may differ between a run and its replay.
nlohmann::json withoutWallClock(nlohmann::json j) {
  j.erase("wall_time_s");
  j.erase("ms_per_frame_per_thread");
  return j;
}

fs::path tempDir(const std::string& name) {
  const fs::path dir = fs::path(testing::TempDir()) / (name + "_" + std::to_string(::getpid()));
  fs::remove_all(dir);
  return dir;
}

}  // namespace

// The registration before the throws renders its own frames and stays simulated in a replay (from
// the seed); it is off here, and the cameras at 25 Hz, to keep the test short.
const std::vector<std::string> kNoRegistration = {"registration.enabled=false", "rate_override_hz=25"};

TEST(BallCatchingSources, ReplayOfARecordingGivesTheSameSummaryBitForBit) {
  const auto cfg =
      scenarios::loadBallCatchingConfig(io::loadConfigWithValues("config/ball_catching.yaml", kNoRegistration));
  const fs::path dir = tempDir("viewline_bc_rec");
  scenarios::CatchHooks record;
  record.record_dir = dir.string();
  record.config_text = "name: ball_catching\n";
  const auto live = scenarios::runBallCatching(cfg, 2, 11, record);
  ASSERT_EQ(scenarios::recordedCatchThrows(dir.string()), 2);
  ASSERT_TRUE(fs::exists(dir / "throw_001" / "recording.csv"));
  ASSERT_TRUE(fs::exists(dir / "throw_000" / "throw.json"));
  ASSERT_TRUE(fs::exists(dir / "throw_000" / "camera1.xml"));  // the default rig's two cameras share one index
  ASSERT_GT(live.frames, 30);

  scenarios::CatchHooks replay;
  replay.replay_dir = dir.string();
  const auto again = scenarios::runBallCatching(cfg, 2, 11, replay);
  EXPECT_EQ(again.frames, live.frames);
  EXPECT_EQ(withoutWallClock(scenarios::summaryJson(again, cfg)).dump(),
            withoutWallClock(scenarios::summaryJson(live, cfg)).dump());

  // The same recording named by the config's source.
  const auto from_config = scenarios::loadBallCatchingConfig(
      io::loadConfigWithValues("config/ball_catching.yaml", {"registration.enabled=false", "rate_override_hz=25",
                                                               "source.kind=recording", "source.path=" + dir.string()}));
  const auto third = scenarios::runBallCatching(from_config, 1, 11);  // the first recorded throw only
  ASSERT_EQ(third.results.size(), 1u);
  EXPECT_EQ(third.results[0].frames, live.results.at(0).frames);
  EXPECT_EQ(third.results[0].hole_at_cross, live.results.at(0).hole_at_cross);
  EXPECT_EQ(third.results[0].miss_distance, live.results.at(0).miss_distance);

  // Another seed would draw other pixel noise and registration: refused, naming the recorded seed.
  EXPECT_NE(errorOf([&] { scenarios::runBallCatching(cfg, 2, 12, replay); }).find("replay with --seed 11"),
            std::string::npos);
  // A config with fewer cameras than the recording's.
  const auto one_camera = scenarios::loadBallCatchingConfig(io::loadConfigWithValues(
      "config/ball_catching.yaml", {"registration.enabled=false", "rate_override_hz=25", "camera_count=1"}));
  EXPECT_NE(errorOf([&] { scenarios::runBallCatching(one_camera, 2, 11, replay); }).find("frames of 2 cameras"),
            std::string::npos);
  // More throws than recorded.
  EXPECT_NE(errorOf([&] { scenarios::runBallCatching(cfg, 3, 11, replay); }).find("holds 2 throws"), std::string::npos);
  // A recording is never written over.
  EXPECT_NE(errorOf([&] { scenarios::runBallCatching(cfg, 1, 11, record); }).find("is not empty"), std::string::npos);
  fs::remove_all(dir);
}

TEST(BallCatchingSources, AFolderThatIsNotARecordingIsRefused) {
  const auto cfg = scenarios::loadBallCatchingConfig(io::loadConfigWithValues("config/ball_catching.yaml", {}));
  const fs::path dir = tempDir("viewline_bc_notrec");
  fs::create_directories(dir);
  scenarios::CatchHooks replay;
  replay.replay_dir = dir.string();
  EXPECT_NE(errorOf([&] { scenarios::runBallCatching(cfg, 1, 1, replay); }).find("not a ball_catching recording"),
            std::string::npos);
  fs::remove_all(dir);
}

TEST(BallCatchingSources, FootageAtTheTopLevelIsRefusedAndPointsToTheCameras) {
  const std::string e = errorOf([] {
    scenarios::loadBallCatchingConfig(
        io::loadConfigWithValues("config/ball_catching.yaml", {"source.kind=video", "source.path=x.mp4"}));
  });
  EXPECT_NE(e.find("source.kind video is not supported by ball_catching at the top level"), std::string::npos) << e;
  EXPECT_NE(e.find("cameras: [{name: right, source: {kind: video"), std::string::npos) << e;  // where footage goes
}

// The diagnosis switch: the estimators take the rig's true cameras, and only without the
// registration (which would move them).
TEST(BallCatchingConfig, TrueCamerasGiveTheEstimatorsTheRenderersCamerasAndRefuseTheRegistration) {
  const auto shipped = scenarios::loadBallCatchingConfig(io::loadConfigWithValues("config/ball_catching.yaml", {}));
  ASSERT_FALSE(shipped.true_cameras);
  // Calibrated: the estimator's pose differs from the renderer's (a calibration is never exact).
  EXPECT_GT((shipped.cameras[0].estimatorCamera().c_M_w.translation() -
             shipped.cameras[0].renderCamera().c_M_w.translation()).norm(), 1e-6);

  const auto truth = scenarios::loadBallCatchingConfig(
      io::loadConfigWithValues("config/ball_catching.yaml", {"true_cameras=true", "registration.enabled=false"}));
  for (const auto& k : truth.cameras) {
    EXPECT_TRUE(k.estimatorCamera().c_M_w.matrix() == k.renderCamera().c_M_w.matrix()) << k.name;
    EXPECT_EQ(k.estimatorCamera().intrinsics.get_px(), k.renderCamera().intrinsics.get_px()) << k.name;
  }
  const std::string e = errorOf([] {
    scenarios::loadBallCatchingConfig(io::loadConfigWithValues("config/ball_catching.yaml", {"true_cameras=true"}));
  });
  EXPECT_NE(e.find("registration.enabled: false as well"), std::string::npos) << e;
}
