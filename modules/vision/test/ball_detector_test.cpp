#include <gtest/gtest.h>

#include <cmath>
#include <opencv2/imgproc.hpp>

#include "synthetic.h"
#include "viewline/core/error.h"
#include "viewline/core/frames.h"
#include "viewline/vision/ball_detector.h"

namespace viewline::vision {
namespace {

core::Camera camera656() {
  core::Camera cam;
  cam.width = 656;
  cam.height = 480;
  cam.intrinsics = core::intrinsicsFromFov(core::deg2rad(60.0), 656, 480);
  return cam;  // c_M_w = identity: world = camera frame
}

const cv::Vec3b kGreen{40, 180, 40};

TEST(BallDetector, SubPixelCentreOfARenderedSphere) {
  const auto cam = camera656();
  BallDetector det({}, cam);
  core::Rng rng = core::makeRng(7);
  double sq = 0.0;
  int n = 0;
  for (int i = 0; i < 12; ++i) {
    const Eigen::Vector3d c(core::uniform(rng, -0.35, 0.35), core::uniform(rng, -0.25, 0.25),
                            core::uniform(rng, 1.0, 1.6));
    cv::Mat img = test::texturedBackground(656, 480, 100 + static_cast<unsigned>(i));
    test::renderSphere(img, cam, c, 0.025, kGreen);
    const auto truth = *cam.project(c);
    const auto r = det.detect(img, 0.02 * i);
    ASSERT_TRUE(r.ok()) << toString(r.failure().reason) << ": " << r.failure().message;
    EXPECT_EQ(r->quality, Quality::Good);
    EXPECT_DOUBLE_EQ(r->stamp, 0.02 * i);
    const double err = (r->pixel - truth).norm();
    sq += err * err;
    ++n;
    // Radius: the projected sphere's semi-major axis ≈ f r / sqrt(Z² - r²) (on axis).
    const double rho = cam.focalPx() * 0.025 / std::sqrt(c.squaredNorm() - 0.025 * 0.025);
    EXPECT_NEAR(r->radius_px, rho, 0.1 * rho + 0.6);
    EXPECT_GT(r->pixel_covariance(0, 0), 0.0);
    EXPECT_LT(r->pixel_covariance(0, 0), 0.1);
  }
  const double rms = std::sqrt(sq / n);
  EXPECT_LT(rms, 0.3) << "centre RMS error " << rms << " px";
}

TEST(BallDetector, WindowAroundPredictionGivesTheFullFrameAnswer) {
  const auto cam = camera656();
  BallDetector det({}, cam);
  cv::Mat img = test::texturedBackground(656, 480, 3);
  test::renderSphere(img, cam, {0.1, 0.05, 1.2}, 0.025, kGreen);
  const auto full = det.detect(img, 1.0);
  const auto win = det.detect(img, 1.0, Eigen::Vector2d(full->pixel.x() + 10.0, full->pixel.y() - 7.0));
  ASSERT_TRUE(full.ok());
  ASSERT_TRUE(win.ok());
  EXPECT_FALSE(full->used_roi);
  EXPECT_TRUE(win->used_roi);
  EXPECT_NEAR((full->pixel - win->pixel).norm(), 0.0, 1e-9);
  // A wrong prediction falls back to the full frame.
  const auto far = det.detect(img, 1.0, Eigen::Vector2d(20.0, 20.0));
  ASSERT_TRUE(far.ok());
  EXPECT_FALSE(far->used_roi);
  EXPECT_NEAR((far->pixel - full->pixel).norm(), 0.0, 1e-9);
}

TEST(BallDetector, ReportsWhyItFoundNothing) {
  const auto cam = camera656();
  BallDetector det({}, cam);
  cv::Mat empty = test::texturedBackground(656, 480, 4);
  auto r = det.detect(empty, 0.0);
  ASSERT_FALSE(r.ok());
  EXPECT_EQ(r.failure().reason, FailureReason::NotFound);

  // Cut by the left image border.
  cv::Mat clipped = empty.clone();
  cv::circle(clipped, cv::Point(5, 200), 20, cv::Scalar(kGreen), cv::FILLED, cv::LINE_AA);
  r = det.detect(clipped, 0.0);
  ASSERT_FALSE(r.ok());
  EXPECT_EQ(r.failure().reason, FailureReason::Clipped);

  // Tiny blob.
  cv::Mat tiny = empty.clone();
  cv::circle(tiny, cv::Point(300, 200), 1, cv::Scalar(kGreen), cv::FILLED);
  BallDetectorConfig cfg;
  cfg.open_kernel_px = 1;
  cfg.coarse_step_px = 1;  // the exhaustive search sees every pixel of the 5-pixel cross
  BallDetector det_noopen(cfg);
  r = det_noopen.detect(tiny, 0.0);
  ASSERT_FALSE(r.ok());
  EXPECT_EQ(r.failure().reason, FailureReason::TooSmall);
  // The coarse search looks for 2x2 blocks of colour; a cross holds none, so it sees no blob.
  cfg.coarse_step_px = 2;
  BallDetector det_coarse(cfg);
  r = det_coarse.detect(tiny, 0.0);
  ASSERT_FALSE(r.ok());
  EXPECT_EQ(r.failure().reason, FailureReason::NotFound);
  EXPECT_NE(r.failure().message.find("sampled every 2 px"), std::string::npos) << r.failure().message;

  // Two equal balls, no prediction: ambiguous. With a prediction: the near one.
  cv::Mat two = empty.clone();
  cv::circle(two, cv::Point(200, 200), 15, cv::Scalar(kGreen), cv::FILLED, cv::LINE_AA);
  cv::circle(two, cv::Point(450, 260), 15, cv::Scalar(kGreen), cv::FILLED, cv::LINE_AA);
  r = det.detect(two, 0.0);
  ASSERT_FALSE(r.ok());
  EXPECT_EQ(r.failure().reason, FailureReason::Ambiguous);
  BallDetector plain;
  r = plain.detect(two, 0.0, Eigen::Vector2d(452.0, 258.0));
  ASSERT_TRUE(r.ok());
  EXPECT_NEAR(r->pixel.x(), 450.0, 0.3);
  EXPECT_NEAR(r->pixel.y(), 260.0, 0.3);
}

class CoarseSearch : public ::testing::TestWithParam<double> {};  // min_area_px

TEST_P(CoarseSearch, GivesTheExhaustiveAnswerBitForBit) {
  // Balls of 1.5-30 px radius anywhere (some cut by the border, some with a second ball or a
  // smaller green patch beside them, some on a noisy image): the coarse-to-fine search (colour
  // sampled every 2nd pixel, the default) must give exactly what the exhaustive search gives, for
  // the smallest balls the scenarios accept (min_area_px 4-12).
  const auto cam = camera656();
  BallDetectorConfig exhaustive_cfg;
  exhaustive_cfg.coarse_step_px = 1;
  exhaustive_cfg.min_area_px = GetParam();
  BallDetectorConfig coarse_cfg = exhaustive_cfg;
  coarse_cfg.coarse_step_px = 2;
  BallDetector exhaustive(exhaustive_cfg, cam), coarse(coarse_cfg, cam);
  core::Rng rng = core::makeRng(11);
  int found = 0, small = 0;
  for (int i = 0; i < 100; ++i) {
    cv::Mat img = test::texturedBackground(656, 480, 500 + static_cast<unsigned>(i));
    const double radius = i % 3 == 0 ? core::uniform(rng, 1.5, 3.0) : core::uniform(rng, 3.0, 30.0);
    const cv::Point2d c(core::uniform(rng, -10.0, 666.0), core::uniform(rng, -10.0, 490.0));
    const int shift = 4;  // sub-pixel centres
    const auto fixed = [&](double v) { return static_cast<int>(std::lround(v * (1 << shift))); };
    cv::circle(img, cv::Point(fixed(c.x), fixed(c.y)), fixed(radius), cv::Scalar(kGreen), cv::FILLED, cv::LINE_AA,
               shift);
    if (i % 5 == 1)
      cv::circle(img, cv::Point(fixed(core::uniform(rng, 0.0, 656.0)), fixed(core::uniform(rng, 0.0, 480.0))),
                 fixed(core::uniform(rng, 2.0, 20.0)), cv::Scalar(kGreen), cv::FILLED, cv::LINE_AA, shift);
    if (i % 7 == 2) {
      core::Rng noise = core::makeRng(900 + static_cast<std::uint64_t>(i));
      test::addNoise(img, 6.0, noise);
    }
    const auto a = exhaustive.detect(img, 0.01 * i);
    const auto b = coarse.detect(img, 0.01 * i);
    ASSERT_EQ(a.ok(), b.ok()) << "frame " << i << ": " << (a.ok() ? b.failure().message : a.failure().message);
    if (!a.ok()) {
      EXPECT_EQ(a.failure().reason, b.failure().reason) << "frame " << i;
      continue;
    }
    ++found;
    if (radius < 3.0) ++small;
    EXPECT_EQ(a->pixel.x(), b->pixel.x()) << "frame " << i;
    EXPECT_EQ(a->pixel.y(), b->pixel.y()) << "frame " << i;
    EXPECT_EQ(a->radius_px, b->radius_px) << "frame " << i;
    EXPECT_EQ(a->area_px, b->area_px) << "frame " << i;
    EXPECT_EQ(a->pixel_covariance, b->pixel_covariance) << "frame " << i;
    EXPECT_FALSE(b->used_roi);
  }
  // The comparison covered found balls, small ones among them.
  EXPECT_GT(found, 60);  // balls found (whole, alone or clearly the best)
  EXPECT_GT(small, 10);  // of them under 3 px radius
}

INSTANTIATE_TEST_SUITE_P(BallDetector, CoarseSearch,
                         ::testing::Values(4.0, 6.0, 12.0),
                         [](const ::testing::TestParamInfo<double>& p) {
                           return "MinArea" + std::to_string(static_cast<int>(p.param));
                         });

TEST(BallDetector, HalfOccludedBallIsDegradedWithInflatedCovariance) {
  BallDetector det;
  cv::Mat img(480, 656, CV_8UC3, cv::Scalar(90, 90, 90));
  cv::circle(img, cv::Point(300, 200), 20, cv::Scalar(kGreen), cv::FILLED, cv::LINE_AA);
  const auto good = det.detect(img, 0.0);
  cv::rectangle(img, cv::Point(300, 150), cv::Point(340, 250), cv::Scalar(90, 90, 90), cv::FILLED);
  const auto half = det.detect(img, 0.0);
  ASSERT_TRUE(good.ok());
  ASSERT_TRUE(half.ok());
  EXPECT_EQ(good->quality, Quality::Good);
  EXPECT_EQ(half->quality, Quality::Degraded);
  EXPECT_GT(half->pixel_covariance(0, 0), 10.0 * good->pixel_covariance(0, 0));
  // The covariance covers the bias of the cut.
  EXPECT_LT(std::abs(half->pixel.x() - 300.0), 3.0 * std::sqrt(half->pixel_covariance(0, 0)));
}

TEST(BallDetector, RejectsBadInputNamingTheField) {
  BallDetector det;
  EXPECT_THROW(det.detect(cv::Mat(), 0.0), core::InvalidInput);
  EXPECT_THROW(det.detect(cv::Mat(10, 10, CV_8UC1), 0.0), core::InvalidInput);
  EXPECT_THROW(det.detect(cv::Mat(10, 10, CV_8UC3), std::nan("")), core::InvalidInput);
  BallDetectorConfig cfg;
  cfg.open_kernel_px = 4;
  try {
    BallDetector bad(cfg);
    FAIL();
  } catch (const core::InvalidInput& e) {
    EXPECT_NE(std::string(e.what()).find("open_kernel_px"), std::string::npos);
  }
  cfg = {};
  cfg.min_roundness = 0.9;
  cfg.good_roundness = 0.5;
  EXPECT_THROW(BallDetector{cfg}, core::InvalidInput);
  cfg = {};
  cfg.hsv.hue_lo = 200;
  EXPECT_THROW(BallDetector{cfg}, core::InvalidInput);
}

}  // namespace
}  // namespace viewline::vision

