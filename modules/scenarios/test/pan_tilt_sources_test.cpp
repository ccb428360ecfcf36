// The pan-tilt loop on other frame sources: a recording of a simulated run replays to the same
// summary bit for bit; footage without truth runs the loop but is not scored.
#include <gtest/gtest.h>
#include <unistd.h>

#include <filesystem>
#include <fstream>
#include <opencv2/imgcodecs.hpp>
#include <opencv2/videoio.hpp>
#include <sstream>
#include <string>
#include <vector>

#include "viewline/io/config_edit.h"
#include "viewline/scenarios/pan_tilt/loop.h"

namespace fs = std::filesystem;
using namespace viewline;

namespace {

/// A short run (0.7 s, ours only): the loop, not the figures, is under test.
scenarios::PanTiltScenarioConfig shortRun(std::vector<std::string> edits = {}) {
  edits.insert(edits.end(), {"run.duration=0.7", "run.metrics_start=0.2", "run.baseline=false"});
  return scenarios::loadPanTiltScenarioConfig(io::loadConfigWithValues("config/pan_tilt_circle.yaml", edits));
}

fs::path scratch(const std::string& name) {
  const fs::path p = fs::path(testing::TempDir()) / ("viewline_pt_" + std::to_string(::getpid()) + "_" + name);
  fs::remove_all(p);
  return p;
}

/// The summary without its wall-clock figure (the only value a replay may change).
nlohmann::json withoutWallClock(nlohmann::json j) {
  j["ours"].erase("wall_ms_per_frame");
  return j;
}

}  // namespace

TEST(PanTiltSources, ReplayOfARecordingGivesTheLiveSummaryBitForBit) {
  const auto cfg = shortRun();
  const fs::path dir = scratch("rec");
  scenarios::PanTiltRunIo record;
  record.record_dir = dir.string();
  record.config_text = "recorded: true\n";
  const auto live = scenarios::runPanTiltComparison(cfg, 7, record);
  ASSERT_TRUE(fs::exists(dir / "predictive" / "recording.csv"));
  ASSERT_TRUE(fs::exists(dir / "predictive" / "truth.csv"));
  ASSERT_TRUE(fs::exists(dir / "predictive" / "camera0.xml"));

  scenarios::PanTiltRunIo replay;
  replay.replay_dir = dir.string();
  const auto again = scenarios::runPanTiltComparison(cfg, 7, replay);
  EXPECT_TRUE(again.ours.scored);
  EXPECT_GT(live.ours.detections, 15u);
  EXPECT_EQ(withoutWallClock(again.toJson(cfg)).dump(), withoutWallClock(live.toJson(cfg)).dump());

  // The same recording named in the config (source: kind recording) replays alike.
  const auto by_config = shortRun({"source.kind=recording", "source.path=" + (dir / "predictive").string()});
  const auto third = scenarios::runPanTiltComparison(by_config, 7);
  EXPECT_EQ(third.ours.image_error_rms_px, live.ours.image_error_rms_px);
  EXPECT_EQ(third.ours.rmse_filtered_cm, live.ours.rmse_filtered_cm);
}

TEST(PanTiltSources, FootageWithoutTruthIsNotScored) {
  const std::string mire = "/usr/share/visp-images-data/ViSP-images/mire-2/image.%04d.pgm";
  if (!fs::exists("/usr/share/visp-images-data/ViSP-images/mire-2/image.0001.pgm")) GTEST_SKIP() << "visp-images-data missing";
  const auto cfg = shortRun({"source.kind=images", "source.pattern=" + mire, "source.first=1", "source.rate_hz=30"});
  const auto r = scenarios::runPanTiltComparison(cfg, 1);
  EXPECT_FALSE(r.ours.scored);
  EXPECT_EQ(r.ours.frames, 21u);  // run.duration x the camera's 30 fps, from the sequence's first 21 files
  EXPECT_TRUE(std::isnan(r.ours.image_error_rms_px));
  const nlohmann::json j = r.toJson(cfg);
  EXPECT_EQ(j["truth"], "not scored (the frame source has no truth)");
  EXPECT_TRUE(j["ours"]["rmse_measured_cm"]["x"].is_null());
}

// A recorded run's frames written as footage, an image sequence and an FFV1 (lossless) video with
// one stamps file: the loop gives the same unscored result on both, frame for frame.
TEST(PanTiltSources, FootageAsAVideoGivesWhatItsImagesGive) {
  const fs::path dir = scratch("video");
  scenarios::PanTiltRunIo record;
  record.record_dir = (dir / "rec").string();
  const auto live = scenarios::runPanTiltComparison(shortRun(), 7, record);
  std::ifstream index(dir / "rec" / "predictive" / "recording.csv");
  std::string line;
  ASSERT_TRUE(std::getline(index, line)) << "recording.csv";  // ready_time,camera,sequence,capture_time,stamp,file
  const fs::path mkv = dir / "footage.mkv";
  std::ofstream stamps(dir / "stamps.csv");
  cv::VideoWriter video;
  std::size_t frames = 0;
  while (std::getline(index, line)) {
    std::vector<std::string> f;
    std::stringstream row(line);
    for (std::string cell; std::getline(row, cell, ',');) f.push_back(cell);
    ASSERT_EQ(f.size(), 6u) << line;
    const cv::Mat bgr = cv::imread((dir / "rec" / "predictive" / f[5]).string(), cv::IMREAD_COLOR);
    ASSERT_FALSE(bgr.empty()) << f[5];
    if (!video.isOpened())
      video.open(mkv.string(), cv::CAP_FFMPEG, cv::VideoWriter::fourcc('F', 'F', 'V', '1'), 30.0, bgr.size(), true);
    ASSERT_TRUE(video.isOpened()) << "OpenCV's FFmpeg back end cannot write FFV1";
    video.write(bgr);
    stamps << frames << ',' << f[4] << '\n';  // the recorded stamp, printed to the last bit
    ++frames;
  }
  video.release();
  stamps.close();
  ASSERT_EQ(frames, live.ours.frames);
  const std::string stamps_file = (dir / "stamps.csv").string();
  const auto on_images = scenarios::runPanTiltComparison(
      shortRun({"source.kind=images", "source.pattern=" + (dir / "rec" / "predictive" / "cam0" / "%06d.png").string(),
                "source.stamps=" + stamps_file}),
      7);
  const auto on_video =
      scenarios::runPanTiltComparison(shortRun({"source.kind=video", "source.path=" + mkv.string(), "source.stamps=" + stamps_file}), 7);
  EXPECT_FALSE(on_video.ours.scored);
  EXPECT_EQ(on_video.ours.frames, frames);
  EXPECT_EQ(on_images.ours.frames, frames);
  EXPECT_GT(on_images.ours.detections, 15u);
  EXPECT_EQ(on_video.ours.detections, on_images.ours.detections);
  EXPECT_EQ(on_video.ours.detections, live.ours.detections);
  EXPECT_EQ(on_video.ours.filter_jumps, on_images.ours.filter_jumps);
  fs::remove_all(dir);
}
