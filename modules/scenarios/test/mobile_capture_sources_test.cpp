// Mobile capture on a recording of its runs (mobile_capture/recording.h): a recorded batch replayed
// with the same config and seed gives the same summary bit for bit (the wall-clock time aside); a
// replay whose simulated object is not the recorded one is refused; a recorded run's frames, placed
// with its head readings (head.csv) and no robot, give the live run's measurements bit for bit;
// footage kinds are read for the footage session (mobile_capture/footage.h).
#include <gtest/gtest.h>
#include <unistd.h>

#include <filesystem>
#include <fstream>
#include <string>
#include <vector>

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

TEST(MobileCaptureSources, ARecordedRunGivesTheLiveMeasurementsWithoutTheRobot) {
  const auto cfg = scenarios::loadMobileCaptureConfig(io::loadConfigWithValues("config/mobile_capture.yaml", kShort));
  const fs::path dir = fs::path(testing::TempDir()) / ("viewline_mc_head_" + std::to_string(::getpid()));
  fs::remove_all(dir);
  std::vector<scenarios::RecordedFloorMeasurement> live;
  scenarios::MobileCaptureHooks hooks;
  hooks.record_dir = dir.string();
  hooks.on_frame = [&](const scenarios::MobileCaptureFrame& f) {
    if (f.measurement) live.push_back({f.t, 0, *f.measurement});
  };
  const auto run = scenarios::runMobileCapture(cfg, 5, &hooks);
  ASSERT_GT(live.size(), 40u);

  // No robot, simulator or truth: the frames through the loop's detector, placed at head.csv's readings.
  ASSERT_TRUE(fs::remove(dir / "truth.csv"));
  const scenarios::RecordedMobileCaptureRun replayed =
      scenarios::mobileCaptureRecordedMeasurements(cfg, dir.string(), 1);
  EXPECT_EQ(replayed.frames, static_cast<std::size_t>(run.frames));
  ASSERT_EQ(replayed.measurements.size(), live.size());
  for (std::size_t k = 0; k < live.size(); ++k) {
    const auto& r = replayed.measurements[k];
    EXPECT_EQ(r.t, live[k].t);
    EXPECT_EQ(r.floor.z, live[k].floor.z) << k;
    EXPECT_EQ(r.floor.unit_pixel_cov, live[k].floor.unit_pixel_cov) << k;
    EXPECT_EQ(r.floor.bias_cov, live[k].floor.bias_cov) << k;
  }

  // The head readings are what places a detection: one frame's row removed is refused, naming head.csv.
  const fs::path head = dir / "head.csv";
  std::ifstream in(head);
  std::string header, first, rest, line;
  std::getline(in, header);
  std::getline(in, first);
  while (std::getline(in, line)) rest += line + "\n";
  in.close();
  std::ofstream(head) << header << "\n" << rest;
  EXPECT_NE(errorOf([&] { scenarios::mobileCaptureRecordedMeasurements(cfg, dir.string(), 1); })
                .find("head.csv: no row for camera 0 sequence"),
            std::string::npos);
  fs::remove(head);
  EXPECT_NE(errorOf([&] { scenarios::mobileCaptureRecordedMeasurements(cfg, dir.string(), 1); }).find(": no head.csv"),
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
