#include <gtest/gtest.h>

#include <cmath>
#include <cstdint>
#include <vector>
#include <opencv2/imgproc.hpp>

#include "synthetic.h"
#include "viewline/core/error.h"
#include "viewline/core/frames.h"
#include "viewline/vision/color.h"
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

// The filter and moments as OpenCV computes them: what medianBlobMoments must equal bit for bit.
BinaryBlobMoments openCvBlobMoments(const cv::Mat& binary, int ksize) {
  cv::Mat filtered = binary;
  if (ksize > 1) cv::medianBlur(binary, filtered, ksize);
  const cv::Moments m = cv::moments(filtered, true);
  BinaryBlobMoments out;
  out.m00 = m.m00;
  out.m10 = m.m10;
  out.m01 = m.m01;
  out.box = cv::boundingRect(filtered);
  return out;
}

void expectSameMoments(const BinaryBlobMoments& a, const BinaryBlobMoments& b, const std::string& what) {
  // == on doubles: equal to the last bit (all values are >= +0).
  EXPECT_EQ(a.m00, b.m00) << what;
  EXPECT_EQ(a.m10, b.m10) << what;
  EXPECT_EQ(a.m01, b.m01) << what;
  if (b.m00 > 0.0) {
    EXPECT_EQ(a.box, b.box) << what;
  }
}

TEST(ScreenTargetDetector, BlobMomentsEqualOpenCvOnRandomBinaryImages) {
  // Scattered noise at several densities, and discs (some cut by the border) with flipped pixels, on
  // image sizes that are and are not multiples of cv::moments' 32-px tiles, for every aperture.
  core::Rng rng = core::makeRng(5);
  std::vector<std::int32_t> scratch;
  int compared = 0, inexact = 0;
  for (const cv::Size size : {cv::Size(312, 232), cv::Size(45, 37), cv::Size(64, 64), cv::Size(33, 95), cv::Size(4, 6)}) {
    for (const double density : {0.0, 0.0005, 0.01, 0.2, 0.5, 0.9}) {
      for (const bool disc : {false, true}) {
        cv::Mat bin(size, CV_8UC1, cv::Scalar(0));
        if (disc) {
          const cv::Point c(static_cast<int>(core::uniform(rng, -5.0, size.width + 5.0)),
                            static_cast<int>(core::uniform(rng, -5.0, size.height + 5.0)));
          cv::circle(bin, c, static_cast<int>(core::uniform(rng, 2.0, 30.0)), cv::Scalar(255), cv::FILLED);
        }
        for (int y = 0; y < size.height; ++y)
          for (int x = 0; x < size.width; ++x)
            if (core::uniform(rng, 0.0, 1.0) < density) bin.at<std::uint8_t>(y, x) ^= 255;
        for (const int k : {1, 3, 5, 7, 9}) {
          const BinaryBlobMoments ours = medianBlobMoments(bin, k, scratch);
          const BinaryBlobMoments ref = openCvBlobMoments(bin, k);
          expectSameMoments(ours, ref, std::to_string(size.width) + "x" + std::to_string(size.height) + " density " +
                                           std::to_string(density) + (disc ? " disc" : "") + " k " + std::to_string(k));
          ++compared;
          // cv::moments' 1/255 scaling is not exact: the integer sums would differ from its m10 in places.
          double sx = 0.0;
          cv::Mat f = bin;
          if (k > 1) cv::medianBlur(bin, f, k);
          for (int y = 0; y < f.rows; ++y)
            for (int x = 0; x < f.cols; ++x)
              if (f.at<std::uint8_t>(y, x) != 0) sx += x;
          inexact += sx != ref.m10;
        }
      }
    }
  }
  EXPECT_EQ(compared, 5 * 6 * 2 * 5);
  EXPECT_GT(inexact, 0);  // so the test would catch a kernel that summed exactly
}

TEST(ScreenTargetDetector, HalfScaleBinaryEqualsOpenCvAtEveryLevel) {
  // Uniform noise (every block computed exactly) and bright frames with dark specks and a disc (most
  // blocks skipped), grey and BGR, as a cropped view (rows not contiguous) and whole, at every level:
  // equal binaries at all 256 levels mean equal half-resolution grey images.
  core::Rng rng = core::makeRng(6);
  cv::Mat expected, ours, g, small;
  int levels = 0;
  for (const int channels : {1, 3}) {
    for (const bool bright : {false, true}) {
      cv::Mat frame(102, 140, CV_8UC(channels));
      cv::randu(frame, bright ? 150 : 0, 256);
      if (bright) {
        for (int k = 0; k < 40; ++k)
          frame.at<std::uint8_t>(static_cast<int>(core::uniform(rng, 0.0, 102.0)),
                                 static_cast<int>(core::uniform(rng, 0.0, 140.0 * channels))) =
              static_cast<std::uint8_t>(core::uniform(rng, 0.0, 256.0));
        cv::circle(frame, cv::Point(60, 50), 17, cv::Scalar::all(40), cv::FILLED);
      }
      for (const cv::Rect roi : {cv::Rect(0, 0, 140, 102), cv::Rect(6, 4, 50, 38)}) {
        const cv::Mat view = frame(roi);
        if (channels == 3)
          cv::cvtColor(view, g, cv::COLOR_BGR2GRAY);
        else
          g = view;
        cv::resize(g, small, cv::Size(), 0.5, 0.5, cv::INTER_AREA);
        for (int level = 0; level <= 255; ++level) {
          for (const bool dark : {true, false}) {
            cv::threshold(small, expected, level, 255, dark ? cv::THRESH_BINARY_INV : cv::THRESH_BINARY);
            halfScaleBinary(view, level, dark, ours);
            ASSERT_EQ(ours.size(), expected.size());
            ASSERT_EQ(cv::countNonZero(ours != expected), 0)
                << channels << " channels, bright " << bright << ", roi " << roi << ", level " << level << ", dark " << dark;
          }
          ++levels;
        }
      }
    }
  }
  EXPECT_EQ(levels, 2 * 2 * 2 * 256);
  EXPECT_THROW(halfScaleBinary(cv::Mat(11, 10, CV_8UC1), 100, true, ours), core::InvalidInput);
}

