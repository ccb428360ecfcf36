// Dart tracking on footage (dart/footage.h): two dart flights of the scenario's own model
// (simulateDartFlight, no outliers) are rendered by the simulator's renderer, the dart's marker a
// small green sphere, as seen by the rig's two cameras on one clock (side at even, rear at odd
// 10 ms steps, 50 Hz each), and written as footage: an image sequence with a stamps file per
// camera (PNG, lossless) and a video per camera (FFV1 in Matroska through cv::VideoWriter,
// lossless, with a stamps file). The second flight comes well after the first ends (> max_coast_s).
// The session must count every file's frames, start one track per flight and predict each
// flight's board hit within a few cm of the true one (which the footage does not carry: the test
// knows it from the flight). Played as live cameras (source.pace) on a test clock, a slow frame
// misses exactly the frames the cameras delivered meanwhile; injected detector faults (a throwing
// detector, a NaN centre) are counted and skipped, and the board hits stand.
#include <gtest/gtest.h>
#include <unistd.h>

#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <functional>
#include <opencv2/imgcodecs.hpp>
#include <opencv2/videoio.hpp>
#include <string>
#include <vector>

#include "viewline/core/error.h"
#include "viewline/core/random.h"
#include "viewline/io/config_edit.h"
#include "viewline/runtime/live.h"
#include "viewline/runtime/telemetry.h"
#include "viewline/scenarios/dart/footage.h"
#include "viewline/scenarios/dart/loop.h"
#include "viewline/scenarios/dart/world.h"
#include "viewline/sim/renderer.h"
#include "scenario_test_util.h"

namespace fs = std::filesystem;
using namespace viewline;

using viewline::scenarios::test::errorOf;

