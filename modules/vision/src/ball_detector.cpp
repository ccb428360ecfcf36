#include "viewline/vision/ball_detector.h"

#include <algorithm>
#include <cmath>
#include <opencv2/imgproc.hpp>
#include <sstream>

#include "viewline/core/checks.h"
#include "viewline/core/error.h"
#include "viewline/core/frames.h"

namespace viewline::vision {

namespace {

cv::Mat ellipseKernel(int size) {
  if (size <= 1) return {};
  return cv::getStructuringElement(cv::MORPH_ELLIPSE, cv::Size(size, size));
}

void requireKernel(int size, const char* field) {
  if (size < 0 || size > 31 || (size > 1 && size % 2 == 0))
    throw core::InvalidInput(std::string("BallDetectorConfig.") + field + " = " +
                             std::to_string(size) + " must be 0, 1 or an odd size <= 31");
}

struct Candidate {
  std::size_t index = 0;
  double area = 0.0;
  double radius = 0.0;
  double roundness = 0.0;
  cv::Point2f circle_center;
  cv::Rect box;
  double score = 0.0;
};

}  // namespace

void BallDetectorConfig::validate() const {
  hsv.validate("BallDetectorConfig.hsv");
  requireKernel(open_kernel_px, "open_kernel_px");
  requireKernel(close_kernel_px, "close_kernel_px");
  core::requirePositive(min_area_px, "BallDetectorConfig.min_area_px");
  core::requireFinite(noise_area_px, "BallDetectorConfig.noise_area_px");
  if (noise_area_px < 0.0 || noise_area_px > min_area_px)
    throw core::InvalidInput("BallDetectorConfig.noise_area_px must be in [0, min_area_px]");
  if (!(min_roundness > 0.0 && min_roundness <= good_roundness && good_roundness <= 1.0))
    throw core::InvalidInput(
        "BallDetectorConfig.min_roundness/good_roundness must satisfy 0 < min <= good <= 1");
  if (!(ambiguity_ratio > 0.0 && ambiguity_ratio <= 1.0))
    throw core::InvalidInput("BallDetectorConfig.ambiguity_ratio must be in (0, 1]");
  core::requirePositive(roi_half_size_px, "BallDetectorConfig.roi_half_size_px");
  core::requirePositive(edge_noise_px, "BallDetectorConfig.edge_noise_px");
  core::requirePositive(min_sigma_px, "BallDetectorConfig.min_sigma_px");
  core::requireFinite(edge_offset_px, "BallDetectorConfig.edge_offset_px");
  if (edge_offset_px < 0.0 || edge_offset_px > 2.0)
    throw core::InvalidInput("BallDetectorConfig.edge_offset_px must be in [0, 2] px");
}

BallDetector::BallDetector(BallDetectorConfig config, std::optional<core::Camera> camera)
    : config_(std::move(config)), camera_(std::move(camera)) {
  config_.validate();
  open_kernel_ = ellipseKernel(config_.open_kernel_px);
  close_kernel_ = ellipseKernel(config_.close_kernel_px);
}

Result<BallMeasurement> BallDetector::detect(const cv::Mat& bgr, core::Timestamp stamp,
                                             const std::optional<Eigen::Vector2d>& predicted) {
  // Test first, name the failure after (the checks take std::string: a heap allocation per frame).
  if (bgr.empty() || bgr.type() != CV_8UC3) requireBgrImage(bgr, "BallDetector::detect");
  if (!std::isfinite(stamp)) core::requireFinite(stamp, "BallDetector::detect: stamp");
  const cv::Rect full(0, 0, bgr.cols, bgr.rows);
  bool cut = false;
  if (predicted && std::isfinite(predicted->x()) && std::isfinite(predicted->y())) {
    const cv::Rect roi =
        squareRoi(predicted->x(), predicted->y(), config_.roi_half_size_px, bgr.size());
    if (roi.area() > 0 && roi != full) {
      auto r = detectIn(bgr, roi, stamp, predicted, cut);
      if (r.ok() || !config_.fallback_full_frame) return r;
      // The window showed no ball, cut it, or was ambiguous: look at the whole frame.
    }
  }
  return detectIn(bgr, full, stamp, predicted, cut);
}

Result<BallMeasurement> BallDetector::detectIn(const cv::Mat& bgr, const cv::Rect& roi,
                                               core::Timestamp stamp,
                                               const std::optional<Eigen::Vector2d>& predicted,
                                               bool& cut_by_roi) {
  const cv::Rect full(0, 0, bgr.cols, bgr.rows);
  const bool is_full = roi == full;
  cv::cvtColor(bgr(roi), hsv_, cv::COLOR_BGR2HSV);
  thresholdColor(hsv_, config_.hsv, mask_);
  if (!open_kernel_.empty()) cv::morphologyEx(mask_, mask_, cv::MORPH_OPEN, open_kernel_);
  if (!close_kernel_.empty()) cv::morphologyEx(mask_, mask_, cv::MORPH_CLOSE, close_kernel_);
  cv::findContours(mask_, contours_, cv::RETR_EXTERNAL, cv::CHAIN_APPROX_NONE, roi.tl());

  // Reused between calls (per thread: the detector itself is used by one thread at a time), so
  // the steady-state path does not allocate.
  thread_local std::vector<Candidate> candidates;
  candidates.clear();
  double largest_tiny = 0.0;
  for (std::size_t i = 0; i < contours_.size(); ++i) {
    const auto& c = contours_[i];
    // Polygon through boundary pixel centres; + half the perimeter ≈ the pixel count.
    const double area = cv::contourArea(c) + 0.5 * cv::arcLength(c, true) + 1.0;
    if (area < config_.noise_area_px) continue;
    if (area < config_.min_area_px) {
      largest_tiny = std::max(largest_tiny, area);
      continue;
    }
    Candidate cand;
    cand.index = i;
    cand.area = area;
    float rho = 0.0F;
    cv::minEnclosingCircle(c, cand.circle_center, rho);
    cand.radius = static_cast<double>(rho) + config_.edge_offset_px;
    cand.roundness = std::min(1.0, area / (core::kPi * cand.radius * cand.radius));
    if (cand.roundness < config_.min_roundness) continue;
    cand.box = cv::boundingRect(c);
    cand.score = area * cand.roundness * cand.roundness;
    if (predicted) {
      const double du = static_cast<double>(cand.circle_center.x) - predicted->x();
      const double dv = static_cast<double>(cand.circle_center.y) - predicted->y();
      const double s = config_.roi_half_size_px;
      cand.score *= std::exp(-0.5 * (du * du + dv * dv) / (s * s));
    }
    candidates.push_back(cand);
  }

  // Where the search ran, for the failure messages only (built on failure: no allocation otherwise).
  const auto where = [&] {
    std::ostringstream w;
    w << (is_full ? "full frame" : "window") << " [" << roi.x << "," << roi.y << " " << roi.width << "x"
      << roi.height << "]";
    return w;
  };
  if (candidates.empty()) {
    if (largest_tiny > 0.0)
      return Result<BallMeasurement>::fail(
          FailureReason::TooSmall, "largest ball-coloured blob has " + std::to_string(largest_tiny) +
                                       " px < min_area_px in " + where().str());
    return Result<BallMeasurement>::fail(FailureReason::NotFound,
                                         "no round ball-coloured blob in " + where().str());
  }
  std::sort(candidates.begin(), candidates.end(),
            [](const Candidate& a, const Candidate& b) { return a.score > b.score; });
  const Candidate& best = candidates.front();
  if (touchesBorder(best.box, full))
    return Result<BallMeasurement>::fail(FailureReason::Clipped,
                                         "ball blob touches the image border");
  if (!is_full && touchesBorder(best.box, roi)) {
    cut_by_roi = true;
    return Result<BallMeasurement>::fail(FailureReason::Clipped,
                                         "ball blob touches the search window border");
  }
  if (candidates.size() > 1 && candidates[1].score >= config_.ambiguity_ratio * best.score)
    return Result<BallMeasurement>::fail(
        FailureReason::Ambiguous, std::to_string(candidates.size()) +
                                      " ball-like blobs score alike in " + where().str());

  const cv::Moments m = cv::moments(contours_[best.index]);
  if (!(m.m00 > 0.0))
    return Result<BallMeasurement>::fail(FailureReason::TooSmall, "degenerate ball contour");
  BallMeasurement out;
  out.stamp = stamp;
  out.blob_center = {m.m10 / m.m00, m.m01 / m.m00};
  out.pixel = out.blob_center;
  if (camera_) {
    // Image of the sphere centre: bisector of the rays through the major-axis end points.
    const Eigen::Vector2d p0(camera_->intrinsics.get_u0(), camera_->intrinsics.get_v0());
    Eigen::Vector2d e = out.blob_center - p0;
    e = e.norm() > 1e-9 ? Eigen::Vector2d(e.normalized()) : Eigen::Vector2d(1.0, 0.0);
    const Eigen::Vector2d xa = camera_->pixelToNormalized(out.blob_center + best.radius * e);
    const Eigen::Vector2d xb = camera_->pixelToNormalized(out.blob_center - best.radius * e);
    const Eigen::Vector3d axis = Eigen::Vector3d(xa.x(), xa.y(), 1.0).normalized() +
                                 Eigen::Vector3d(xb.x(), xb.y(), 1.0).normalized();
    if (axis.z() > 1e-9) out.pixel = camera_->normalizedToPixel({axis.x() / axis.z(), axis.y() / axis.z()});
  }
  out.radius_px = best.radius;
  out.circle_center = {static_cast<double>(best.circle_center.x),
                       static_cast<double>(best.circle_center.y)};
  out.area_px = best.area;
  out.roundness = best.roundness;
  out.used_roi = !is_full;
  out.quality = best.roundness >= config_.good_roundness ? Quality::Good : Quality::Degraded;
  double var = config_.edge_noise_px * config_.edge_noise_px / (core::kPi * best.radius) +
               config_.min_sigma_px * config_.min_sigma_px;
  if (out.quality == Quality::Degraded) {
    const double shift = best.radius * (1.0 - best.roundness);
    var += shift * shift;
  }
  out.pixel_covariance = Eigen::Matrix2d::Identity() * var;
  out.score = std::clamp(best.roundness, 0.0, 1.0);
  if (candidates.size() > 1) out.score *= 1.0 - candidates[1].score / best.score;
  return out;
}

}  // namespace viewline::vision
