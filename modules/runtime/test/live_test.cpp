// Live mode: footage played as a camera (PacedSource) hands out the newest arrived frame and counts
// the ones a busy loop passed over; ProcessingTimer counts the frames processed past the deadline.
// A clock the test advances makes the counts exact; one short run on the real clock checks the
// bookkeeping with real sleeps.
#include <gtest/gtest.h>
#include <unistd.h>

#include <chrono>
#include <filesystem>
#include <opencv2/core.hpp>
#include <opencv2/imgcodecs.hpp>
#include <string>
#include <thread>
#include <vector>

#include "viewline/core/error.h"
#include "viewline/io/config.h"
#include "viewline/runtime/file_sources.h"
#include "viewline/runtime/live.h"
#include "viewline/runtime/source_config.h"

namespace fs = std::filesystem;
using namespace viewline;
using namespace viewline::runtime;

namespace {

/// The manual clock from an arbitrary origin: the source's times are relative to its first grab.
class TestClock : public ManualClock {
public:
  TestClock() : ManualClock(100.0) {}
};

/// `n` 16x16 grey images seq/image.%04d.pgm, frame i filled with the value 10 i (distinct, so the
/// frame handed out can be told by its content).
std::string writeSequence(const std::string& name, int n) {
  const fs::path dir = fs::path(testing::TempDir()) / ("viewline_live_" + std::to_string(::getpid()) + "_" + name);
  fs::remove_all(dir);
  fs::create_directories(dir);
  for (int i = 0; i < n; ++i)
    cv::imwrite(formatFramePattern((dir / "image.%04d.pgm").string(), i), cv::Mat(16, 16, CV_8UC1, cv::Scalar(10 * i)));
  return (dir / "image.%04d.pgm").string();
}

std::unique_ptr<PacedSource> pacedImages(const std::string& pattern, double rate, double factor, WallClock* clock) {
  ImageSequenceOptions o;
  o.pattern = pattern;
  o.rate = rate;
  return std::make_unique<PacedSource>(std::make_unique<ImageSequenceSource>(o), factor, "images", clock);
}

}  // namespace

TEST(PacedSource, ASlowFrameDropsTheFramesThatArrivedMeanwhileAndCountsThemExactly) {
  // 10 frames at 20 fps (one every 50 ms); processing takes 10 ms, except 170 ms on the third
  // frame handed out and 70 ms on the fifth. Arrivals at 0, 50, ..., 450 ms:
  //   f0 at 0 (+10), f1 at 50 (+10), f2 at 100 (+170: busy until 270, f3..f5 arrived),
  //   f5 at 270 (f3, f4 dropped; +10), f6 at 300 (+70: until 370, f7 arrived), f7 at 370, f8, f9.
  TestClock clock;
  auto source = pacedImages(writeSequence("slow", 10), 20.0, 1.0, &clock);
  ProcessingTimer timer(0.05, &clock);  // one frame period
  const std::vector<double> step_ms = {10, 10, 170, 10, 70, 10, 10, 10};
  std::vector<std::uint64_t> sequences;
  std::vector<double> grab_times;
  std::size_t k = 0;
  while (source->nextReadyTime()) {
    const auto frame = source->grab();
    ASSERT_TRUE(frame.has_value());
    grab_times.push_back(clock.now() - 100.0);
    sequences.push_back(frame->sequence);
    EXPECT_EQ(static_cast<std::uint64_t>(frame->image.at<unsigned char>(0, 0)), 10 * frame->sequence);  // the newest frame's own image
    timer.resume(k);
    clock.advance(1e-3 * step_ms.at(k));
    timer.finish(k);
    ++k;
  }
  EXPECT_EQ(sequences, (std::vector<std::uint64_t>{0, 1, 2, 5, 6, 7, 8, 9}));
  const std::vector<double> expected_grab = {0.0, 0.05, 0.10, 0.27, 0.30, 0.37, 0.40, 0.45};
  ASSERT_EQ(grab_times.size(), expected_grab.size());
  for (std::size_t i = 0; i < grab_times.size(); ++i) EXPECT_NEAR(grab_times[i], expected_grab[i], 1e-9) << i;
  EXPECT_EQ(source->delivered(), 10u);
  EXPECT_EQ(source->dropped(), 2u);
  EXPECT_EQ(timer.frames(), 8u);
  EXPECT_EQ(timer.late(), 2u);  // the 170 ms and the 70 ms frames

  const LiveReport r = liveReport(*source, timer, "one frame period at 20 fps");
  EXPECT_EQ(r.missed(), 4u);
  EXPECT_EQ(r.processed, 8u);
  EXPECT_NEAR(r.wall.median_ms, 10.0, 1e-6);
  EXPECT_NEAR(r.wall.max_ms, 170.0, 1e-6);
  EXPECT_NEAR(r.wall.p99_ms, 70.0 + 0.93 * 100.0, 1e-6);  // type 7 between the two largest of 8
  EXPECT_EQ(summaryLine(r),
            "live: 4 of 10 frames missed their 50.0 ms deadline (one frame period at 20 fps): 2 dropped while busy, "
            "2 processed late");
  const nlohmann::json j = toJson(r);
  EXPECT_EQ(j["frames_missed"], 4);
  EXPECT_EQ(j["frames_dropped"], 2);
  EXPECT_EQ(j["frames_late"], 2);
  EXPECT_EQ(j["deadline_s"], 0.05);
  EXPECT_EQ(j["source"], "images played as a live camera at 1x its stamps' rate");
}

