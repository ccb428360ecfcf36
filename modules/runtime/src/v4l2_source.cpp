#include "viewline/runtime/v4l2_source.h"

#include <sys/stat.h>

#include <cerrno>
#include <cmath>
#include <cstdio>
#include <cstring>
#include <opencv2/videoio.hpp>
#include <utility>

#include "viewline/core/error.h"

namespace viewline::runtime {

V4l2Source::V4l2Source(V4l2Options options) : opt_(std::move(options)), t0_(std::chrono::steady_clock::now()) {
  const std::string& dev = opt_.device;
  struct stat st {};
  if (::stat(dev.c_str(), &st) != 0)
    throw core::InvalidInput("v4l2 camera " + dev + ": no such device (" + std::strerror(errno) +
                             "); list the cameras with `v4l2-ctl --list-devices`");
  if (!S_ISCHR(st.st_mode))
    throw core::InvalidInput("v4l2 camera " + dev + ": not a V4L2 device (not a character device file)");
  cap_ = std::make_unique<cv::VideoCapture>();
  if (!cap_->open(dev, cv::CAP_V4L2) || !cap_->isOpened())
    throw core::InvalidInput("v4l2 camera " + dev +
                             ": cannot be opened as a V4L2 capture device (busy, no permission: group video, or not a camera)");
  if (opt_.width > 0) cap_->set(cv::CAP_PROP_FRAME_WIDTH, opt_.width);
  if (opt_.height > 0) cap_->set(cv::CAP_PROP_FRAME_HEIGHT, opt_.height);
  if (opt_.rate > 0.0) cap_->set(cv::CAP_PROP_FPS, opt_.rate);
  if (opt_.exposure >= 0.0) {
    cap_->set(cv::CAP_PROP_AUTO_EXPOSURE, 1);  // V4L2_EXPOSURE_MANUAL through OpenCV's V4L2 mapping
    cap_->set(cv::CAP_PROP_EXPOSURE, opt_.exposure);
  }
  rate_ = cap_->get(cv::CAP_PROP_FPS);
  if (!(rate_ > 0.0 && std::isfinite(rate_))) rate_ = opt_.rate > 0.0 ? opt_.rate : 30.0;
  t0_ = std::chrono::steady_clock::now();
}

V4l2Source::~V4l2Source() = default;

double V4l2Source::now() const {
  return std::chrono::duration<double>(std::chrono::steady_clock::now() - t0_).count();
}

std::optional<core::Timestamp> V4l2Source::nextReadyTime() const {
  if (opt_.count >= 0 && sequence_ >= static_cast<std::uint64_t>(opt_.count)) return std::nullopt;
  return now();
}

std::optional<Frame> V4l2Source::grab() {
  if (opt_.count >= 0 && sequence_ >= static_cast<std::uint64_t>(opt_.count)) return std::nullopt;
  cv::Mat image;
  const bool ok = cap_->read(image);
  const double t_grab = now();
  if (!ok || image.empty()) {
    ++dropped_;
    ++sequence_;
    return std::nullopt;
  }
  // The driver's buffer stamp (ms on CLOCK_MONOTONIC, the clock of steady_clock on Linux).
  const double t0_abs = std::chrono::duration<double>(t0_.time_since_epoch()).count();
  const double buffer = cap_->get(cv::CAP_PROP_POS_MSEC) * 1e-3 - t0_abs;
  double stamp = t_grab;
  if (buffer_stamps_ && std::isfinite(buffer) && buffer <= t_grab && buffer > t_grab - 1.0)
    stamp = buffer;
  else
    buffer_stamps_ = false;  // once unusable, stay with grab times: one clock per run
  const double period = 1.0 / rate_;
  if (last_stamp_) {
    const double gap = (stamp - *last_stamp_) / period;
    if (gap > 1.5) {
      const auto skipped = static_cast<std::uint64_t>(std::lround(gap)) - 1;
      dropped_ += skipped;
      gaps_ += skipped;
    }
  }
  if (t_grab - stamp > period) ++late_;
  last_stamp_ = stamp;
  Frame f;
  f.camera = 0;
  f.sequence = sequence_++;
  f.stamp = stamp;
  f.capture_time = stamp;
  f.image = std::move(image);
  return f;
}

std::string V4l2Source::describe() const {
  char rate[32];
  std::snprintf(rate, sizeof rate, "%g", rate_);
  return "v4l2 camera " + opt_.device + " at " + rate + " fps (" + stampMethod() + ")";
}

std::string V4l2Source::stampMethod() const {
  return buffer_stamps_ ? "driver buffer time stamps" : "time of grab (the driver gave no usable buffer time stamp)";
}

}  // namespace viewline::runtime