TEST(ScreenTargetDetector, DetectionEqualsOpenCvPipelineOnRenderedFrames) {
  // The whole detector against [T]'s pipeline written with OpenCV calls (crop, grey, INTER_AREA 50 %,
  // threshold, cv::medianBlur, cv::moments, cv::boundingRect) on noisy BGR discs, fixed and Otsu levels.
  core::Rng rng = core::makeRng(8);
  int detected = 0;
  for (const int threshold : {110, -1}) {
    ScreenTargetDetectorConfig cfg;
    cfg.crop_left = cfg.crop_top = cfg.crop_right = cfg.crop_bottom = 8;
    cfg.threshold = threshold;
    cfg.min_area_px = 200;
    ScreenTargetDetector det(cfg);
    for (int i = 0; i < 8; ++i) {
      const double u = core::uniform(rng, 20.0, 620.0), v = core::uniform(rng, 20.0, 460.0);
      cv::Mat gray = test::screenWithDisc(640, 480, u, v, core::uniform(rng, 6.0, 40.0));
      cv::Mat bgr;
      cv::cvtColor(gray, bgr, cv::COLOR_GRAY2BGR);
      test::addNoise(bgr, core::uniform(rng, 0.0, 40.0), rng);
      cv::Mat g, small, bin, filtered;
      cv::cvtColor(bgr(cv::Rect(8, 8, 624, 464)), g, cv::COLOR_BGR2GRAY);
      cv::resize(g, small, cv::Size(), 0.5, 0.5, cv::INTER_AREA);
      if (threshold < 0)
        cv::threshold(small, bin, 0, 255, cv::THRESH_BINARY_INV | cv::THRESH_OTSU);
      else
        cv::threshold(small, bin, threshold, 255, cv::THRESH_BINARY_INV);
      cv::medianBlur(bin, filtered, 5);
      const cv::Moments m = cv::moments(filtered, true);
      const auto r = det.detect(bgr, 0.0);
      if (!r.ok()) {
        EXPECT_TRUE(m.m00 / 0.25 < cfg.min_area_px || touchesBorder(cv::boundingRect(filtered), cv::Rect(0, 0, 312, 232)) ||
                    m.m00 / cv::boundingRect(filtered).area() < cfg.min_fill)
            << r.failure().message;
        continue;
      }
      const double qu = m.m10 / m.m00, qv = m.m01 / m.m00;
      EXPECT_EQ(r->pixel.x(), 8 + (qu + 0.5) / 0.5 - 0.5) << i;
      EXPECT_EQ(r->pixel.y(), 8 + (qv + 0.5) / 0.5 - 0.5) << i;
      EXPECT_EQ(r->area_px, m.m00 / 0.25);
      EXPECT_EQ(r->fill, m.m00 / static_cast<double>(cv::boundingRect(filtered).area()));
      ++detected;
    }
  }
  EXPECT_GE(detected, 10);  // most discs lie inside the crop
}

