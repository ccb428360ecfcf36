#include "viewline/scenarios/pan_tilt/footage.h"

#include <algorithm>
#include <cmath>
#include <opencv2/imgproc.hpp>
#include <visp3/blob/vpDot2.h>
#include <visp3/core/vpImageConvert.h>
#include <utility>

#include "viewline/core/error.h"

namespace viewline::scenarios::pan_tilt {

void FootageTrackerConfig::validate() const {
  detector.validate();
  filter.validate();
  if (!(initial_half_size.minCoeff() >= 4.0)) throw core::InvalidInput("FootageTrackerConfig.initial_half_size must be >= 4 px");
  if (!(window_growth >= 1.0)) throw core::InvalidInput("FootageTrackerConfig.window_growth must be >= 1");
  if (!(window_margin_px >= 0.0)) throw core::InvalidInput("FootageTrackerConfig.window_margin_px must be >= 0");
  if (max_retries < 0) throw core::InvalidInput("FootageTrackerConfig.max_retries must be >= 0");
}

FootageTrackerConfig brightDiscTrackerConfig(const Eigen::Vector2d& initial_px) {
  FootageTrackerConfig c;
  c.detector.scale = 1.0;  // sub-pixel centres: no half-resolution step on a small real image
  c.detector.dark_target = false;
  c.detector.threshold = -1;
  c.detector.median_ksize = 3;
  c.detector.min_area_px = 30.0;
  c.filter.model = tracking::TargetModel::ConstantVelocity;
  c.filter.q = 2e4;
  c.filter.init_velocity_sigma = 200.0;
  c.initial_px = initial_px;
  return c;
}

FootageTracker::FootageTracker(FootageTrackerConfig config)
    : config_(std::move(config)), filter_(config_.filter), half_size_(config_.initial_half_size / config_.window_growth),
      last_px_(config_.initial_px) {
  config_.validate();
}

namespace {

/// The window [c − h, c + h] clipped to the image (at least 8x8 px inside it).
cv::Rect windowAt(const Eigen::Vector2d& c, const Eigen::Vector2d& h, const cv::Size& image) {
  const int x0 = std::clamp(static_cast<int>(std::floor(c.x() - h.x())), 0, image.width - 8);
  const int y0 = std::clamp(static_cast<int>(std::floor(c.y() - h.y())), 0, image.height - 8);
  const int x1 = std::clamp(static_cast<int>(std::ceil(c.x() + h.x())) + 1, x0 + 8, image.width);
  const int y1 = std::clamp(static_cast<int>(std::ceil(c.y() + h.y())) + 1, y0 + 8, image.height);
  return {x0, y0, x1 - x0, y1 - y0};
}

/// Half-size of the blob that holds `centre` in the window binarised at `level` (the detector's
/// polarity), px; nullopt when the centre is not on the blob.
std::optional<Eigen::Vector2d> blobHalfSize(const cv::Mat& grey, const cv::Rect& window, const Eigen::Vector2d& centre,
                                            int level, bool dark) {
  cv::Mat binary, labels, stats, centroids;
  cv::threshold(grey(window), binary, level, 255, dark ? cv::THRESH_BINARY_INV : cv::THRESH_BINARY);
  cv::connectedComponentsWithStats(binary, labels, stats, centroids, 8, CV_32S);
  const int u = static_cast<int>(std::lround(centre.x())) - window.x, v = static_cast<int>(std::lround(centre.y())) - window.y;
  if (u < 0 || v < 0 || u >= labels.cols || v >= labels.rows) return std::nullopt;
  const int id = labels.at<int>(v, u);
  if (id == 0) return std::nullopt;
  return Eigen::Vector2d(0.5 * stats.at<int>(id, cv::CC_STAT_WIDTH), 0.5 * stats.at<int>(id, cv::CC_STAT_HEIGHT));
}

}  // namespace

FootageStep FootageTracker::track(const runtime::Frame& frame) {
  FootageStep step;
  step.stamp = frame.stamp;
  cv::Mat grey = frame.image;
  if (grey.channels() == 3) cv::cvtColor(frame.image, grey, cv::COLOR_BGR2GRAY);
  Eigen::Vector2d centre = last_px_;
  if (filter_.initialized()) {
    const auto k = filter_.at(frame.stamp);
    step.has_prediction = true;
    step.predicted_px = k.p;
    centre = k.p;
  }
  // Not widened by the predicted motion: a wider window takes in the clutter around the target
  // (a real target's edge), and the window is centred where the motion takes the blob anyway.
  const Eigen::Vector2d half0 = config_.window_growth * half_size_ + Eigen::Vector2d::Constant(config_.window_margin_px);
  // Attempts: at the prediction; at the last measured centre (a jerk the motion model did not
  // foresee); then growing windows at the prediction (a blob that grew).
  for (int attempt = 0; attempt <= config_.max_retries + 1; ++attempt) {
    const Eigen::Vector2d c = attempt == 1 ? last_px_ : centre;
    const Eigen::Vector2d half = attempt <= 1 ? half0 : half0 * std::pow(config_.window_growth, attempt - 1);
    if (attempt == 1 && !filter_.initialized()) continue;  // the first window is already at the last centre
    const cv::Rect w = windowAt(c, half, grey.size());
    step.window = w;
    vision::ScreenTargetDetectorConfig dc = config_.detector;
    dc.crop_left = w.x;
    dc.crop_top = w.y;
    dc.crop_right = grey.cols - w.x - w.width;
    dc.crop_bottom = grey.rows - w.y - w.height;
    vision::ScreenTargetDetector detector(dc);
    const auto det = detector.detect(grey, frame.stamp);
    if (det.ok()) {
      const auto& m = det.value();
      if (const auto hs = blobHalfSize(grey, w, m.pixel, m.threshold_used, dc.dark_target)) half_size_ = *hs;
      step.detected = true;
      step.measured_px = m.pixel;
      last_px_ = m.pixel;
      const auto u = filter_.update(frame.stamp, m.pixel, m.pixel_covariance);
      step.accepted = u.accepted;
      break;
    }
    if (attempt >= 1 && det.failure().reason != vision::FailureReason::Clipped) break;
  }
  step.filtered_px = filter_.initialized() ? filter_.at(frame.stamp).p : last_px_;
  return step;
}

FootageReport trackFootage(runtime::FrameSource& source, const FootageTrackerConfig& config, bool vpdot2) {
  FootageRunOptions options;
  options.vpdot2 = vpdot2;
  return trackFootage(source, config, options);
}

FootageReport trackFootage(runtime::FrameSource& source, const FootageTrackerConfig& config,
                           const FootageRunOptions& options) {
  const bool vpdot2 = options.vpdot2;
  const auto* live = dynamic_cast<const runtime::LiveFrameSource*>(&source);
  std::optional<runtime::ProcessingTimer> timer;
  if (live) timer.emplace(options.deadline_s, options.clock);
  FootageTracker tracker(config);
  FootageReport r;
  vpDot2 dot;
  dot.setGraphics(false);
  vpImage<unsigned char> I;
  double sum_d2 = 0.0, max_d = 0.0, sum_pred2 = 0.0, sum_hold2 = 0.0;
  bool has_previous = false;
  Eigen::Vector2d previous = Eigen::Vector2d::Zero();
  bool go_on = true;
  while (go_on && source.nextReadyTime()) {
    const auto frame = source.grab();
    ++r.frames;
    if (!frame) {
      ++r.lost;
      has_previous = false;
      continue;
    }
    if (timer) timer->resume(r.frames);
    // The frame's processing ends after the viewer's drawing, however the loop below goes on.
    struct Finish {
      std::optional<runtime::ProcessingTimer>& timer;
      std::uint64_t id;
      ~Finish() {
        if (timer) timer->finish(id);
      }
    } finish{timer, r.frames};
    if (vpdot2) {
      cv::Mat grey = frame->image;
      if (grey.channels() == 3) cv::cvtColor(frame->image, grey, cv::COLOR_BGR2GRAY);
      vpImageConvert::convert(grey, I);
      if (r.frames == 1)
        dot.initTracking(I, vpImagePoint(config.initial_px.y(), config.initial_px.x()));  // (v, u)
      else
        dot.track(I);
    }
    const FootageStep step = tracker.track(*frame);
    r.steps.push_back(step);
    if (options.on_frame) {
      go_on = options.on_frame(*frame, step, timer ? runtime::liveStatus(*live, *timer) : std::string());
    }
    if (!step.detected) {
      ++r.lost;
      has_previous = false;
      continue;
    }
    if (vpdot2) {
      const double d = (step.measured_px - Eigen::Vector2d(dot.getCog().get_u(), dot.getCog().get_v())).norm();
      sum_d2 += d * d;
      max_d = std::max(max_d, d);
      ++r.compared;
    }
    if (step.has_prediction && has_previous) {
      sum_pred2 += (step.predicted_px - step.measured_px).squaredNorm();
      sum_hold2 += (previous - step.measured_px).squaredNorm();
      ++r.predicted;
    }
    previous = step.measured_px;
    has_previous = true;
  }
  if (r.compared > 0) {
    r.vpdot2_rms_px = std::sqrt(sum_d2 / static_cast<double>(r.compared));
    r.vpdot2_max_px = max_d;
  }
  if (r.predicted > 0) {
    r.predicted_rms_px = std::sqrt(sum_pred2 / static_cast<double>(r.predicted));
    r.hold_rms_px = std::sqrt(sum_hold2 / static_cast<double>(r.predicted));
  }
  if (live) r.live = runtime::liveReport(*live, *timer, options.deadline_origin);
  return r;
}

}  // namespace viewline::scenarios::pan_tilt
