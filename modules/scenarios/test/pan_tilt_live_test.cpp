// The pan-tilt loop on a live source: footage played at its stamps' rate (source.pace) with one
// slow frame misses exactly the frames a camera would have made it miss, and reports them; the
// same footage unpaced runs every frame and reports nothing live.
#include <gtest/gtest.h>
#include <unistd.h>

#include <filesystem>
#include <opencv2/imgcodecs.hpp>
#include <opencv2/imgproc.hpp>
#include <string>

#include "viewline/io/config_edit.h"
#include "viewline/runtime/file_sources.h"
#include "viewline/runtime/live.h"
#include "viewline/scenarios/pan_tilt/loop.h"

namespace fs = std::filesystem;
using namespace viewline;

namespace {

using TestClock = runtime::ManualClock;

/// The slow part of each frame's processing, as a frame sink (called from the loop's control
/// event, before the frame's processing ends): 10 ms, and 110 ms on the sixth frame.
class SlowStep : public scenarios::pan_tilt::FrameSink {
public:
  explicit SlowStep(TestClock& clock) : clock_(clock) {}
  void frame(const scenarios::pan_tilt::FrameRecord& r) override {
    clock_.advance(calls_++ == 5 ? 0.110 : 0.010);
    last_status = r.live_status;
  }
  std::string last_status;

private:
  TestClock& clock_;
  int calls_ = 0;
};

/// 20 frames 640x480: a dark disc on white, moving 2 px a frame (so no frame repeats the last).
std::string writeFootage() {
  const fs::path dir = fs::path(testing::TempDir()) / ("viewline_pt_live_" + std::to_string(::getpid()));
  fs::remove_all(dir);
  fs::create_directories(dir);
  const std::string pattern = (dir / "image.%04d.pgm").string();
  for (int i = 0; i < 20; ++i) {
    cv::Mat image(480, 640, CV_8UC1, cv::Scalar(230));
    cv::circle(image, cv::Point(300 + 2 * i, 240), 20, cv::Scalar(20), cv::FILLED);
    cv::imwrite(runtime::formatFramePattern(pattern, i), image);
  }
  return pattern;
}

scenarios::PanTiltScenarioConfig footageRun(const std::string& pattern, bool pace) {
  return scenarios::loadPanTiltScenarioConfig(io::loadConfigWithValues(
      "config/pan_tilt_circle.yaml",
      {"run.duration=1.0", "run.metrics_start=0.2", "run.baseline=false", "camera.fps=20", "source.kind=images",
       "source.pattern=" + pattern, "source.rate_hz=20", std::string("source.pace=") + (pace ? "true" : "false")}));
}

}  // namespace

TEST(PanTiltLive, ASlowFrameOnPacedFootageCountsTheFramesMissed) {
  // Frames every 50 ms (20 fps, deadline one period). Processing takes 10 ms, 110 ms on frame 5
  // (grabbed at 250 ms, done at 360 ms): frames 6 (300 ms) and 7 (350 ms) have arrived by then, the
  // loop takes 7 and frame 6 is dropped. Missed: frame 5 (late) and frame 6 (dropped), of 20.
  const std::string pattern = writeFootage();
  TestClock clock;
  SlowStep slow(clock);
  scenarios::PanTiltRunIo io;
  io.clock = &clock;
  io.frames = &slow;
  const auto r = scenarios::runPanTiltComparison(footageRun(pattern, true), 1, io);
  ASSERT_TRUE(r.ours.live.has_value());
  const runtime::LiveReport& live = *r.ours.live;
  EXPECT_EQ(live.delivered, 20u);
  EXPECT_EQ(live.processed, 19u);
  EXPECT_EQ(live.dropped, 1u);
  EXPECT_EQ(live.late, 1u);
  EXPECT_EQ(live.missed(), 2u);
  EXPECT_DOUBLE_EQ(live.deadline_s, 0.05);
  EXPECT_NEAR(live.wall.max_ms, 110.0, 1.0);  // the test clock's 110 ms (real work is not on it)
  EXPECT_EQ(r.ours.frames, 19u);               // frames the loop captured
  EXPECT_EQ(slow.last_status, "missed 2 of 20 frames (deadline 50.0 ms), last 10.0 ms");
  const nlohmann::json j = r.toJson(footageRun(pattern, true));
  EXPECT_EQ(j["ours"]["live"]["frames_missed"], 2);
  EXPECT_EQ(j["ours"]["live"]["frames_dropped"], 1);
  EXPECT_EQ(j["ours"]["live"]["deadline"], "one frame period at 20 fps");
  EXPECT_GT(r.ours.detections, 15u);  // the loop tracked the disc meanwhile
}

TEST(PanTiltLive, UnpacedFootageRunsEveryFrameAndReportsNothingLive) {
  const std::string pattern = writeFootage();
  TestClock clock;
  SlowStep slow(clock);
  scenarios::PanTiltRunIo io;
  io.clock = &clock;
  io.frames = &slow;
  const auto r = scenarios::runPanTiltComparison(footageRun(pattern, false), 1, io);
  EXPECT_FALSE(r.ours.live.has_value());
  EXPECT_EQ(r.ours.frames, 20u);
  EXPECT_TRUE(slow.last_status.empty());
  EXPECT_FALSE(r.toJson(footageRun(pattern, false))["ours"].contains("live"));
}
