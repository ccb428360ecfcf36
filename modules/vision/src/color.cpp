#include "viewline/vision/color.h"

#include <algorithm>
#include <cmath>
#include <opencv2/imgproc.hpp>

#include "viewline/core/error.h"

namespace viewline::vision {

namespace {
void requireIn(int v, int lo, int hi, const std::string& what, const char* field) {
  if (v < lo || v > hi)
    throw core::InvalidInput(what + "." + field + " = " + std::to_string(v) + " must be in [" +
                             std::to_string(lo) + ", " + std::to_string(hi) + "]");
}
}  // namespace

void ColorRange::validate(const std::string& what) const {
  requireIn(hue_lo, 0, 179, what, "hue_lo");
  requireIn(hue_hi, 0, 179, what, "hue_hi");
  requireIn(c1_lo, 0, 255, what, "c1_lo");
  requireIn(c1_hi, 0, 255, what, "c1_hi");
  requireIn(c2_lo, 0, 255, what, "c2_lo");
  requireIn(c2_hi, 0, 255, what, "c2_hi");
  if (c1_lo > c1_hi) throw core::InvalidInput(what + ": c1_lo > c1_hi");
  if (c2_lo > c2_hi) throw core::InvalidInput(what + ": c2_lo > c2_hi");
}

void thresholdColor(const cv::Mat& hxx, const ColorRange& range, cv::Mat& mask) {
  if (!range.wraps()) {
    cv::inRange(hxx, cv::Scalar(range.hue_lo, range.c1_lo, range.c2_lo),
                cv::Scalar(range.hue_hi, range.c1_hi, range.c2_hi), mask);
    return;
  }
  cv::Mat upper;
  cv::inRange(hxx, cv::Scalar(range.hue_lo, range.c1_lo, range.c2_lo),
              cv::Scalar(179, range.c1_hi, range.c2_hi), upper);
  cv::inRange(hxx, cv::Scalar(0, range.c1_lo, range.c2_lo),
              cv::Scalar(range.hue_hi, range.c1_hi, range.c2_hi), mask);
  cv::bitwise_or(mask, upper, mask);
}

void requireBgrImage(const cv::Mat& image, const std::string& what) {
  if (image.empty()) throw core::InvalidInput(what + ": image is empty");
  if (image.type() != CV_8UC3)
    throw core::InvalidInput(what + ": image must be CV_8UC3 (BGR), got type " +
                             std::to_string(image.type()));
}

void requireGrayOrBgrImage(const cv::Mat& image, const std::string& what) {
  if (image.empty()) throw core::InvalidInput(what + ": image is empty");
  if (image.type() != CV_8UC1 && image.type() != CV_8UC3)
    throw core::InvalidInput(what + ": image must be CV_8UC1 or CV_8UC3, got type " +
                             std::to_string(image.type()));
}

cv::Rect squareRoi(double u, double v, double half_size, const cv::Size& image_size) {
  if (!std::isfinite(u) || !std::isfinite(v) || !std::isfinite(half_size)) return {};
  const double x0 = std::floor(u - half_size), y0 = std::floor(v - half_size);
  const double x1 = std::ceil(u + half_size) + 1.0, y1 = std::ceil(v + half_size) + 1.0;
  const int ix0 = static_cast<int>(std::clamp(x0, 0.0, static_cast<double>(image_size.width)));
  const int iy0 = static_cast<int>(std::clamp(y0, 0.0, static_cast<double>(image_size.height)));
  const int ix1 = static_cast<int>(std::clamp(x1, 0.0, static_cast<double>(image_size.width)));
  const int iy1 = static_cast<int>(std::clamp(y1, 0.0, static_cast<double>(image_size.height)));
  if (ix1 <= ix0 || iy1 <= iy0) return {};
  return {ix0, iy0, ix1 - ix0, iy1 - iy0};
}

}  // namespace viewline::vision