TEST(ScreenTargetDetector, WindowEqualsFullFrameBitForBit) {
  // The window pass against the full frame on noisy grey and BGR discs, predictions near and far from the
  // disc (in the window, cut by its edge, elsewhere, off the image): every result equal to the last bit,
  // and the window used whenever the disc lies inside it.
  core::Rng rng = core::makeRng(23);
  ScreenTargetDetectorConfig cfg;
  cfg.crop_left = cfg.crop_top = cfg.crop_right = cfg.crop_bottom = 8;
  cfg.threshold = 110;
  cfg.min_area_px = 200;
  ScreenTargetDetector windowed(cfg), full(cfg);
  int in_window = 0, fell_back = 0, compared = 0;
  for (int i = 0; i < 60; ++i) {
    const double u = core::uniform(rng, 10.0, 630.0), v = core::uniform(rng, 10.0, 470.0);
    const double radius = core::uniform(rng, 6.0, 40.0);
    cv::Mat img = test::screenWithDisc(640, 480, u, v, radius);
    if (i % 2 == 1) {
      cv::Mat bgr;
      cv::cvtColor(img, bgr, cv::COLOR_GRAY2BGR);
      img = bgr;
    }
    test::addNoise(img, core::uniform(rng, 0.0, 30.0), rng);
    const auto ref = full.detect(img, 0.5);
    for (const double off : {0.0, 3.0, 20.0, 55.0, 90.0, 400.0, 2000.0}) {
      const double a = core::uniform(rng, 0.0, 2.0 * core::kPi);
      const Eigen::Vector2d predicted(u + off * std::cos(a), v + off * std::sin(a));
      const auto r = windowed.detect(img, 0.5, predicted);
      ++compared;
      ASSERT_EQ(r.ok(), ref.ok()) << i << " " << off;
      if (!ref.ok()) {
        EXPECT_EQ(r.failure().reason, ref.failure().reason);
        EXPECT_FALSE(windowed.usedWindow());
        continue;
      }
      EXPECT_EQ(r->pixel.x(), ref->pixel.x()) << i << " " << off;
      EXPECT_EQ(r->pixel.y(), ref->pixel.y()) << i << " " << off;
      EXPECT_EQ(r->area_px, ref->area_px);
      EXPECT_EQ(r->fill, ref->fill);
      EXPECT_EQ(r->pixel_covariance, ref->pixel_covariance);
      EXPECT_EQ(r->score, ref->score);
      EXPECT_EQ(r->quality, ref->quality);
      EXPECT_EQ(r->threshold_used, ref->threshold_used);
      // A disc well inside the window (its radius + 2 px margin from the predicted pixel's window edge) uses it.
      if (off + radius + 6.0 < cfg.window_half_size_px) {
        EXPECT_TRUE(windowed.usedWindow()) << i << " " << off;
      }
      (windowed.usedWindow() ? in_window : fell_back) += 1;
    }
  }
  EXPECT_EQ(compared, 60 * 7);
  EXPECT_GE(in_window, 80);
  EXPECT_GE(fell_back, 80);
}

TEST(ScreenTargetDetector, WindowIgnoresOnlyForegroundWhollyOutsideIt) {
  // A second dark disc far from the prediction: the full frame sees two blobs (Ambiguous); the window sees
  // the predicted one alone. A disc cut by the window's edge makes it fall back to the full frame.
  ScreenTargetDetectorConfig cfg;
  cfg.threshold = 110;
  cv::Mat img = test::screenWithDisc(640, 480, 200.0, 200.0, 20.0);
  cv::Mat other = test::screenWithDisc(640, 480, 480.0, 300.0, 20.0);
  cv::min(img, other, img);
  ScreenTargetDetector det(cfg);
  const auto full = det.detect(img, 0.0);
  ASSERT_FALSE(full.ok());
  EXPECT_EQ(full.failure().reason, FailureReason::Ambiguous);
  const auto near = det.detect(img, 0.0, Eigen::Vector2d(205.0, 195.0));
  ASSERT_TRUE(near.ok());
  EXPECT_TRUE(det.usedWindow());
  EXPECT_NEAR(near->pixel.x(), 200.0, 0.3);
  const auto cut = det.detect(img, 0.0, Eigen::Vector2d(200.0 + 64.0, 200.0));  // the disc crosses the window's edge
  EXPECT_FALSE(det.usedWindow());
  ASSERT_FALSE(cut.ok());
  EXPECT_EQ(cut.failure().reason, FailureReason::Ambiguous);
  cfg.window_half_size_px = -1;
  EXPECT_THROW(ScreenTargetDetector{cfg}, core::InvalidInput);
}

TEST(ScreenTargetDetector, BlobMomentsInARoiEqualTheWholeImage) {
  // medianBlobMoments told where the foreground lies gives the whole image's moments bit for bit.
  core::Rng rng = core::makeRng(31);
  std::vector<std::int32_t> scratch;
  for (int i = 0; i < 40; ++i) {
    cv::Mat bin(240, 320, CV_8UC1, cv::Scalar(0));
    const cv::Rect roi(static_cast<int>(core::uniform(rng, 0.0, 250.0)), static_cast<int>(core::uniform(rng, 0.0, 170.0)),
                       static_cast<int>(core::uniform(rng, 10.0, 70.0)), static_cast<int>(core::uniform(rng, 10.0, 70.0)));
    cv::Mat part = bin(roi);
    for (int y = 0; y < part.rows; ++y)
      for (int x = 0; x < part.cols; ++x) part.at<std::uint8_t>(y, x) = core::uniform(rng, 0.0, 1.0) < 0.6 ? 255 : 0;
    for (const int k : {1, 3, 5}) {
      const BinaryBlobMoments whole = medianBlobMoments(bin, k, scratch);
      const BinaryBlobMoments in_roi = medianBlobMoments(bin, k, scratch, roi);
      EXPECT_EQ(in_roi.m00, whole.m00);
      EXPECT_EQ(in_roi.m10, whole.m10);
      EXPECT_EQ(in_roi.m01, whole.m01);
      EXPECT_EQ(in_roi.box, whole.box);
    }
  }
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
