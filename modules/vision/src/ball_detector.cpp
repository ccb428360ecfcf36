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
  std::size_t index = 0;  // into BallDetector::kept_
  cv::Rect window;        // the window it was found in
  double area = 0.0;
  double radius = 0.0;
  double roundness = 0.0;
  cv::Point2f circle_center;
  cv::Rect box;
  double score = 0.0;
};

}  // namespace

void morphologyStep(const cv::Mat& src, cv::Mat& dst, const cv::Mat& kernel, bool erode) {
  if (src.type() != CV_8UC1 || kernel.type() != CV_8UC1 || kernel.empty() || src.data == dst.data)
    throw core::InvalidInput("morphologyStep: expected 8-bit single-channel src and kernel, dst not src");
  dst.create(src.size(), CV_8UC1);
  const int rows = src.rows, cols = src.cols;
  const uchar neutral = erode ? 255 : 0;
  for (int y = 0; y < rows; ++y) std::fill_n(dst.ptr<uchar>(y), cols, neutral);
  // dst = min (max) over the kernel's offsets of src shifted by the offset. Outside the image
  // src is the neutral value of the min (max), so only the overlapping part of each shift is
  // visited; the result is the same whatever the order of the offsets (min and max are exact).
  const int ax = kernel.cols / 2, ay = kernel.rows / 2;
  for (int ky = 0; ky < kernel.rows; ++ky)
    for (int kx = 0; kx < kernel.cols; ++kx) {
      if (kernel.at<uchar>(ky, kx) == 0) continue;
      const int dx = kx - ax, dy = ky - ay;
      const int x0 = std::max(0, -dx), x1 = std::min(cols, cols - dx);
      for (int y = std::max(0, -dy); y < std::min(rows, rows - dy); ++y) {
        uchar* d = dst.ptr<uchar>(y);
        const uchar* s = src.ptr<uchar>(y + dy);
        if (erode)
          for (int x = x0; x < x1; ++x) d[x] = std::min(d[x], s[x + dx]);
        else
          for (int x = x0; x < x1; ++x) d[x] = std::max(d[x], s[x + dx]);
      }
    }
}

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
  if (coarse_step_px < 1 || coarse_step_px > 8)
    throw core::InvalidInput("BallDetectorConfig.coarse_step_px = " + std::to_string(coarse_step_px) +
                             " must be in [1, 8] (1: colour test on every pixel)");
  if (edge_offset_px < 0.0 || edge_offset_px > 2.0)
    throw core::InvalidInput("BallDetectorConfig.edge_offset_px must be in [0, 2] px");
}

BallDetector::BallDetector(BallDetectorConfig config, std::optional<core::Camera> camera)
    : config_(std::move(config)), camera_(std::move(camera)) {
  config_.validate();
  open_kernel_ = ellipseKernel(config_.open_kernel_px);
  close_kernel_ = ellipseKernel(config_.close_kernel_px);
}

// Reused between calls (per thread: the detector itself is used by one thread at a time), so
// the steady-state path does not allocate.
thread_local std::vector<Candidate> t_candidates;

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
      windows_.assign(1, roi);
      auto r = search(bgr, windows_, false, stamp, predicted, cut);
      if (r.ok() || !config_.fallback_full_frame) return r;
      // The window showed no ball, cut it, or was ambiguous: look at the whole frame.
    }
  }
  if (config_.coarse_step_px > 1 && coarseWindows(bgr)) {
    bool cut_coarse = false;
    auto r = search(bgr, windows_, true, stamp, predicted, cut_coarse);
    if (!cut_coarse) return r;
    // A blob reached the edge of its window (larger than the samples showed): search exhaustively.
  }
  windows_.assign(1, full);
  return search(bgr, windows_, true, stamp, predicted, cut);
}

