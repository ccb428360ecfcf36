#include <gtest/gtest.h>

#include "viewline/core/error.h"
#include "viewline/vision/color.h"
#include "viewline/vision/detection.h"

namespace viewline::vision {
namespace {

TEST(Result, HoldsValueOrFailureAndNeverMixesThem) {
  Result<Measurement> ok = Measurement{};
  EXPECT_TRUE(ok.ok());
  EXPECT_THROW(ok.failure(), core::Error);
  auto bad = Result<Measurement>::fail(FailureReason::Clipped, "touches border");
  EXPECT_FALSE(bad);
  EXPECT_EQ(bad.failure().reason, FailureReason::Clipped);
  EXPECT_THROW(bad.value(), core::Error);
  EXPECT_STREQ(toString(FailureReason::Ambiguous), "ambiguous");
}

TEST(ColorRange, WrapsThroughZeroAndValidates) {
  const ColorRange red{170, 10, 50, 255, 50, 255};
  EXPECT_TRUE(red.wraps());
  EXPECT_TRUE(red.contains(175, 100, 100));
  EXPECT_TRUE(red.contains(5, 100, 100));
  EXPECT_FALSE(red.contains(90, 100, 100));
  EXPECT_FALSE(red.contains(5, 10, 100));
  cv::Mat hsv(1, 3, CV_8UC3);
  hsv.at<cv::Vec3b>(0, 0) = {175, 100, 100};
  hsv.at<cv::Vec3b>(0, 1) = {5, 100, 100};
  hsv.at<cv::Vec3b>(0, 2) = {90, 100, 100};
  cv::Mat mask;
  thresholdColor(hsv, red, mask);
  EXPECT_EQ(mask.at<unsigned char>(0, 0), 255);
  EXPECT_EQ(mask.at<unsigned char>(0, 1), 255);
  EXPECT_EQ(mask.at<unsigned char>(0, 2), 0);
  EXPECT_THROW((ColorRange{0, 200, 0, 255, 0, 255}.validate("x")), core::InvalidInput);
  EXPECT_THROW((ColorRange{0, 20, 100, 50, 0, 255}.validate("x")), core::InvalidInput);
  try {
    ColorRange{0, 20, 0, 255, 0, 300}.validate("BallDetectorConfig.hsv");
    FAIL();
  } catch (const core::InvalidInput& e) {
    EXPECT_NE(std::string(e.what()).find("BallDetectorConfig.hsv.c2_hi"), std::string::npos);
  }
}

TEST(SquareRoi, ClipsToTheImage) {
  const cv::Rect r = squareRoi(5.0, 5.0, 10.0, cv::Size(100, 50));
  EXPECT_EQ(r.x, 0);
  EXPECT_EQ(r.y, 0);
  EXPECT_GE(r.width, 15);
  EXPECT_TRUE(squareRoi(500.0, 5.0, 10.0, cv::Size(100, 50)).empty());
  EXPECT_TRUE(touchesBorder(cv::Rect(0, 10, 5, 5), cv::Rect(0, 0, 100, 50)));
  EXPECT_FALSE(touchesBorder(cv::Rect(1, 10, 5, 5), cv::Rect(0, 0, 100, 50)));
}

}  // namespace
}  // namespace viewline::vision