namespace {

constexpr int kFlights = 2;
constexpr double kStart = 0.2;         // s, footage stamp of the first release
constexpr double kPause = 1.0;         // s between one flight's board hit and the next release (> max_coast_s)
constexpr double kPeriod = 0.02;       // s, each camera's frame period (50 Hz)
constexpr double kMarkerRadius = 0.02; // m: a dart's marker, a few pixels on the rig's cameras
const char* const kConfig = "config/dart_tracking.yaml";

struct Flight {
  double t_release = 0.0;       // s, footage clock
  tracking::Vector6 x0;         // state at the release (p m, v m/s, world)
  double duration = 0.0;        // s, release to the board
  planning::Crossing hit;       // the true board hit (footage clock)
};

struct Footage {
  fs::path dir;
  std::vector<Flight> flights;
  std::vector<std::size_t> frames;  // per camera
  std::vector<std::string> image_sets, video_sets;
  bool video_lossless = true;  // FFV1 written (else motion JPEG)
};

void writeText(const fs::path& file, const std::string& text) {
  std::ofstream out(file);
  out << text;
  ASSERT_TRUE(out.good()) << file;
}

Footage makeFootage() {
  Footage f;
  f.dir = fs::path(testing::TempDir()) / ("viewline_dart_footage_" + std::to_string(::getpid()));
  // VIEWLINE_DART_FOOTAGE_DIR: the footage written there and kept (the app runs of docs/results.md).
  if (const char* keep = std::getenv("VIEWLINE_DART_FOOTAGE_DIR")) f.dir = keep;
  fs::remove_all(f.dir);
  const scenarios::DartScenarioConfig cfg = scenarios::loadDartScenario(kConfig);
  const std::vector<core::Camera> cams = scenarios::makeDartCameras(cfg);
  const planning::CrossingPlane board = scenarios::dartBoardPlane(cfg);
  planning::CrossingModel model;
  model.kind = planning::FlightModel::Ballistic;
  model.gravity_w = cfg.gravity_w;
  tracking::BallisticModel ballistic;
  ballistic.gravity_w = cfg.gravity_w;

  // The flights: the scenario's throw model, the state at the release taken back from the first
  // generated detection (pure ballistic truth: truth_accel_psd is 0 in the shipped config).
  core::Rng rng = core::makeRng(7);
  double t = kStart;
  for (int k = 0; k < kFlights; ++k) {
    const scenarios::DartFlight sim =
        scenarios::simulateDartFlight(cfg, cams, scenarios::DartClockMode::Alternating, 0.0, rng);
    EXPECT_FALSE(sim.detections.empty());
    Flight fl;
    fl.t_release = t;
    fl.duration = sim.duration;
    // Back from the first detection (capture time t1 after the release) to the release.
    const tracking::Vector6& x1 = sim.detections.front().truth;
    const double t1 = sim.detections.front().m.t;
    fl.x0.head<3>() = x1.head<3>() - x1.tail<3>() * t1 + 0.5 * cfg.gravity_w * t1 * t1;
    fl.x0.tail<3>() = x1.tail<3>() - cfg.gravity_w * t1;
    const auto hit = planning::predictCrossing(fl.x0, t, board, model);
    EXPECT_TRUE(hit.has_value());
    fl.hit = *hit;
    f.flights.push_back(fl);
    t += sim.duration + kPause;
  }
  const double t_end = t - kPause + 0.1;

  // The marker at time t (on the footage clock): in flight, stuck in the board after the hit, absent before.
  auto marker = [&](double tt, std::vector<sim::Primitive>& out) {
    for (const Flight& fl : f.flights) {
      if (tt < fl.t_release || tt > fl.t_release + fl.duration + 0.3) continue;
      const double dt = std::min(tt, fl.hit.t) - fl.t_release;
      out.push_back(sim::makeSphere("dart", ballistic.propagate(fl.x0, dt).head<3>(), kMarkerRadius,
                                    Eigen::Vector3d(0.15, 0.75, 0.15)));
    }
  };
  sim::SceneWorld world(sim::Scene{}, marker);
  sim::Renderer renderer;
  f.frames.assign(cams.size(), 0);
  for (std::size_t c = 0; c < cams.size(); ++c) {
    const std::string cam = "cam" + std::to_string(c);
    fs::create_directories(f.dir / cam);
    std::string stamps = "index,stamp\n";
    cv::VideoWriter video;
    const fs::path mkv = f.dir / (cam + ".mkv");
    video.open(mkv.string(), cv::CAP_FFMPEG, cv::VideoWriter::fourcc('F', 'F', 'V', '1'), 50.0,
               cv::Size(static_cast<int>(cams[c].width), static_cast<int>(cams[c].height)));
    EXPECT_TRUE(video.isOpened()) << "OpenCV's FFmpeg back end cannot write FFV1";
    // Camera c's frames at c * 10 ms + n * 20 ms: the cameras alternate on one clock.
    for (double tc = 0.01 * static_cast<double>(c); tc <= t_end; tc += kPeriod) {
      const cv::Mat image = renderer.render(world, cams[c], sim::ExposureSpec{tc, 0.0, 1});
      char name[32];
      std::snprintf(name, sizeof name, "image.%04zu.png", f.frames[c]);
      EXPECT_TRUE(cv::imwrite((f.dir / cam / name).string(), image));
      video.write(image);
      char line[64];
      std::snprintf(line, sizeof line, "%zu,%.17g\n", f.frames[c], tc);
      stamps += line;
      ++f.frames[c];
    }
    video.release();
    writeText(f.dir / cam / "stamps.csv", stamps);
    const std::string key = "cameras[" + std::to_string(c) + "].source=";
    f.image_sets.push_back(key + "{kind: images, pattern: " + (f.dir / cam / "image.%04d.png").string() +
                           ", stamps: " + (f.dir / cam / "stamps.csv").string() + "}");
    f.video_sets.push_back(key + "{kind: video, path: " + mkv.string() + ", stamps: " +
                           (f.dir / cam / "stamps.csv").string() + "}");
  }
  return f;
}

class DartFootage : public testing::Test {
protected:
  static void SetUpTestSuite() { footage_ = new Footage(makeFootage()); }
  static void TearDownTestSuite() {
    if (!std::getenv("VIEWLINE_DART_FOOTAGE_DIR")) fs::remove_all(footage_->dir);
    delete footage_;
    footage_ = nullptr;
  }
  // Every file's frames counted, one track per flight, each board hit within max_mm of the truth.
  static void checkSession(const scenarios::DartFootageSummary& s, const scenarios::DartScenarioConfig& cfg,
                           double max_mm) {
    const Footage& f = *footage_;
    std::printf("%s", scenarios::dartFootageSummaryText(s, cfg).c_str());
    ASSERT_EQ(s.cameras.size(), f.frames.size());
    for (std::size_t c = 0; c < f.frames.size(); ++c) {
      EXPECT_EQ(s.cameras[c].frames, f.frames[c]) << "camera " << c;
      EXPECT_EQ(s.cameras[c].lost, 0u);
      EXPECT_GE(s.cameras[c].detections, 6u) << "camera " << c;
    }
    EXPECT_EQ(s.frames, f.frames[0] + f.frames[1]);
    EXPECT_EQ(s.tracks_started, kFlights);
    ASSERT_EQ(s.tracks.size(), static_cast<std::size_t>(kFlights));
    for (int k = 0; k < kFlights; ++k) {
      const Flight& fl = f.flights[static_cast<std::size_t>(k)];
      const scenarios::DartFootageTrack& t = s.tracks[static_cast<std::size_t>(k)];
      ASSERT_TRUE(t.board_hit.has_value()) << "track " << k;
      const double error = (t.board_hit->p - fl.hit.p).norm();
      std::printf("flight %d: predicted board hit %.1f mm from the true one (%.2f ms off), std %.1f mm\n", k,
                  1e3 * error, 1e3 * (t.board_hit->t - fl.hit.t), 1e3 * t.board_hit->sigmaMax());
      EXPECT_LT(error, 1e-3 * max_mm) << "track " << k;
      EXPECT_NEAR(t.board_hit->t, fl.hit.t, 0.005) << "track " << k;
      EXPECT_NEAR(t.board_hit->p.x(), cfg.board_center.x(), 1e-6);  // on the board plane
      EXPECT_GT(t.t_first, fl.t_release - 1e-9) << "track " << k;
    }
    EXPECT_GT(s.nis_samples, 10u);
    EXPECT_GT(s.nis_mean, 0.0);
  }
  static scenarios::DartScenarioConfig configWith(const std::vector<std::string>& sets) {
    return scenarios::loadDartScenario(kConfig, sets);
  }
  static Footage* footage_;
};

Footage* DartFootage::footage_ = nullptr;

}  // namespace

