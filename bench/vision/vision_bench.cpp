// Per-frame cost of each detector beside a plain OpenCV implementation of
// [M]'s steps, in the same run (SPEC §3: [M] needed 2.9 ms per frame in
// Python). Images are rendered once up front (table scene 320x240 as [M];
// ball 656x480 as [L]); a sequence of frames moves the table and the ball so
// that the tracking window of the production detectors is exercised as in a
// real loop.
//
//   build-vision/bench/vision_bench --benchmark_min_time=0.5

#include <benchmark/benchmark.h>

#include <opencv2/core/utility.hpp>
#include <opencv2/imgproc.hpp>
#include <vector>

#include "synthetic.h"
#include "viewline/core/frames.h"
#include "viewline/vision/apriltag_detector.h"
#include "viewline/vision/ball_detector.h"
#include "viewline/vision/screen_target_detector.h"
#include "viewline/vision/table_detector.h"

namespace {

using namespace viewline;

constexpr int kFrames = 24;

core::Camera tableCamera() {
  core::Camera cam;
  cam.width = 320;
  cam.height = 240;
  cam.intrinsics = core::intrinsicsFromFov(core::deg2rad(90.0), 320, 240);
  cam.c_M_w = core::lookAt({0.0, -0.32, 0.40}, {0.0, 0.0, 0.0}, {0.0, 0.0, 1.0});
  return cam;
}

core::Camera ballCamera() {
  core::Camera cam;
  cam.width = 656;
  cam.height = 480;
  cam.intrinsics = core::intrinsicsFromFov(core::deg2rad(60.0), 656, 480);
  return cam;
}

const std::vector<cv::Mat>& tableFrames() {
  static const std::vector<cv::Mat> frames = [] {
    std::vector<cv::Mat> out;
    const auto cam = tableCamera();
    for (int i = 0; i < kFrames; ++i) {
      const double s = static_cast<double>(i) / kFrames;
      Eigen::Isometry3d w_M_t = Eigen::Isometry3d::Identity();
      w_M_t.linear() = core::rotation(Eigen::Vector3d::UnitX(), core::deg2rad(6.0 * std::sin(6.28 * s))) *
                       core::rotation(Eigen::Vector3d::UnitY(), core::deg2rad(5.0 * std::cos(6.28 * s)));
      cv::Mat img = vision::test::texturedBackground(320, 240, 77);
      vision::test::renderTable(img, cam, w_M_t, 0.3, 0.02);
      vision::test::renderSphere(img, cam, w_M_t * Eigen::Vector3d(0.1 * std::cos(6.28 * s), 0.08 * std::sin(6.28 * s), 0.025),
                                 0.025, {40, 190, 40});
      out.push_back(img);
    }
    return out;
  }();
  return frames;
}

std::vector<Eigen::Vector2d>& ballTruth() {
  static std::vector<Eigen::Vector2d> truth;
  return truth;
}

const std::vector<cv::Mat>& ballFrames() {
  static const std::vector<cv::Mat> frames = [] {
    std::vector<cv::Mat> out;
    const auto cam = ballCamera();
    const cv::Mat bg = vision::test::texturedBackground(656, 480, 12);
    for (int i = 0; i < kFrames; ++i) {
      const double s = static_cast<double>(i) / kFrames;
      const Eigen::Vector3d c(0.3 * std::cos(6.28 * s), 0.2 * std::sin(6.28 * s), 1.3);
      cv::Mat img = bg.clone();
      vision::test::renderSphere(img, cam, c, 0.025, {40, 180, 40});
      out.push_back(img);
      ballTruth().push_back(*cam.project(c));
    }
    return out;
  }();
  return frames;
}

// ---- [M]'s table scene, 320x240 -------------------------------------------------------

void BM_Table_ReferenceOpenCV(benchmark::State& state) {
  const auto& frames = tableFrames();
  const auto cam = tableCamera();
  vision::TableDetectorConfig cfg;
  cfg.refine = false;
  std::size_t i = 0, ok = 0;
  for (auto _ : state) {
    const auto scene = vision::referenceTableScene(frames[i++ % frames.size()], 0.0, cam, cfg);
    ok += scene.table.ok() && scene.ball.ok();
    benchmark::DoNotOptimize(scene);
  }
  state.counters["detected"] = benchmark::Counter(static_cast<double>(ok) / static_cast<double>(i));
}
BENCHMARK(BM_Table_ReferenceOpenCV)->Unit(benchmark::kMicrosecond);

void BM_Table_Ours_MSteps(benchmark::State& state) {
  const auto& frames = tableFrames();
  vision::TableDetectorConfig cfg;
  cfg.refine = false;
  vision::TableDetector det(tableCamera(), cfg);
  std::size_t i = 0, ok = 0, roi = 0;
  for (auto _ : state) {
    const auto scene = det.detect(frames[i++ % frames.size()], 0.0);
    ok += scene.table.ok() && scene.ball.ok();
    roi += scene.table.ok() && scene.table->used_roi;
    benchmark::DoNotOptimize(scene);
  }
  state.counters["detected"] = benchmark::Counter(static_cast<double>(ok) / static_cast<double>(i));
  state.counters["in_window"] = benchmark::Counter(static_cast<double>(roi) / static_cast<double>(i));
}
BENCHMARK(BM_Table_Ours_MSteps)->Unit(benchmark::kMicrosecond);

void BM_Table_Ours_Refined(benchmark::State& state) {
  const auto& frames = tableFrames();
  vision::TableDetector det(tableCamera());
  std::size_t i = 0, ok = 0, roi = 0;
  for (auto _ : state) {
    const auto scene = det.detect(frames[i++ % frames.size()], 0.0);
    ok += scene.table.ok() && scene.ball.ok();
    roi += scene.table.ok() && scene.table->used_roi;
    benchmark::DoNotOptimize(scene);
  }
  state.counters["detected"] = benchmark::Counter(static_cast<double>(ok) / static_cast<double>(i));
  state.counters["in_window"] = benchmark::Counter(static_cast<double>(roi) / static_cast<double>(i));
}
BENCHMARK(BM_Table_Ours_Refined)->Unit(benchmark::kMicrosecond);

/// The production detector with the earlier ball outline (greenness ellipse, no sphere cone).
void BM_Table_Ours_Refined_GreennessEllipse(benchmark::State& state) {
  const auto& frames = tableFrames();
  vision::TableDetectorConfig cfg;
  cfg.ball_outline = vision::TableDetectorConfig::BallOutline::GreennessEllipse;
  vision::TableDetector det(tableCamera(), cfg);
  std::size_t i = 0, ok = 0;
  for (auto _ : state) {
    const auto scene = det.detect(frames[i++ % frames.size()], 0.0);
    ok += scene.table.ok() && scene.ball.ok();
    benchmark::DoNotOptimize(scene);
  }
  state.counters["detected"] = benchmark::Counter(static_cast<double>(ok) / static_cast<double>(i));
}
BENCHMARK(BM_Table_Ours_Refined_GreennessEllipse)->Unit(benchmark::kMicrosecond);

// ---- ball, 656x480 --------------------------------------------------------------------

/// [M]'s ball steps written plainly on the full frame: blur, HLS, threshold, open, largest
/// external contour, minEnclosingCircle.
void BM_Ball_ReferenceOpenCV(benchmark::State& state) {
  const auto& frames = ballFrames();
  const vision::TableDetectorConfig cfg;
  std::size_t i = 0, ok = 0;
  for (auto _ : state) {
    const cv::Mat& img = frames[i++ % frames.size()];
    cv::Mat blurred, hls, mask;
    cv::GaussianBlur(img, blurred, cv::Size(5, 5), 0.0);
    cv::cvtColor(blurred, hls, cv::COLOR_BGR2HLS);
    vision::thresholdColor(hls, cfg.green_hls, mask);
    cv::morphologyEx(mask, mask, cv::MORPH_OPEN, cv::getStructuringElement(cv::MORPH_ELLIPSE, cv::Size(3, 3)));
    std::vector<std::vector<cv::Point>> contours;
    cv::findContours(mask, contours, cv::RETR_EXTERNAL, cv::CHAIN_APPROX_SIMPLE);
    double best = 0.0;
    cv::Point2f c;
    float r = 0.0F;
    for (const auto& ct : contours) {
      const double a = cv::contourArea(ct);
      if (a > best) {
        best = a;
        cv::minEnclosingCircle(ct, c, r);
      }
    }
    ok += best > 0.0;
    benchmark::DoNotOptimize(c);
  }
  state.counters["detected"] = benchmark::Counter(static_cast<double>(ok) / static_cast<double>(i));
}
BENCHMARK(BM_Ball_ReferenceOpenCV)->Unit(benchmark::kMicrosecond);

void BM_Ball_Ours_FullFrame(benchmark::State& state) {
  const auto& frames = ballFrames();
  vision::BallDetector det({}, ballCamera());
  std::size_t i = 0, ok = 0;
  for (auto _ : state) {
    const auto r = det.detect(frames[i++ % frames.size()], 0.0);
    ok += r.ok();
    benchmark::DoNotOptimize(r);
  }
  state.counters["detected"] = benchmark::Counter(static_cast<double>(ok) / static_cast<double>(i));
}
BENCHMARK(BM_Ball_Ours_FullFrame)->Unit(benchmark::kMicrosecond);

void BM_Ball_Ours_Tracked(benchmark::State& state) {
  const auto& frames = ballFrames();
  const auto& truth = ballTruth();
  vision::BallDetector det({}, ballCamera());
  std::size_t i = 0, ok = 0;
  std::optional<Eigen::Vector2d> predicted;
  for (auto _ : state) {
    const std::size_t k = i++ % frames.size();
    // Prediction = last measurement moved by the true frame-to-frame motion (a filter's job).
    if (predicted && k > 0) *predicted += truth[k] - truth[k - 1];
    if (k == 0) predicted.reset();
    const auto r = det.detect(frames[k], 0.0, predicted);
    if (r.ok()) {
      ++ok;
      predicted = r->pixel;
    } else {
      predicted.reset();
    }
    benchmark::DoNotOptimize(r);
  }
  state.counters["detected"] = benchmark::Counter(static_cast<double>(ok) / static_cast<double>(i));
}
BENCHMARK(BM_Ball_Ours_Tracked)->Unit(benchmark::kMicrosecond);

// ---- [T]'s screen target, 640x480 -----------------------------------------------------

void BM_ScreenTarget_T(benchmark::State& state) {
  const cv::Mat img = vision::test::screenWithDisc(640, 480, 300.4, 200.2, 20.0);
  vision::ScreenTargetDetectorConfig cfg;
  cfg.crop_left = cfg.crop_right = 16;
  cfg.crop_top = cfg.crop_bottom = 8;
  vision::ScreenTargetDetector det(cfg);
  for (auto _ : state) {
    const auto r = det.detect(img, 0.0);
    benchmark::DoNotOptimize(r);
  }
}
BENCHMARK(BM_ScreenTarget_T)->Unit(benchmark::kMicrosecond);

// ---- AprilTag table pose, 640x480 -----------------------------------------------------

void BM_AprilTagTable(benchmark::State& state) {
  core::Camera cam;
  cam.width = 640;
  cam.height = 480;
  cam.intrinsics = core::intrinsicsFromFov(core::deg2rad(60.0), 640, 480);
  cam.c_M_w = core::lookAt({0.05, -0.30, 0.45}, {0.0, 0.0, 0.0}, {0.0, 0.0, 1.0});
  cv::Mat img(480, 640, CV_8UC3, cv::Scalar(200, 200, 200));
  std::vector<vision::TagOnTable> layout;
  for (int k = 0; k < 4; ++k) {
    vision::TagOnTable t;
    t.id = k;
    t.size_m = 0.05;
    t.t_M_tag.translation() = Eigen::Vector3d((k & 1) ? 0.1 : -0.1, (k & 2) ? 0.1 : -0.1, 0.0);
    layout.push_back(t);
    vision::test::renderTag36h11(img, cam, t.t_M_tag, t.id, t.size_m);
  }
  vision::AprilTagTableDetector det(cam, layout);
  for (auto _ : state) {
    const auto r = det.detect(img, 0.0);
    benchmark::DoNotOptimize(r);
  }
}
BENCHMARK(BM_AprilTagTable)->Unit(benchmark::kMicrosecond);

}  // namespace

int main(int argc, char** argv) {
  // One thread: per-camera detectors run one frame at a time, and the 2-core CI machine is shared.
  cv::setNumThreads(1);
  benchmark::Initialize(&argc, argv);
  if (benchmark::ReportUnrecognizedArguments(argc, argv)) return 1;
  benchmark::RunSpecifiedBenchmarks();
  benchmark::Shutdown();
  return 0;
}
