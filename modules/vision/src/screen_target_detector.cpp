#include "viewline/vision/screen_target_detector.h"

#include <algorithm>
#include <cmath>
#include <opencv2/imgproc.hpp>

#include "viewline/core/checks.h"
#include "viewline/core/error.h"
#include "viewline/core/frames.h"
#include "viewline/vision/color.h"

namespace viewline::vision {

void ScreenTargetDetectorConfig::validate() const {
  if (crop_left < 0 || crop_top < 0 || crop_right < 0 || crop_bottom < 0)
    throw core::InvalidInput("ScreenTargetDetectorConfig.crop_*: margins must be >= 0");
  if (!(scale > 0.0 && scale <= 1.0))
    throw core::InvalidInput("ScreenTargetDetectorConfig.scale must be in (0, 1]");
  if (threshold > 255)
    throw core::InvalidInput("ScreenTargetDetectorConfig.threshold must be <= 255 (or < 0 for Otsu)");
  if (median_ksize != 1 && (median_ksize < 3 || median_ksize % 2 == 0 || median_ksize > 15))
    throw core::InvalidInput("ScreenTargetDetectorConfig.median_ksize must be 1 or odd in [3, 15]");
  core::requirePositive(min_area_px, "ScreenTargetDetectorConfig.min_area_px");
  if (!(min_fill >= 0.0 && min_fill <= 1.0))
    throw core::InvalidInput("ScreenTargetDetectorConfig.min_fill must be in [0, 1]");
  core::requirePositive(edge_noise_px, "ScreenTargetDetectorConfig.edge_noise_px");
  core::requirePositive(min_sigma_px, "ScreenTargetDetectorConfig.min_sigma_px");
}

ScreenTargetDetector::ScreenTargetDetector(ScreenTargetDetectorConfig config)
    : config_(std::move(config)) {
  config_.validate();
}

Result<ScreenTargetMeasurement> ScreenTargetDetector::detect(const cv::Mat& image,
                                                             core::Timestamp stamp) {
  requireGrayOrBgrImage(image, "ScreenTargetDetector::detect");
  core::requireFinite(stamp, "ScreenTargetDetector::detect: stamp");
  const int w = image.cols - config_.crop_left - config_.crop_right;
  const int h = image.rows - config_.crop_top - config_.crop_bottom;
  if (w < 8 || h < 8)
    throw core::InvalidInput("ScreenTargetDetectorConfig.crop_*: margins leave less than 8x8 px of a " +
                             std::to_string(image.cols) + "x" + std::to_string(image.rows) + " image");
  const cv::Rect crop(config_.crop_left, config_.crop_top, w, h);
  // 1. crop, grey
  if (image.channels() == 3)
    cv::cvtColor(image(crop), gray_, cv::COLOR_BGR2GRAY);
  else
    gray_ = image(crop);
  // 2. resize 50 %
  const double s = config_.scale;
  if (s < 1.0)
    cv::resize(gray_, small_, cv::Size(), s, s, cv::INTER_AREA);
  else
    small_ = gray_;
  // 3. binarise (target = 255)
  const int type = config_.dark_target ? cv::THRESH_BINARY_INV : cv::THRESH_BINARY;
  double level = config_.threshold;
  if (config_.threshold < 0)
    level = cv::threshold(small_, binary_, 0, 255, type | cv::THRESH_OTSU);
  else
    cv::threshold(small_, binary_, level, 255, type);
  // 4. median filter
  if (config_.median_ksize > 1)
    cv::medianBlur(binary_, filtered_, config_.median_ksize);
  else
    filtered_ = binary_;
  // 5. centroid of the binary image
  const cv::Moments m = cv::moments(filtered_, true);
  const double full_area = m.m00 / (s * s);
  if (m.m00 <= 0.0)
    return Result<ScreenTargetMeasurement>::fail(FailureReason::NotFound,
                                                 "no target pixels after binarisation");
  if (full_area < config_.min_area_px)
    return Result<ScreenTargetMeasurement>::fail(
        FailureReason::TooSmall, "target area " + std::to_string(full_area) + " px < min_area_px");
  const cv::Rect box = cv::boundingRect(filtered_);
  if (touchesBorder(box, cv::Rect(0, 0, filtered_.cols, filtered_.rows)))
    return Result<ScreenTargetMeasurement>::fail(FailureReason::Clipped,
                                                 "target touches the crop border");
  const double fill = m.m00 / static_cast<double>(box.area());
  if (fill < config_.min_fill)
    return Result<ScreenTargetMeasurement>::fail(
        FailureReason::Ambiguous,
        "foreground fills " + std::to_string(fill) + " of its bounding box: several blobs or clutter");

  const double qu = m.m10 / m.m00, qv = m.m01 / m.m00;
  ScreenTargetMeasurement out;
  out.stamp = stamp;
  out.pixel = {config_.crop_left + (qu + 0.5) / s - 0.5, config_.crop_top + (qv + 0.5) / s - 0.5};
  out.area_px = full_area;
  out.fill = fill;
  out.threshold_used = static_cast<int>(std::lround(level));
  const double radius_full = std::sqrt(full_area / core::kPi);
  const double sigma_e = config_.edge_noise_px / s;
  const double var = sigma_e * sigma_e / (core::kPi * radius_full * s) +
                     config_.min_sigma_px * config_.min_sigma_px;
  out.pixel_covariance = Eigen::Matrix2d::Identity() * var;
  out.quality = fill >= 0.7 ? Quality::Good : Quality::Degraded;
  out.score = std::clamp(fill / (core::kPi / 4.0), 0.0, 1.0);
  return out;
}

}  // namespace viewline::vision