TEST_F(DartFootage, ImageSequencesGiveTheBoardHits) {
  const auto cfg = configWith(footage_->image_sets);
  ASSERT_TRUE(cfg.onFootage());
  const auto s = scenarios::runDartFootage(cfg);
  checkSession(s, cfg, 30.0);
  const nlohmann::json j = scenarios::dartFootageSummaryJson(s, cfg);
  EXPECT_TRUE(j.at("rmse_position").is_null());
  EXPECT_TRUE(j.at("experiments").is_null());
  EXPECT_EQ(j.at("truth"), "not scored (the frame source has no truth)");
  EXPECT_EQ(j.at("tracks").size(), static_cast<std::size_t>(kFlights));
  EXPECT_NE(scenarios::dartFootageSummaryText(s, cfg).find("not scored: no truth"), std::string::npos);
  EXPECT_FALSE(j.contains("live"));  // unpaced files: no live figures
  // Nothing injected; the only defence that acted is the frozen-camera one: these renders carry
  // no sensor noise, so the images of a dart at rest in the board repeat bit for bit (the hits
  // use only the images before them).
  EXPECT_TRUE(s.faults.injected.empty());
  ASSERT_EQ(s.faults.outcome.size(), 1u);
  EXPECT_GT(s.faults.outcomeOf("frames_frozen_dropped"), 0u);
}

namespace {

using TestClock = runtime::ManualClock;

/// The slow part of a frame's processing, as a telemetry sink (called while the session processes
/// a frame with a detection): the side camera's third detection takes 110 ms, the rest no time.
class SlowDetection : public runtime::TelemetrySink {
public:
  explicit SlowDetection(TestClock& clock) : clock_(clock) {}
  void measurement(const runtime::MeasurementRecord& r) override {
    if (r.channel == "camera0" && ++side_ == 3) {
      clock_.advance(0.110);
      slow_stamp = r.t;
    }
  }
  double slow_stamp = -1.0;  // s, the slow frame's stamp

private:
  TestClock& clock_;
  int side_ = 0;
};

std::vector<std::string> paced(std::vector<std::string> sets) {
  for (std::size_t c = 0; c < 2; ++c) sets.push_back("cameras[" + std::to_string(c) + "].source.pace=true");
  return sets;
}

}  // namespace

