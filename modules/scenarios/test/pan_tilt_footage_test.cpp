// Real footage through the pan-tilt perception: ViSP's mire-2 sequence (501 real 384x288 frames
// of a target with a large white disc, visp-images-data), read by runtime::ImageSequenceSource,
// tracked by [T]'s detector in a window placed by the pan-tilt target filter
// (pan_tilt::FootageTracker), compared with ViSP's own blob tracker vpDot2 on the same frames.
#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>
#include <filesystem>
#include <visp3/blob/vpDot2.h>
#include <visp3/core/vpImageConvert.h>

#include "viewline/runtime/file_sources.h"
#include "viewline/scenarios/pan_tilt/footage.h"

using namespace viewline;

namespace {

const std::string kMire = "/usr/share/visp-images-data/ViSP-images/mire-2/image.%04d.pgm";

}  // namespace

TEST(PanTiltFootage, TracksTheMire2DiscLikeVpDot2OnEveryFrame) {
  if (!std::filesystem::exists(runtime::formatFramePattern(kMire, 1))) GTEST_SKIP() << "visp-images-data not installed";
  runtime::ImageSequenceSource source({kMire, 1, 25.0, "", -1});
  scenarios::pan_tilt::FootageTracker tracker(scenarios::pan_tilt::brightDiscTrackerConfig({160.0, 212.0}));

  vpDot2 dot;
  dot.setGraphics(false);
  vpImage<unsigned char> I;
  std::size_t frames = 0, lost = 0, predicted = 0;
  double sum_d2 = 0.0, sum_pred2 = 0.0, sum_hold2 = 0.0, max_d = 0.0;
  bool has_previous = false;
  Eigen::Vector2d previous = Eigen::Vector2d::Zero();
  while (source.nextReadyTime()) {
    const auto frame = source.grab();
    ASSERT_TRUE(frame);
    vpImageConvert::convert(frame->image, I);
    if (frames == 0) dot.initTracking(I, vpImagePoint(212, 160));  // (v, u): a click on the disc
    else dot.track(I);
    const auto step = tracker.track(*frame);
    ++frames;
    if (!step.detected) {
      ++lost;
      has_previous = false;
      continue;
    }
    const Eigen::Vector2d cog(dot.getCog().get_u(), dot.getCog().get_v());
    const double d = (step.measured_px - cog).norm();
    sum_d2 += d * d;
    max_d = std::max(max_d, d);
    if (step.has_prediction && has_previous) {
      sum_pred2 += (step.predicted_px - step.measured_px).squaredNorm();
      sum_hold2 += (previous - step.measured_px).squaredNorm();
      ++predicted;
    }
    previous = step.measured_px;
    has_previous = true;
  }
  const double rms = std::sqrt(sum_d2 / static_cast<double>(frames - lost));
  const double pred = std::sqrt(sum_pred2 / static_cast<double>(predicted));
  const double hold = std::sqrt(sum_hold2 / static_cast<double>(predicted));
  std::printf("mire-2: %zu frames, %zu lost; detector vs vpDot2 rms %.3f px (max %.3f); one frame ahead rms: "
              "filter %.3f px, hold-last %.3f px, ratio %.3f\n",
              frames, lost, rms, max_d, pred, hold, pred / hold);
  EXPECT_EQ(frames, 501u);
  EXPECT_EQ(lost, 0u);
  EXPECT_LE(rms, 0.5);
  EXPECT_EQ(predicted, 500u);
  // Hand-held motion at 25 Hz: a constant-velocity prediction is only about as good as holding
  // the last position (docs/results.md, "Real footage"); it must not be worse.
  EXPECT_LE(pred, hold);
  EXPECT_GT(pred, 0.5 * hold);  // a prediction this good would mean the error is not measured
}
