// Ball catching on footage (ball_catching/footage.h): two simulated throws are rendered and
// recorded (--record), then written out as footage the way a real rig would give it, one source per
// camera on one clock: an image sequence with a stamps file per camera (PNG, lossless) and a video
// per camera (motion JPEG in AVI through cv::VideoWriter, lossy, with a stamps file). The second throw comes
// a second after the first ends. The footage session must count every file's frames, start one
// track per throw, predict each throw's crossing within a few cm of the rendered truth (which the
// footage does not carry: the test knows it from the recording), move the simulated robot there
// within its limits, and go home in between. On the lossless images the session sees exactly the
// frames and stamps the simulated throws saw, so the planner's target equals the simulated one.
#include <gtest/gtest.h>
#include <unistd.h>

#include <cstdio>
#include <filesystem>
#include <functional>
#include <fstream>
#include <opencv2/imgcodecs.hpp>
#include <opencv2/videoio.hpp>
#include <string>
#include <vector>

#include "viewline/core/error.h"
#include "viewline/io/config_edit.h"
#include "viewline/runtime/recording.h"
#include "viewline/runtime/stamps.h"
#include "viewline/scenarios/ball_catching.h"
#include "viewline/scenarios/ball_catching/recording.h"
#include "scenario_test_util.h"

namespace fs = std::filesystem;
using namespace viewline;

using viewline::scenarios::test::errorOf;

