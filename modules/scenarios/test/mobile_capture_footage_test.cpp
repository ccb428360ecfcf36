// Mobile capture on footage (mobile_capture/footage.h): the scenario's renderer draws the object
// moving on the floor as seen from the robot's head camera at its start pose (the pose the footage
// session holds), and the frames are written as footage the way a real camera would give them: an
// image sequence (PNG, lossless) with a stamps file, and a motion-JPEG video (lossy) with a stamps
// file. The session runs on each without truth; the test knows the rendered object's path and
// checks the tracked ground position against it, the frame counts against the files, and that no
// command the held robot computed is outside its limits.
#include <gtest/gtest.h>
#include <unistd.h>

#include <cmath>
#include <cstdlib>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <functional>
#include <opencv2/imgcodecs.hpp>
#include <opencv2/videoio.hpp>
#include <string>
#include <vector>

#include "viewline/core/error.h"
#include "viewline/io/config_edit.h"
#include "viewline/scenarios/mobile_capture.h"
#include "viewline/scenarios/mobile_capture/footage.h"
#include "viewline/scenarios/mobile_capture/world.h"
#include "scenario_test_util.h"

namespace fs = std::filesystem;
using namespace viewline;

using viewline::scenarios::test::errorOf;

namespace {

// The object's path and the sensor noise; VIEWLINE_MC_FOOTAGE_SEED=S runs the suite on another seed
// (docs/results.md gives the figures over seeds 1-5).
const std::uint64_t kSeed =
    std::getenv("VIEWLINE_MC_FOOTAGE_SEED") ? std::strtoull(std::getenv("VIEWLINE_MC_FOOTAGE_SEED"), nullptr, 10) : 3;
// The object starts 3.5 m ahead of the robot (at (-0.5, -0.5), heading +y), comes towards it on
// [K]'s capture profile (0.6 m/s) and turns left: it stays within 7 degrees of the held head
// camera's axis and 1.2-3.6 m from it for the footage's 4 s (41 frames).
const std::vector<std::string> kScene = {"world.object_start=[-0.1, 3.0]", "world.object_heading_deg=210",
                                         "world.max_time=4"};
constexpr int kSkip = 5;  // frames after the track's start before its position is compared (two-point start)

struct Footage {
  fs::path dir;
  std::size_t frames = 0;
  std::vector<double> stamps;
  std::vector<Eigen::Vector2d> truth;  // the rendered object's centre at each frame's stamp, m
};

scenarios::MobileCaptureConfig configWith(const std::vector<std::string>& sets) {
  std::vector<std::string> all = kScene;
  all.insert(all.end(), sets.begin(), sets.end());
  return scenarios::loadMobileCaptureConfig(io::loadConfigWithValues("config/mobile_capture.yaml", all));
}

// Renders the scene from the held camera and writes it as an image sequence and a video, each with
// a stamps file (stamps offset by 100 s: the footage's clock is its own, not the simulator's).
Footage makeFootage() {
  using namespace scenarios::mobile_capture;
  Footage f;
  f.dir = fs::path(testing::TempDir()) / ("viewline_mc_footage_" + std::to_string(::getpid()));
  fs::remove_all(f.dir);
  fs::create_directories(f.dir / "seq");
  const auto cfg = configWith({});
  Streams rng(kSeed);
  const sim::GroundTarget target(targetParams(cfg, sim::GroundProfile::Capture, targetDuration(cfg)), rng.object);
  const RobotSim robot(cfg);
  const robots::BasePose pose = robot.base.pose();
  RenderedHeadCamera camera(cfg, target, rng,
                            [&] { return trueCamera_c_M_w(robot.head, robot.q, pose.x, pose.y, pose.theta); });
  std::string stamps = "index,stamp\n";
  cv::VideoWriter video;
  while (camera.nextReadyTime()) {
    const auto frame = camera.grab();
    if (!frame) continue;
    char name[32];
    std::snprintf(name, sizeof name, "image.%04zu.png", f.frames);
    EXPECT_TRUE(cv::imwrite((f.dir / "seq" / name).string(), frame->image));
    if (!video.isOpened())
      video.open((f.dir / "head.avi").string(), cv::CAP_FFMPEG, cv::VideoWriter::fourcc('M', 'J', 'P', 'G'), 10.0,
                 frame->image.size());
    EXPECT_TRUE(video.isOpened()) << "OpenCV's FFmpeg back end cannot write MJPG";
    video.write(frame->image);
    const double stamp = 100.0 + frame->stamp;
    char line[64];
    std::snprintf(line, sizeof line, "%zu,%.17g\n", f.frames, stamp);
    stamps += line;
    const auto s = target.state(frame->stamp);
    f.stamps.push_back(stamp);
    f.truth.emplace_back(s.x, s.y);
    ++f.frames;
  }
  video.release();
  std::ofstream(f.dir / "seq" / "stamps.csv") << stamps;
  std::ofstream(f.dir / "head_stamps.csv") << stamps;
  return f;
}

class MobileCaptureFootage : public testing::Test {
protected:
  static void SetUpTestSuite() { footage_ = new Footage(makeFootage()); }
  static void TearDownTestSuite() {
    fs::remove_all(footage_->dir);
    delete footage_;
    footage_ = nullptr;
  }
  static std::vector<std::string> imageSets() {
    return {"source={kind: images, pattern: " + (footage_->dir / "seq" / "image.%04d.png").string() +
            ", stamps: " + (footage_->dir / "seq" / "stamps.csv").string() + "}"};
  }
  // The video is motion JPEG: its blob centres are noisier than the rendered frames' the shipped
  // detector.pixel_sigma (0.12 px) was fitted to, and with it the gate rejected up to 9 of 39
  // detections and restarted the track on 3 of seeds 1-5; 0.3 px is what this footage needs.
  static std::vector<std::string> videoSets() {
    return {"detector.pixel_sigma=0.3", "source={kind: video, path: " + (footage_->dir / "head.avi").string() +
            ", stamps: " + (footage_->dir / "head_stamps.csv").string() + "}"};
  }
  // The checks every session must pass: every frame counted, the track within max_mean_m (mean)
  // and max_max_m (max) of the rendered object on the frames after the track's first kSkip. "A few
  // cm": the calibrated rig's camera-to-ground error alone puts the floor points several cm off at
  // 3 m (docs/results.md, Mobile capture: 0.080 m RMS in the simulated loop).
  static void checkSession(const scenarios::MobileFootageSummary& s, const scenarios::MobileCaptureConfig& cfg,
                           double max_mean_m, double max_max_m) {
    const Footage& f = *footage_;
    std::printf("%s", scenarios::footageSummaryText(s, cfg).c_str());
    EXPECT_FALSE(s.interrupted);
    EXPECT_EQ(s.frames, f.frames);
    EXPECT_EQ(s.lost, 0u);
    ASSERT_EQ(s.samples.size(), f.frames);
    EXPECT_DOUBLE_EQ(s.t_first, f.stamps.front());
    EXPECT_DOUBLE_EQ(s.t_last, f.stamps.back());
    EXPECT_GT(s.detections, f.frames * 3 / 4);
    EXPECT_EQ(s.gate.starts, 1u);  // one track over the footage, never restarted
    EXPECT_EQ(s.gate.restarts, 0u);
    double sum = 0.0, worst = 0.0, sse_measured = 0.0;
    int n = 0, tracked = 0, measured = 0;
    for (std::size_t k = 0; k < s.samples.size(); ++k) {
      const auto& r = s.samples[k];
      EXPECT_DOUBLE_EQ(r.t, f.stamps[k]);
      if (r.detected) sse_measured += (r.measured - f.truth[k]).squaredNorm(), ++measured;
      if (!r.track_valid || ++tracked <= kSkip) continue;
      const double e = (r.position - f.truth[k]).norm();
      sum += e, worst = std::max(worst, e), ++n;
      EXPECT_TRUE(std::isfinite(r.speed));
      EXPECT_TRUE(r.intercept.allFinite());
      EXPECT_GT(r.intercept_time, r.t);
    }
    ASSERT_GT(n, static_cast<int>(f.frames) / 2);
    std::printf("tracked ground position against the rendered object over %d frames: mean %.1f mm, max %.1f mm "
                "(the detections' floor points: RMS %.1f mm over %d)\n",
                n, 1e3 * sum / n, 1e3 * worst, 1e3 * std::sqrt(sse_measured / std::max(measured, 1)), measured);
    EXPECT_LT(sum / n, max_mean_m);
    EXPECT_LT(worst, max_max_m);
    // The held robot's commands: one per control period over the footage, none outside the limits.
    const auto ticks = static_cast<std::uint64_t>(std::floor((s.t_last - s.t_first) / cfg.controlPeriod() + 1e-6)) + 1;
    EXPECT_NEAR(static_cast<double>(s.base_commands), static_cast<double>(ticks), 1.0);
    EXPECT_EQ(s.head_commands, s.base_commands);
    EXPECT_EQ(s.limit_violations, 0u);
    EXPECT_LE(s.max_speed, cfg.base.max_speed * (1.0 + 1e-9));
    EXPECT_LE(s.max_turn_rate, cfg.base.max_turn_rate * (1.0 + 1e-9));
    EXPECT_GT(s.max_speed, 0.0);  // the planner sent the base somewhere (not executed)
    EXPECT_NEAR(s.robot.x, cfg.robot_start.x(), 1e-12);
    EXPECT_NEAR(s.robot.y, cfg.robot_start.y(), 1e-12);
  }
  static Footage* footage_;
};

Footage* MobileCaptureFootage::footage_ = nullptr;

}  // namespace