bool BallDetector::coarseWindows(const cv::Mat& bgr) {
  const int s = config_.coarse_step_px;
  const int rows = (bgr.rows + s - 1) / s, cols = (bgr.cols + s - 1) / s;
  coarse_bgr_.create(rows, cols, CV_8UC3);
  for (int r = 0; r < rows; ++r) {
    const uchar* in = bgr.ptr<uchar>(r * s);
    uchar* out = coarse_bgr_.ptr<uchar>(r);
    for (int c = 0; c < cols; ++c, in += 3 * s, out += 3) {
      out[0] = in[0];
      out[1] = in[1];
      out[2] = in[2];
    }
  }
  cv::cvtColor(coarse_bgr_, coarse_hsv_, cv::COLOR_BGR2HSV);
  thresholdColor(coarse_hsv_, config_.hsv, coarse_mask_);

  // A sample that passes is kept when it lies in an s x s block of ball-coloured pixels (its
  // neighbours within s - 1 tested in one batch): image noise passes the colour test a pixel at a
  // time and the opening removes it, while a blob that holds such a block is what the samples
  // guarantee to see.
  hits_.clear();
  for (int r = 0; r < rows; ++r) {
    const uchar* m = coarse_mask_.ptr<uchar>(r);
    for (int c = 0; c < cols; ++c)
      if (m[c]) hits_.emplace_back(c * s, r * s);
  }
  if (hits_.empty()) {
    windows_.clear();
    return true;  // nothing ball-coloured: nothing to look at
  }
  // Clutter over a quarter of the samples: the exhaustive search is cheaper.
  if (4 * hits_.size() > static_cast<std::size_t>(rows) * static_cast<std::size_t>(cols)) return false;
  const int side = 2 * s - 1;  // the neighbourhood that holds every s x s block through the sample
  const int nbhd = side * side;
  coarse_bgr_.create(1, static_cast<int>(nbhd * hits_.size()), CV_8UC3);
  {
    cv::Vec3b* out = coarse_bgr_.ptr<cv::Vec3b>(0);
    for (const cv::Point& h : hits_)
      for (int dy = 1 - s; dy < s; ++dy) {
        // Outside the image: the edge pixel (a blob there is clipped anyway).
        const cv::Vec3b* row = bgr.ptr<cv::Vec3b>(std::clamp(h.y + dy, 0, bgr.rows - 1));
        for (int dx = 1 - s; dx < s; ++dx) *out++ = row[std::clamp(h.x + dx, 0, bgr.cols - 1)];
      }
  }
  cv::cvtColor(coarse_bgr_, coarse_hsv_, cv::COLOR_BGR2HSV);
  thresholdColor(coarse_hsv_, config_.hsv, coarse_mask_);
  const auto inBlock = [&](const uchar* nb) {
    for (int by = 0; by < s; ++by)  // block's top-left at (s - 1 - bx, s - 1 - by) in the neighbourhood
      for (int bx = 0; bx < s; ++bx) {
        bool all = true;
        for (int y = 0; y < s && all; ++y)
          for (int x = 0; x < s && all; ++x) all = nb[(by + y) * side + bx + x] != 0;
        if (all) return true;
      }
    return false;
  };

  // Each kept sample claims the full-resolution window its blob can influence: the s - 1 pixels
  // up to the next sample, and the reach of the opening and closing, (k - 1) / 2 pixels each way,
  // twice each; plus one so that a whole blob never touches its window's edge.
  const int open_k = std::max(config_.open_kernel_px, 1), close_k = std::max(config_.close_kernel_px, 1);
  const int margin = (s - 1) + (open_k - 1) + (close_k - 1) + 2;
  const cv::Rect full(0, 0, bgr.cols, bgr.rows);
  // Many separate groups are clutter, where windows cost more than they save.
  constexpr std::size_t kMaxWindows = 24;
  windows_.clear();
  const uchar* nb = coarse_mask_.ptr<uchar>(0);
  for (std::size_t i = 0; i < hits_.size(); ++i, nb += nbhd) {
    if (!inBlock(nb)) continue;
    const cv::Point& h = hits_[i];
    const cv::Rect claim(h.x - margin, h.y - margin, 2 * margin + 1, 2 * margin + 1);
    bool joined = false;
    for (auto w = windows_.rbegin(); w != windows_.rend() && !joined; ++w)
      if ((*w & claim).area() > 0) {
        *w |= claim;
        joined = true;
      }
    if (!joined) {
      if (windows_.size() == kMaxWindows) return false;
      windows_.push_back(claim);
    }
  }
  // Windows grown into each other become one (a blob must be measured in one window, whole).
  for (bool merged = true; merged;) {
    merged = false;
    for (std::size_t a = 0; a < windows_.size() && !merged; ++a)
      for (std::size_t b = a + 1; b < windows_.size(); ++b)
        if ((windows_[a] & windows_[b]).area() > 0) {
          windows_[a] |= windows_[b];
          windows_.erase(windows_.begin() + static_cast<std::ptrdiff_t>(b));
          merged = true;
          break;
        }
  }
  double area = 0.0;
  for (cv::Rect& w : windows_) {
    w &= full;
    area += w.area();
  }
  return area <= 0.5 * full.area();
}