TEST(PacedSource, AFastLoopWaitsForEachFrameAndMissesNone) {
  TestClock clock;
  auto source = pacedImages(writeSequence("fast", 6), 25.0, 2.0, &clock);  // 2x: one frame every 20 ms
  ProcessingTimer timer(0.02, &clock);
  std::vector<double> grab_times;
  for (std::uint64_t k = 0; source->nextReadyTime(); ++k) {
    ASSERT_TRUE(source->grab().has_value());
    grab_times.push_back(clock.now() - 100.0);
    timer.resume(k);
    clock.advance(0.005);
    timer.pause(k);  // waiting for the scheduler is not processing
    clock.advance(0.005);
    timer.resume(k);
    clock.advance(0.005);
    timer.finish(k);
  }
  ASSERT_EQ(grab_times.size(), 6u);
  for (std::size_t i = 0; i < 6; ++i) EXPECT_NEAR(grab_times[i], 0.02 * static_cast<double>(i), 1e-9);
  EXPECT_EQ(source->dropped(), 0u);
  EXPECT_EQ(timer.late(), 0u);
  EXPECT_NEAR(timer.wall().max_ms, 10.0, 1e-6);  // 5 + 5 ms, the 5 ms pause left out
}

TEST(PacedSource, OnTheRealClockEveryDeliveredFrameIsProcessedOrDropped) {
  // 8 frames at 50 fps, 30 ms of (sleeping) processing each: always past the 20 ms deadline, and
  // the loop falls behind, so frames are dropped; how many depends on the machine's timing, but
  // every delivered frame is accounted for.
  auto source = pacedImages(writeSequence("real", 8), 50.0, 1.0, nullptr);
  ProcessingTimer timer(0.02);
  for (std::uint64_t k = 0; source->nextReadyTime(); ++k) {
    const auto frame = source->grab();
    ASSERT_TRUE(frame.has_value());
    timer.resume(k);
    std::this_thread::sleep_for(std::chrono::milliseconds(30));
    timer.finish(k);
  }
  EXPECT_EQ(source->delivered(), 8u);
  EXPECT_EQ(timer.frames() + source->dropped(), 8u);
  EXPECT_GE(source->dropped(), 1u);
  EXPECT_EQ(timer.late(), timer.frames());
  EXPECT_GE(timer.wall().median_ms, 30.0);
  EXPECT_LT(timer.cpu().median_ms, 30.0);  // sleeping uses no CPU
}

TEST(PacedSource, RefusesABadFactorAndDeadline) {
  TestClock clock;
  const std::string pattern = writeSequence("bad", 1);
  EXPECT_THROW(pacedImages(pattern, 30.0, 0.0, &clock), core::InvalidInput);
  EXPECT_THROW(ProcessingTimer(0.0), core::InvalidInput);
}

TEST(SourceConfig, PaceMakesFootageALiveSource) {
  const std::string pattern = writeSequence("cfg", 2);
  const auto read = [](const std::string& yaml) { return readSourceConfig(io::ConfigNode::fromString(yaml, "s.yaml", "/cfg")); };
  const SourceConfig paced = read("source: {kind: images, pattern: " + pattern + ", pace: true}\n");
  EXPECT_TRUE(paced.pace);
  EXPECT_TRUE(paced.live());
  EXPECT_NE(dynamic_cast<LiveFrameSource*>(makeFrameSource(paced).get()), nullptr);
  const SourceConfig batch = read("source: {kind: images, pattern: " + pattern + "}\n");
  EXPECT_FALSE(batch.live());
  EXPECT_EQ(dynamic_cast<LiveFrameSource*>(makeFrameSource(batch).get()), nullptr);
  // A camera is live by itself: `pace` is not one of its keys.
  const io::ConfigNode n = io::ConfigNode::fromString("source: {kind: v4l2, pace: true}\n", "s.yaml");
  EXPECT_TRUE(readSourceConfig(n).live());
  EXPECT_THROW(n.finish(), core::InvalidInput);
}
