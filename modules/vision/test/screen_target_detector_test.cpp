#include <gtest/gtest.h>

#include <cmath>
#include <opencv2/imgproc.hpp>

#include "synthetic.h"
#include "viewline/core/error.h"
#include "viewline/vision/screen_target_detector.h"

namespace viewline::vision {
namespace {

TEST(ScreenTargetDetector, CentroidInFullResolutionCoordinates) {
  ScreenTargetDetectorConfig cfg;
  cfg.crop_left = 40;
  cfg.crop_right = 24;
  cfg.crop_top = 16;
  cfg.crop_bottom = 8;
  ScreenTargetDetector det(cfg);
  core::Rng rng = core::makeRng(11);
  double sq = 0.0;
  for (int i = 0; i < 10; ++i) {
    const double u = core::uniform(rng, 120.0, 520.0), v = core::uniform(rng, 100.0, 380.0);
    cv::Mat img = test::screenWithDisc(640, 480, u, v, 18.0);
    const auto r = det.detect(img, 0.1 * i);
    ASSERT_TRUE(r.ok()) << r.failure().message;
    sq += (r->pixel - Eigen::Vector2d(u, v)).squaredNorm();
    EXPECT_NEAR(r->area_px, 3.14159 * 18.0 * 18.0, 60.0);
    EXPECT_EQ(r->quality, Quality::Good);
  }
  EXPECT_LT(std::sqrt(sq / 10.0), 0.25);
}

TEST(ScreenTargetDetector, WorksWithNoiseAndBgrInput) {
  ScreenTargetDetector det;
  cv::Mat gray = test::screenWithDisc(640, 480, 301.3, 222.7, 25.0);
  cv::Mat bgr;
  cv::cvtColor(gray, bgr, cv::COLOR_GRAY2BGR);
  core::Rng rng = core::makeRng(2);
  test::addNoise(bgr, 20.0, rng);
  const auto r = det.detect(bgr, 3.0);
  ASSERT_TRUE(r.ok());
  EXPECT_NEAR(r->pixel.x(), 301.3, 0.4);
  EXPECT_NEAR(r->pixel.y(), 222.7, 0.4);
  EXPECT_DOUBLE_EQ(r->stamp, 3.0);
}

TEST(ScreenTargetDetector, ReportsFailures) {
  ScreenTargetDetectorConfig cfg;
  cfg.threshold = 100;
  ScreenTargetDetector det(cfg);
  cv::Mat blank(480, 640, CV_8UC1, cv::Scalar(220));
  auto r = det.detect(blank, 0.0);
  ASSERT_FALSE(r.ok());
  EXPECT_EQ(r.failure().reason, FailureReason::NotFound);
  r = det.detect(test::screenWithDisc(640, 480, 5.0, 240.0, 20.0), 0.0);
  ASSERT_FALSE(r.ok());
  EXPECT_EQ(r.failure().reason, FailureReason::Clipped);
  r = det.detect(test::screenWithDisc(640, 480, 300.0, 240.0, 2.0), 0.0);
  ASSERT_FALSE(r.ok());
  EXPECT_TRUE(r.failure().reason == FailureReason::TooSmall || r.failure().reason == FailureReason::NotFound);
  cv::Mat two = test::screenWithDisc(640, 480, 200.0, 240.0, 20.0);
  cv::circle(two, cv::Point(450, 120), 20, cv::Scalar(30), cv::FILLED);
  r = det.detect(two, 0.0);
  ASSERT_FALSE(r.ok());
  EXPECT_EQ(r.failure().reason, FailureReason::Ambiguous);
}

TEST(ScreenTargetDetector, RejectsBadConfigAndImages) {
  ScreenTargetDetectorConfig cfg;
  cfg.median_ksize = 4;
  EXPECT_THROW(ScreenTargetDetector{cfg}, core::InvalidInput);
  cfg = {};
  cfg.scale = 0.0;
  EXPECT_THROW(ScreenTargetDetector{cfg}, core::InvalidInput);
  cfg = {};
  cfg.crop_left = 400;
  cfg.crop_right = 300;
  ScreenTargetDetector det(cfg);
  EXPECT_THROW(det.detect(cv::Mat(480, 640, CV_8UC1, cv::Scalar(0)), 0.0), core::InvalidInput);
  ScreenTargetDetector ok;
  EXPECT_THROW(ok.detect(cv::Mat(), 0.0), core::InvalidInput);
  EXPECT_THROW(ok.detect(cv::Mat(10, 10, CV_32FC1), 0.0), core::InvalidInput);
}

}  // namespace
}  // namespace viewline::vision