void BallDetector::collect(const cv::Mat& bgr, const cv::Rect& window,
                           const std::optional<Eigen::Vector2d>& predicted) {
  cv::cvtColor(bgr(window), hsv_, cv::COLOR_BGR2HSV);
  thresholdColor(hsv_, config_.hsv, mask_);
  // cv::morphologyEx's opening (erode, dilate) and closing (dilate, erode), step by step on the
  // detector's buffers (the same values: vision_test BallDetector.MorphologyStepIsOpenCVs).
  if (!open_kernel_.empty()) {
    morphologyStep(mask_, morph_, open_kernel_, true);
    morphologyStep(morph_, mask_, open_kernel_, false);
  }
  if (!close_kernel_.empty()) {
    morphologyStep(mask_, morph_, close_kernel_, false);
    morphologyStep(morph_, mask_, close_kernel_, true);
  }
  cv::findContours(mask_, contours_, cv::RETR_EXTERNAL, cv::CHAIN_APPROX_NONE, window.tl());

  for (const auto& c : contours_) {
    // Polygon through boundary pixel centres; + half the perimeter ≈ the pixel count.
    const double area = cv::contourArea(c) + 0.5 * cv::arcLength(c, true) + 1.0;
    if (area < config_.noise_area_px) continue;
    if (area < config_.min_area_px) {
      largest_tiny_ = std::max(largest_tiny_, area);
      continue;
    }
    Candidate cand;
    cand.window = window;
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
    if (kept_count_ == kept_.size()) kept_.emplace_back();
    kept_[kept_count_].assign(c.begin(), c.end());
    cand.index = kept_count_++;
    t_candidates.push_back(cand);
  }
}

Result<BallMeasurement> BallDetector::search(const cv::Mat& bgr, const std::vector<cv::Rect>& windows,
                                             bool whole_frame, core::Timestamp stamp,
                                             const std::optional<Eigen::Vector2d>& predicted,
                                             bool& cut_by_window) {
  const cv::Rect full(0, 0, bgr.cols, bgr.rows);
  std::vector<Candidate>& candidates = t_candidates;
  candidates.clear();
  kept_count_ = 0;
  largest_tiny_ = 0.0;
  for (const cv::Rect& w : windows) collect(bgr, w, predicted);
  const double largest_tiny = largest_tiny_;
  const bool coarse = whole_frame && !(windows.size() == 1 && windows.front() == full);

  // Where the search ran, for the failure messages only (built on failure: no allocation otherwise).
  const auto where = [&] {
    std::ostringstream w;
    if (!whole_frame) {
      const cv::Rect& roi = windows.front();
      w << "window [" << roi.x << "," << roi.y << " " << roi.width << "x" << roi.height << "]";
    } else if (coarse) {
      w << "full frame (colour sampled every " << config_.coarse_step_px << " px, " << windows.size()
        << " window(s) searched)";
    } else {
      w << "full frame [0,0 " << full.width << "x" << full.height << "]";
    }
    return w;
  };
  if (coarse) {
    // A blob that reaches the edge of its window may be larger than the window: not measured whole.
    for (const Candidate& c : candidates)
      if (touchesBorder(c.box, c.window) && !touchesBorder(c.box, full)) {
        cut_by_window = true;
        return Result<BallMeasurement>::fail(FailureReason::Clipped, "ball blob touches a search window border");
      }
  }
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
  if (!whole_frame && touchesBorder(best.box, best.window)) {
    cut_by_window = true;
    return Result<BallMeasurement>::fail(FailureReason::Clipped,
                                         "ball blob touches the search window border");
  }
  if (candidates.size() > 1 && candidates[1].score >= config_.ambiguity_ratio * best.score)
    return Result<BallMeasurement>::fail(
        FailureReason::Ambiguous, std::to_string(candidates.size()) +
                                      " ball-like blobs score alike in " + where().str());

  const cv::Moments m = cv::moments(kept_[best.index]);
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
  out.used_roi = !whole_frame;
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
