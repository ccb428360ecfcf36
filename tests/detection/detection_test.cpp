// Detectors against the ground truth of module sim's renders.
// The full tables are printed by bench/vision/vision_figures; these tests keep them honest.

#include <gtest/gtest.h>

#include "detection_scoring.h"

namespace viewline {
namespace {

using detection_scoring::Score;

TEST(DetectionOnSim, BallCentreRmsBelowAThirdOfAPixelAt656x480) {
  const Score s = detection_scoring::scoreBall({}, 0, 40, 1);
  std::printf("ball 656x480: %d/%d detected, %d wrong, centre RMS %.3f px\n", s.detected, s.frames, s.wrong, s.rms());
  ASSERT_GT(s.frames, 30);
  EXPECT_EQ(s.detected, s.frames);
  EXPECT_EQ(s.wrong, 0);
  EXPECT_LT(s.rms(), 0.3);
}

TEST(DetectionOnSim, TablePoseAndBallOnTableInMsScene) {
  const auto s = detection_scoring::scoreTable(30, 2);
  std::printf("table: rot RMS %.3f deg (%d/%d), trans RMS %.2f mm; ball known-r %.2f mm, unknown-r %.2f mm; "
              "AprilTag rot %.3f deg, trans %.2f mm (%d/%d)\n",
              core::rad2deg(s.rotation.rms()), s.rotation.detected, s.rotation.frames, 1e3 * s.translation.rms(),
              1e3 * s.ball_known.rms(), 1e3 * s.ball_unknown.rms(), core::rad2deg(s.tag_rotation.rms()),
              1e3 * s.tag_translation.rms(), s.tag_rotation.detected, s.tag_rotation.frames);
  EXPECT_EQ(s.rotation.detected, s.rotation.frames);
  EXPECT_LT(core::rad2deg(s.rotation.rms()), 0.5);
  EXPECT_LT(s.ball_unknown.rms(), 0.002);
  // Issue target 2 mm for both variants. Known radius: 0.50 mm here with the sphere-cone outline
  // (2.6 mm with the earlier greenness ellipse, whose outline the ball's dark limb biased by
  // -0.05 px; 1 mm is 0.016 px of apparent radius).
  EXPECT_LT(s.ball_known.rms(), 0.002);
  EXPECT_GT(s.tag_rotation.detected, s.tag_rotation.frames / 2);
}

TEST(DetectionOnSim, NeverASilentWrongBallUnderNoiseAndClutter) {
  sim::ImagingEffects fx;
  fx.noise.sigma = 15.0;
  const Score noisy = detection_scoring::scoreBall(fx, 0, 15, 3);
  EXPECT_GT(noisy.rate(), 0.9);
  EXPECT_EQ(noisy.wrong, 0);
  const Score cluttered = detection_scoring::scoreBall({}, 15, 15, 4);
  EXPECT_EQ(cluttered.wrong, 0) << "clutter must give 'ambiguous', not a wrong ball";
}

}  // namespace
}  // namespace viewline