TEST_F(MobileCaptureFootage, ImageSequenceTracksTheRenderedObjectWithinAFewCentimetresPacedOrViewed) {
  const auto cfg = configWith(imageSets());
  ASSERT_TRUE(scenarios::mobileCaptureOnFootage(cfg));
  const auto s = scenarios::runMobileCaptureFootage(cfg, kSeed);
  checkSession(s, cfg, 0.04, 0.10);
  EXPECT_FALSE(s.live.has_value());  // unpaced files: no live figures
  const nlohmann::json j = scenarios::footageSummaryJson(s, cfg);
  EXPECT_TRUE(j.at("capture_success_rate").is_null());
  EXPECT_TRUE(j.at("capture_time_s").is_null());
  EXPECT_EQ(j.at("truth"), "not scored (the frame source has no truth)");
  EXPECT_EQ(j.at("frames"), footage_->frames);
  EXPECT_EQ(j.at("robot").at("limit_violations"), 0);
  EXPECT_FALSE(j.at("object_last").is_null());
  EXPECT_NE(scenarios::footageSummaryText(s, cfg).find("not scored: no truth"), std::string::npos);

  // The same footage (one render per test process: making the footage is the slow part) played as
  // a live camera on a clock the test advances itself: nothing is dropped, every frame is timed.
  runtime::ManualClock clock;
  auto sets = imageSets();
  sets.push_back("source.pace=true");
  const auto paced_cfg = configWith(sets);
  const auto paced = scenarios::runMobileCaptureFootage(paced_cfg, kSeed, &clock);
  ASSERT_TRUE(paced.live.has_value());
  EXPECT_EQ(paced.live->dropped, 0u);
  EXPECT_EQ(paced.live->processed, footage_->frames);
  EXPECT_EQ(paced.frames, footage_->frames);
  EXPECT_TRUE(scenarios::footageSummaryJson(paced, paced_cfg).contains("live"));

  // A view sees every frame with the held robot, and its quit after 10 frames ends the session.
  scenarios::MobileCaptureHooks hooks;
  int shown = 0, tracked = 0;
  hooks.on_frame = [&](const scenarios::MobileCaptureFrame& f) {
    ++shown;
    ASSERT_NE(f.image, nullptr);
    EXPECT_EQ(f.image->cols, 320);
    EXPECT_NEAR(f.robot.x, cfg.robot_start.x(), 1e-12);  // held
    if (f.estimate_valid) {
      ++tracked;
      EXPECT_FALSE(f.prediction.empty());
      EXPECT_TRUE((f.object_true - f.estimate.head<2>()).norm() < 1e-9);  // no truth: the track stands in
    }
  };
  hooks.quit_requested = [&] { return shown >= 10; };
  const auto viewed = scenarios::runMobileCaptureFootage(cfg, kSeed, nullptr, &hooks);
  EXPECT_TRUE(viewed.interrupted);
  EXPECT_EQ(shown, 10);
  EXPECT_EQ(viewed.frames, 10u);
  EXPECT_GT(tracked, 5);
  EXPECT_NE(scenarios::footageSummaryText(viewed, cfg).find("(interrupted)"), std::string::npos);
  // What the footage session cannot do is refused by name.
  scenarios::MobileCaptureHooks record;
  record.record_dir = "rec";
  EXPECT_NE(errorOf([&] { scenarios::runMobileCaptureFootage(cfg, kSeed, nullptr, &record); }).find("--record"),
            std::string::npos);
}