namespace {

constexpr int kThrows = 2;
constexpr std::uint64_t kSeed = 1;  // both throws reachable, neither given up in the simulated run
constexpr double kPause = 1.5;  // s between the end of a throw's footage and the next one (> max_coast_s)
// The registration renders its own frames and needs the marker in them: off, as on footage; the
// cameras at 25 Hz keep the rendering short.
const std::vector<std::string> kSim = {"registration.enabled=false", "rate_override_hz=25", "cameras[0].blur_samples=1",
                                       "cameras[1].blur_samples=1"};

struct Footage {
  fs::path dir;
  scenarios::CatchSummary sim;            // the simulated throws the footage was rendered from
  std::vector<double> offset;             // per throw: its clock's offset on the footage clock, s
  std::vector<std::size_t> frames;        // per camera: frames written
  std::vector<std::string> image_sets, video_sets;  // --set values naming the footage of each camera
};

void writeText(const fs::path& file, const std::string& text) {
  std::ofstream out(file);
  out << text;
  ASSERT_TRUE(out.good()) << file;
}

// Renders and records the throws, then writes each camera's frames as an image sequence with a
// stamps file on the session's clock (and the stamps of the videos writeVideos() makes).
Footage makeFootage() {
  Footage f;
  f.dir = fs::path(testing::TempDir()) / ("viewline_bc_footage_" + std::to_string(::getpid()));
  fs::remove_all(f.dir);
  const auto cfg = scenarios::loadBallCatchingConfig(io::loadConfigWithValues("config/ball_catching.yaml", kSim));
  scenarios::CatchHooks record;
  record.record_dir = (f.dir / "rec").string();
  f.sim = scenarios::runBallCatching(cfg, kThrows, kSeed, record);
  const std::size_t cameras = cfg.activeCameras();
  f.frames.assign(cameras, 0);
  std::vector<std::string> image_stamps(cameras, "index,stamp\n"), video_stamps(cameras, "index,stamp\n");
  double end = 0.0;  // last stamp so far on the footage clock
  for (int k = 0; k < kThrows; ++k) {
    const double offset = k == 0 ? 0.0 : end + kPause;
    f.offset.push_back(offset);
    const fs::path throw_dir = scenarios::catchThrowDir(record.record_dir, k);
    const std::string index_file = (throw_dir / "recording.csv").string();
    for (const runtime::RecordingEntry& e :
         runtime::parseRecordingIndex(runtime::csv::readWholeFile(index_file, "recording index"), index_file)) {
      if (e.file.empty()) continue;  // a lost grab: no file
      const std::size_t c = e.camera;
      const fs::path cam_dir = f.dir / ("cam" + std::to_string(c));
      fs::create_directories(cam_dir);
      char name[32];
      std::snprintf(name, sizeof name, "image.%04zu.png", f.frames[c]);
      fs::copy_file(throw_dir / e.file, cam_dir / name);
      char line[64];
      std::snprintf(line, sizeof line, "%zu,%.17g\n", f.frames[c], e.stamp + offset);
      image_stamps[c] += line;
      video_stamps[c] += line;  // video frame n is image n
      ++f.frames[c];
      end = std::max(end, e.stamp + offset);
    }
  }
  for (std::size_t c = 0; c < cameras; ++c) {
    const std::string cam = "cam" + std::to_string(c);
    writeText(f.dir / cam / "stamps.csv", image_stamps[c]);
    writeText(f.dir / (cam + "_stamps.csv"), video_stamps[c]);
    const std::string key = "cameras[" + std::to_string(c) + "].source=";
    f.image_sets.push_back(key + "{kind: images, pattern: " + (f.dir / cam / "image.%04d.png").string() +
                           ", stamps: " + (f.dir / cam / "stamps.csv").string() + "}");
    f.video_sets.push_back(key + "{kind: video, path: " + (f.dir / (cam + ".avi")).string() +
                           ", stamps: " + (f.dir / (cam + "_stamps.csv")).string() + "}");
  }
  return f;
}

// Each camera's image sequence as a motion-JPEG video beside it (frame n = image n; lossy, as a
// camera's compressed stream is, and several times faster to write and read here than FFV1).
void writeVideos(const Footage& f) {
  for (std::size_t c = 0; c < f.frames.size(); ++c) {
    const std::string cam = "cam" + std::to_string(c);
    cv::VideoWriter video;
    for (std::size_t n = 0; n < f.frames[c]; ++n) {
      char name[32];
      std::snprintf(name, sizeof name, "image.%04zu.png", n);
      const cv::Mat image = cv::imread((f.dir / cam / name).string(), cv::IMREAD_COLOR);
      if (!video.isOpened())
        video.open((f.dir / (cam + ".avi")).string(), cv::CAP_FFMPEG, cv::VideoWriter::fourcc('M', 'J', 'P', 'G'), 25.0,
                   image.size());
      ASSERT_TRUE(video.isOpened()) << "OpenCV's FFmpeg back end cannot write MJPG";
      video.write(image);
    }
  }
}

class BallCatchingFootage : public testing::Test {
protected:
  static void SetUpTestSuite() { footage_ = new Footage(makeFootage()); }
  static void TearDownTestSuite() {
    fs::remove_all(footage_->dir);
    delete footage_;
    footage_ = nullptr;
  }
  static scenarios::BallCatchingConfig configWith(const std::vector<std::string>& sets) {
    std::vector<std::string> all = kSim;
    all.insert(all.end(), sets.begin(), sets.end());
    return scenarios::loadBallCatchingConfig(io::loadConfigWithValues("config/ball_catching.yaml", all));
  }
  // The checks every footage run must pass; max_sim_target_mm: how far each track's target may be
  // from the simulated throw's own target (< 0: not compared).
  static void checkSession(const scenarios::CatchFootageSummary& s, const scenarios::BallCatchingConfig& cfg,
                           double max_truth_mm, double max_sim_target_mm) {
    const Footage& f = *footage_;
    std::printf("%s", scenarios::footageSummaryText(s, cfg).c_str());
    ASSERT_EQ(s.cameras.size(), f.frames.size());
    for (std::size_t c = 0; c < f.frames.size(); ++c) {
      EXPECT_EQ(s.cameras[c].frames, f.frames[c]) << "camera " << c;
      EXPECT_EQ(s.cameras[c].lost, 0u);
      EXPECT_GT(s.cameras[c].detections, f.frames[c] / 3) << "camera " << c;
    }
    EXPECT_EQ(s.tracks_started, kThrows);
    ASSERT_EQ(s.tracks.size(), static_cast<std::size_t>(kThrows));
    EXPECT_EQ(s.limit_violations, 0u);
    EXPECT_EQ(s.refused_setpoints, 0u);
    EXPECT_LE(s.max_speed, cfg.robot.limits.v_max.x() * (1.0 + 1e-9));
    EXPECT_LE(s.max_acceleration, cfg.robot.limits.a_max.x() * (1.0 + 1e-9));
    for (int k = 0; k < kThrows; ++k) {
      const scenarios::ThrowResult& truth = f.sim.results.at(static_cast<std::size_t>(k));
      const scenarios::CatchFootageTrack& t = s.tracks[static_cast<std::size_t>(k)];
      const double t_cross = truth.t_cross + f.offset[static_cast<std::size_t>(k)];
      EXPECT_LE(t.t_first, t_cross) << "track " << k;
      ASSERT_TRUE(t.target.has_value()) << "track " << k << ": the planner never had a target";
      const double error = (t.target->p - truth.cross_true).norm();
      const double home_distance = (cfg.robot.home - truth.cross_true).norm();
      std::printf("throw %d: predicted crossing %.1f mm from the rendered one (%.1f ms off; simulated run's target "
                  "%.1f mm from it); home %.1f mm from it\n",
                  k, 1e3 * error, 1e3 * (t.target->t - t_cross), 1e3 * truth.prediction_error, 1e3 * home_distance);
      EXPECT_LT(error, 1e-3 * max_truth_mm) << "track " << k;
      EXPECT_NEAR(t.target->t, t_cross, 0.01) << "track " << k;
      if (max_sim_target_mm >= 0.0) {
        EXPECT_LE((t.target->p - truth.target).norm(), 1e-3 * max_sim_target_mm) << "track " << k;
        EXPECT_EQ(t.decision, truth.gave_up ? "gave_up" : truth.committed ? "committed" : "moved") << "track " << k;
      }
      // The robot went towards the crossing: at the predicted crossing time the hole is at least
      // halfway from home to the true crossing (the stage starts at home, 0.5 m/s).
      ASSERT_TRUE(t.hole_at_crossing.has_value()) << "track " << k;
      EXPECT_LT((*t.hole_at_crossing - truth.cross_true).norm(), 0.5 * home_distance) << "track " << k;
    }
    // Home again in between: the second track's plan started from home.
    EXPECT_LT((s.tracks[1].start - cfg.robot.home).norm(), 1e-6);
    EXPECT_GT((s.tracks[0].target->p - cfg.robot.home).norm(), 0.01);  // so the robot had moved away
  }
  static Footage* footage_;
};

Footage* BallCatchingFootage::footage_ = nullptr;

}  // namespace