namespace viewline::vision {
namespace {

// The detector's opening and closing (morphologyStep) against OpenCV's erode, dilate and
// morphologyEx with their default border: the same mask, value for value, on blobs and noise,
// on windows smaller and larger than the kernel and at every image edge.
TEST(BallDetector, MorphologyStepIsOpenCVs) {
  cv::RNG rng(5);
  cv::Mat a, b;
  for (int k = 0; k < 120; ++k) {
    const int rows = 1 + rng.uniform(0, 70), cols = 1 + rng.uniform(0, 70);
    cv::Mat src(rows, cols, CV_8UC1);
    if (k % 3 == 0) {
      rng.fill(src, cv::RNG::UNIFORM, 0, 256);  // any values: min and max, not only masks
    } else {
      src.setTo(0);
      for (int i = 0; i < 4; ++i)
        cv::circle(src, {rng.uniform(-5, cols + 5), rng.uniform(-5, rows + 5)}, rng.uniform(1, 20), 255, -1);
      for (int i = 0; i < 30; ++i) src.at<uchar>(rng.uniform(0, rows), rng.uniform(0, cols)) ^= 255;  // speckle
    }
    const int size = 3 + 2 * (k % 4);
    const cv::Mat kernel = cv::getStructuringElement(k % 5 == 4 ? cv::MORPH_RECT : cv::MORPH_ELLIPSE, {size, size});
    for (const bool erode : {true, false}) {
      morphologyStep(src, a, kernel, erode);
      if (erode) cv::erode(src, b, kernel);
      else cv::dilate(src, b, kernel);
      ASSERT_EQ(cv::countNonZero(a != b), 0) << "case " << k << (erode ? " erode" : " dilate");
    }
    cv::Mat t, opened = src.clone(), closed = src.clone();
    morphologyStep(src, t, kernel, true);
    morphologyStep(t, opened, kernel, false);
    morphologyStep(src, t, kernel, false);
    morphologyStep(t, closed, kernel, true);
    cv::morphologyEx(src, b, cv::MORPH_OPEN, kernel);
    ASSERT_EQ(cv::countNonZero(opened != b), 0) << "case " << k << " open";
    cv::morphologyEx(src, b, cv::MORPH_CLOSE, kernel);
    ASSERT_EQ(cv::countNonZero(closed != b), 0) << "case " << k << " close";
  }
  EXPECT_THROW(morphologyStep(a, a, cv::getStructuringElement(cv::MORPH_ELLIPSE, {3, 3}), true), core::InvalidInput);
}

}  // namespace
}  // namespace viewline::vision