TEST_F(DartFootage, PacedFootageWithASlowFrameCountsTheFramesMissed) {
  // The cameras alternate on one clock (side at even, rear at odd 10 ms steps, 50 Hz each: the
  // deadline is one 20 ms period). Each camera's PacedSource sets its origin at its first grab,
  // both at wall 0, so a side frame of stamp s arrives at wall s and a rear one at s - 10 ms. With
  // no processing time the session takes side frame s at wall s, then rear s + 10 ms. The slow
  // side frame s ends at s + 110 ms: by then the side frames s + 20 ... s + 100 ms (5) and the
  // rear frames s + 10 ... s + 110 ms (6) have arrived. The session takes the newest of the rear
  // (its next stamp is the earliest), dropping 5, then the newest of the side, dropping 4. Missed:
  // the slow frame (late) and 9 dropped, of the 165 delivered.
  const Footage& f = *footage_;
  const std::uint64_t all = f.frames[0] + f.frames[1];
  const auto cfg = configWith(paced(f.image_sets));
  TestClock clock;
  SlowDetection slow(clock);
  const auto s = scenarios::runDartFootage(cfg, &slow, &clock);
  ASSERT_TRUE(s.live.has_value());
  const runtime::LiveReport& live = *s.live;
  EXPECT_GT(slow.slow_stamp, kStart);  // the slow frame was in the first flight
  EXPECT_EQ(live.delivered, all);
  EXPECT_EQ(live.dropped, 9u);
  EXPECT_EQ(live.late, 1u);
  EXPECT_EQ(live.missed(), 10u);
  EXPECT_EQ(live.processed, all - 9);
  EXPECT_EQ(s.frames, all - 9);  // frames handed out
  EXPECT_DOUBLE_EQ(live.deadline_s, 0.02);
  EXPECT_NEAR(live.wall.max_ms, 110.0, 1e-6);  // the test clock's 110 ms (real work is not on it)
  const nlohmann::json j = scenarios::dartFootageSummaryJson(s, cfg);
  EXPECT_EQ(j["live"]["frames_missed"], 10);
  EXPECT_EQ(j["live"]["frames_dropped"], 9);
  EXPECT_EQ(j["live"]["deadline"], "one frame period at 50 fps (the fastest camera's rate_hz)");
  const std::string text = scenarios::dartFootageSummaryText(s, cfg);
  EXPECT_NE(text.find("  " + runtime::summaryLine(live) + "\n"), std::string::npos) << text;
  EXPECT_NE(text.find("  " + runtime::processingLine(live) + "\n"), std::string::npos) << text;
  EXPECT_EQ(s.tracks.size(), static_cast<std::size_t>(kFlights));  // both darts tracked meanwhile

  // Without the slow frame nothing is missed, every frame is timed, and the hits are the unpaced
  // session's: pacing changes when, never what.
  TestClock instant;
  const auto on_time = scenarios::runDartFootage(cfg, nullptr, &instant);
  ASSERT_TRUE(on_time.live.has_value());
  EXPECT_EQ(on_time.live->missed(), 0u);
  EXPECT_EQ(on_time.live->processed, all);
  const auto unpaced = scenarios::runDartFootage(configWith(f.image_sets));
  ASSERT_EQ(on_time.tracks.size(), unpaced.tracks.size());
  for (std::size_t k = 0; k < unpaced.tracks.size(); ++k) {
    ASSERT_TRUE(on_time.tracks[k].board_hit && unpaced.tracks[k].board_hit) << "track " << k;
    EXPECT_EQ(on_time.tracks[k].board_hit->p, unpaced.tracks[k].board_hit->p) << "track " << k;
  }
}