TEST_F(BallCatchingFootage, ImageSequencesGiveTheSimulatedThrowsTargets) {
  const auto cfg = configWith(footage_->image_sets);
  ASSERT_TRUE(cfg.onFootage());
  const auto s = scenarios::runCatchFootage(cfg, kSeed);
  // Lossless frames with the simulated stamps: the same detections, tracks and targets.
  checkSession(s, cfg, 30.0, 1.0);
  const nlohmann::json j = scenarios::footageSummaryJson(s, cfg);
  EXPECT_TRUE(j.at("catch_rate_all").is_null());
  EXPECT_EQ(j.at("truth"), "not scored (the frame source has no truth)");
  EXPECT_NE(scenarios::footageSummaryText(s, cfg).find("not scored: no truth"), std::string::npos);
  EXPECT_FALSE(j.contains("live"));  // unpaced files: no live figures

  // The same footage played as live cameras on a clock that is never waited on (the test's own):
  // no frame arrives before the loop asks for it, so none is dropped, and every frame is timed.
  runtime::ManualClock clock;
  std::vector<std::string> sets = footage_->image_sets;
  for (std::size_t c = 0; c < footage_->image_sets.size(); ++c)
    sets.push_back("cameras[" + std::to_string(c) + "].source.pace=true");
  const auto paced_cfg = configWith(sets);
  const auto paced = scenarios::runCatchFootage(paced_cfg, kSeed, {}, &clock);
  ASSERT_TRUE(paced.live.has_value());
  EXPECT_EQ(paced.live->processed, paced.frames);
  EXPECT_EQ(paced.live->dropped, 0u);
  EXPECT_EQ(paced.frames, footage_->frames[0] + footage_->frames[1]);
  EXPECT_TRUE(scenarios::footageSummaryJson(paced, paced_cfg).contains("live"));
  ASSERT_EQ(paced.tracks.size(), s.tracks.size());
  EXPECT_EQ(paced.tracks[1].target->p, s.tracks[1].target->p);  // pacing changes when, never what
}

