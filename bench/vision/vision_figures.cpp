// Prints the detector figures against module sim's ground truth:
//   - ball centre RMS at 656x480 (unoccluded),
//   - [M]'s scene: table rotation/translation RMS, ball on the table (known and unknown radius),
//     AprilTag table pose beside it,
//   - robustness table: ball detection rate, wrong detections and RMS under each imaging effect.
//
//   build-vision/bench/vision_figures [frames_per_case=100] [seed=1]

#include <cstdio>
#include <cstdlib>
#include <opencv2/core/utility.hpp>

#include "detection_scoring.h"

int main(int argc, char** argv) {
  using namespace viewline;
  cv::setNumThreads(1);
  const int n = argc > 1 ? std::atoi(argv[1]) : 100;
  const std::uint64_t seed = argc > 2 ? std::strtoull(argv[2], nullptr, 10) : 1;
  if (n < 5) {
    std::fprintf(stderr, "frames_per_case must be >= 5\n");
    return 2;
  }
  const auto ball = detection_scoring::scoreBall({}, 0, n, seed);
  std::printf("## Ball centre, 656x480, unoccluded (%d frames)\n", ball.frames);
  std::printf("detected %d/%d, wrong %d, centre RMS %.3f px (target <= 0.3)\n\n", ball.detected, ball.frames, ball.wrong,
              ball.rms());

  using Outline = vision::TableDetectorConfig::BallOutline;
  const struct {
    bool refine;
    Outline outline;
    const char* name;
  } variants[] = {{true, Outline::SphereCone, "production (sub-pixel, borders; ball: sphere cone on unmixed outline)"},
                  {true, Outline::GreennessEllipse, "production with the earlier ball outline (greenness ellipse)"},
                  {false, Outline::SphereCone, "[M]'s steps exactly"}};
  for (const auto& v : variants) {
    const auto t = detection_scoring::scoreTable(n, seed + 1, v.refine, v.outline);
    std::printf("## [M]'s table scene, 320x240, %s (%d frames)\n", v.name, t.rotation.frames);
    std::printf("| quantity | RMS | detected |\n|---|---|---|\n");
    std::printf("| table rotation | %.3f deg | %d/%d |\n", core::rad2deg(t.rotation.rms()), t.rotation.detected, t.rotation.frames);
    std::printf("| table translation | %.2f mm | |\n", 1e3 * t.translation.rms());
    std::printf("| ball on table, known radius | %.2f mm | %d/%d |\n", 1e3 * t.ball_known.rms(), t.ball_known.detected, t.ball_known.frames);
    std::printf("| ball on table, unknown radius | %.2f mm | %d/%d |\n", 1e3 * t.ball_unknown.rms(), t.ball_unknown.detected, t.ball_unknown.frames);
    std::printf("| AprilTag table rotation | %.3f deg | %d/%d |\n", core::rad2deg(t.tag_rotation.rms()), t.tag_rotation.detected, t.tag_rotation.frames);
    std::printf("| AprilTag table translation | %.2f mm | |\n\n", 1e3 * t.tag_translation.rms());
  }

  std::printf("## Robustness: ball detector, 656x480, ball at 0.9 m/s, %d frames per case\n", n);
  std::printf("| effect | strength | detection rate | wrong (> max(3 px, 3 sigma)) | centre RMS of the rest (px) |\n|---|---|---|---|---|\n");
  std::uint64_t k = 0;
  for (const auto& c : detection_scoring::robustnessCases()) {
    const auto s = detection_scoring::scoreBall(c.effects, c.clutter, n, seed + 10 + k++);
    std::printf("| %s | %s | %.1f %% | %d | %.3f |\n", c.effect.c_str(), c.strength.c_str(), 100.0 * s.rate(), s.wrong, s.rms());
  }
  return 0;
}