TEST_F(DartFootage, AThrowingDetectorAndANaNCentreAreCountedAndSkipped) {
  // The side camera's detector throws over [0.27, 0.33) s (its frames at 0.28, 0.30 and 0.32 s,
  // in the first flight) and the rear camera's centres are NaN over [0.28, 0.34) s: each is
  // counted (injected, and what the session did about it) and the frame goes on without a
  // detection; the flights are still tracked to their board hits.
  std::vector<std::string> sets = footage_->image_sets;
  sets.push_back("faults=[{kind: detector_throw, camera: 0, from_s: 0.27, to_s: 0.33}, "
                 "{kind: detect_nan, camera: 1, from_s: 0.28, to_s: 0.34}]");
  const auto cfg = configWith(sets);
  const auto s = scenarios::runDartFootage(cfg);
  checkSession(s, cfg, 30.0);
  EXPECT_EQ(s.faults.of(runtime::FaultKind::DetectorThrow), 3u);
  EXPECT_EQ(s.faults.outcomeOf("detector_errors"), 3u);
  EXPECT_GE(s.faults.of(runtime::FaultKind::DetectNan), 1u);
  EXPECT_EQ(s.faults.outcomeOf("detections_rejected"), s.faults.of(runtime::FaultKind::DetectNan));
  const auto clean = scenarios::runDartFootage(configWith(footage_->image_sets));
  EXPECT_EQ(s.cameras[1].detections + s.faults.of(runtime::FaultKind::DetectNan), clean.cameras[1].detections);
  const nlohmann::json j = scenarios::dartFootageSummaryJson(s, cfg);
  EXPECT_EQ(j["faults"]["injected"]["detector_throw"], 3);
  EXPECT_EQ(j["faults"]["outcome"]["detector_errors"], 3);
  EXPECT_NE(scenarios::dartFootageSummaryText(s, cfg).find("faults injected"), std::string::npos);
  // Generated detections have no frames to fault: refused by name.
  const std::string e = errorOf([] { scenarios::loadDartScenario(kConfig, {"faults=[{kind: freeze, from_s: 0, to_s: 1}]"}); });
  EXPECT_NE(e.find("faults: injected on footage only"), std::string::npos) << e;
}

TEST_F(DartFootage, VideosPerCameraGiveTheSameBoardHits) {
  const auto cfg = configWith(footage_->video_sets);
  const auto s = scenarios::runDartFootage(cfg);
  checkSession(s, cfg, 30.0);
  // FFV1 is lossless: the same frames as the image sequences, so the same hits.
  const auto images = scenarios::runDartFootage(configWith(footage_->image_sets));
  ASSERT_EQ(images.tracks.size(), s.tracks.size());
  for (std::size_t k = 0; k < s.tracks.size(); ++k)
    EXPECT_EQ(images.tracks[k].board_hit->p, s.tracks[k].board_hit->p) << "track " << k;
}

TEST(DartFootageConfig, AMissingFileOrAMixedRigIsNamed) {
  const fs::path dir = fs::path(testing::TempDir()) / ("viewline_dart_nofootage_" + std::to_string(::getpid()));
  const std::string none = (dir / "side.mkv").string();
  std::vector<std::string> sets = {"cameras[0].source={kind: video, path: " + none + "}",
                                   "cameras[1].source={kind: images, pattern: " + (dir / "%04d.png").string() + "}"};
  const auto cfg = scenarios::loadDartScenario(kConfig, sets);
  const std::string e = errorOf([&] { scenarios::runDartFootage(cfg); });
  EXPECT_NE(e.find("cameras[side].source"), std::string::npos) << e;
  EXPECT_NE(e.find(none), std::string::npos) << e;
  // Footage is one session, not the experiments.
  const std::string x = errorOf([&] { scenarios::runDartExperiments(cfg, 1, 1); });
  EXPECT_NE(x.find("footage runs as one session"), std::string::npos) << x;
  // One camera with footage, the other generated: refused (two clocks).
  const std::string one = errorOf([&] { scenarios::loadDartScenario(kConfig, {sets[0]}); });
  EXPECT_NE(one.find("every camera needs footage"), std::string::npos) << one;
  // A recording is the session's source, not a camera's.
  const std::string rec =
      errorOf([&] { scenarios::loadDartScenario(kConfig, {"cameras[0].source={kind: recording, path: /tmp}"}); });
  EXPECT_NE(rec.find("cameras[].source.kind recording is not a camera's source"), std::string::npos) << rec;
}