TEST_F(BallCatchingFootage, VideosPerCameraPredictTheCrossings) {
  writeVideos(*footage_);
  const auto cfg = configWith(footage_->video_sets);
  const auto s = scenarios::runCatchFootage(cfg, kSeed);
  checkSession(s, cfg, 30.0, -1.0);
}

TEST(BallCatchingFootageConfig, AMissingFileOrABadPatternIsNamed) {
  const fs::path dir = fs::path(testing::TempDir()) / ("viewline_bc_nofootage_" + std::to_string(::getpid()));
  const std::string missing = (dir / "image.%04d.png").string();
  auto configWith = [](const std::vector<std::string>& sets) {
    std::vector<std::string> all = kSim;
    all.insert(all.end(), sets.begin(), sets.end());
    return scenarios::loadBallCatchingConfig(io::loadConfigWithValues("config/ball_catching.yaml", all));
  };
  std::vector<std::string> sets = {"cameras[0].source={kind: images, pattern: " + missing + "}",
                                   "cameras[1].source={kind: images, pattern: " + missing + "}"};
  const std::string e = errorOf([&] { scenarios::runCatchFootage(configWith(sets), kSeed); });
  EXPECT_NE(e.find("cameras[right].source"), std::string::npos) << e;
  EXPECT_NE(e.find((dir / "image.0000.png").string()), std::string::npos) << e;

  sets[0] = "cameras[0].source={kind: video, path: " + (dir / "none.avi").string() + "}";
  const std::string v = errorOf([&] { scenarios::runCatchFootage(configWith(sets), kSeed); });
  EXPECT_NE(v.find((dir / "none.avi").string()), std::string::npos) << v;

  // Two conversions in a pattern: refused when the config is read, naming the pattern.
  sets[1] = "cameras[1].source={kind: images, pattern: /tmp/a%d_%d.png}";
  const std::string p = errorOf([&] { configWith(sets); });
  EXPECT_NE(p.find("/tmp/a%d_%d.png"), std::string::npos) << p;

  // One camera with footage, the other rendered: refused (two clocks).
  const std::string one = errorOf([&] { configWith({sets[0]}); });
  EXPECT_NE(one.find("every active camera needs footage"), std::string::npos) << one;
  // A recording is the session's source, not a camera's.
  const std::string rec = errorOf([&] { configWith({"cameras[0].source={kind: recording, path: /tmp}"}); });
  EXPECT_NE(rec.find("cameras[].source.kind recording is not a camera's source"), std::string::npos) << rec;
  // Footage runs as one session, not throw by throw (refused before anything is opened).
  const auto cfg = configWith({"cameras[0].source={kind: images, pattern: " + missing + "}",
                               "cameras[1].source={kind: images, pattern: " + missing + "}"});
  const std::string throws = errorOf([&] { scenarios::runBallCatching(cfg, 1, kSeed); });
  EXPECT_NE(throws.find("footage runs as one session"), std::string::npos) << throws;
}