TEST_F(MobileCaptureFootage, MotionJpegVideoTracksTheRenderedObjectWithinAFewCentimetres) {
  const auto cfg = configWith(videoSets());
  const auto s = scenarios::runMobileCaptureFootage(cfg, kSeed);
  checkSession(s, cfg, 0.04, 0.10);
}

TEST(MobileCaptureFootageInput, MissingFilesAndBadPatternsAreNamed) {
  const std::string dir = (fs::path(testing::TempDir()) / "viewline_mc_no_such_folder").string();
  const auto missing = configWith({"source={kind: images, pattern: " + dir + "/image.%04d.png}"});
  std::string e = errorOf([&] { scenarios::runMobileCaptureFootage(missing, 1); });
  EXPECT_NE(e.find(dir + "/image.0000.png"), std::string::npos) << e;
  e = errorOf([&] { configWith({"source={kind: images, pattern: " + dir + "/image.png}"}); });
  EXPECT_NE(e.find("image pattern '" + dir + "/image.png'"), std::string::npos) << e;
  const auto no_video = configWith({"source={kind: video, path: " + dir + "/head.avi}"});
  e = errorOf([&] { scenarios::runMobileCaptureFootage(no_video, 1); });
  EXPECT_NE(e.find(dir + "/head.avi"), std::string::npos) << e;
  const auto no_camera = configWith({"source={kind: v4l2, device: " + dir + "/video9}"});
  e = errorOf([&] { scenarios::runMobileCaptureFootage(no_camera, 1); });
  EXPECT_NE(e.find(dir + "/video9"), std::string::npos) << e;
  // The simulated batch's sources are not footage.
  EXPECT_FALSE(scenarios::mobileCaptureOnFootage(configWith({})));
  EXPECT_NE(errorOf([] { scenarios::runMobileCaptureFootage(configWith({}), 1); }).find("expected footage"),
            std::string::npos);
}
