#include "viewline/runtime/file_sources.h"

#include <sys/stat.h>

#include <cmath>
#include <opencv2/imgcodecs.hpp>
#include <opencv2/imgproc.hpp>
#include <opencv2/videoio.hpp>
#include <utility>

#include "viewline/core/error.h"

namespace viewline::runtime {

namespace {

bool isRegularFile(const std::string& path) {
  struct stat st {};
  return ::stat(path.c_str(), &st) == 0 && S_ISREG(st.st_mode);
}

/// 8-bit grey or BGR, as the detectors expect (a BGRA PNG loses its alpha; 16-bit is refused).
cv::Mat toGreyOrBgr(cv::Mat image, const std::string& file) {
  if (image.depth() != CV_8U)
    throw core::InvalidInput(file + ": only 8-bit images are supported (this one has " +
                             std::to_string(8 * image.elemSize1()) + "-bit samples)");
  if (image.channels() == 4) cv::cvtColor(image, image, cv::COLOR_BGRA2BGR);
  if (image.channels() != 1 && image.channels() != 3)
    throw core::InvalidInput(file + ": expected a grey or colour image, got " + std::to_string(image.channels()) +
                             " channels");
  return image;
}

}  // namespace

std::string formatFramePattern(const std::string& pattern, std::int64_t index) {
  std::string out;
  int conversions = 0;
  for (std::size_t i = 0; i < pattern.size(); ++i) {
    if (pattern[i] != '%') {
      out += pattern[i];
      continue;
    }
    if (i + 1 < pattern.size() && pattern[i + 1] == '%') {
      out += '%';
      ++i;
      continue;
    }
    // %[0][width]d
    std::size_t j = i + 1;
    bool zero = false;
    if (j < pattern.size() && pattern[j] == '0') {
      zero = true;
      ++j;
    }
    int width = 0;
    while (j < pattern.size() && pattern[j] >= '0' && pattern[j] <= '9' && width < 100) width = width * 10 + (pattern[j++] - '0');
    if (j >= pattern.size() || pattern[j] != 'd' || width >= 100)
      throw core::InvalidInput("image pattern '" + pattern +
                               "': only one integer conversion (%d, %4d, %04d) is allowed, '%%' for a literal %");
    std::string digits = std::to_string(index < 0 ? -index : index);
    const std::size_t w = static_cast<std::size_t>(width) - (index < 0 ? 1 : 0);
    if (width > 0 && digits.size() < w) digits.insert(0, w - digits.size(), zero ? '0' : ' ');
    if (index < 0) digits.insert(zero ? 0 : digits.find_first_not_of(' '), "-");
    out += digits;
    ++conversions;
    i = j;
  }
  if (conversions != 1)
    throw core::InvalidInput("image pattern '" + pattern + "' must have exactly one integer conversion (e.g. %04d), has " +
                             std::to_string(conversions));
  return out;
}

// ---------------------------------------------------------------------------- image sequence

ImageSequenceSource::ImageSequenceSource(ImageSequenceOptions options) : opt_(std::move(options)) {
  formatFramePattern(opt_.pattern, opt_.first);  // validates the pattern
  if (!opt_.stamps_file.empty()) {
    stamps_ = readStampsFile(opt_.stamps_file);
  } else if (!(opt_.rate > 0.0 && std::isfinite(opt_.rate))) {
    throw core::InvalidInput("image sequence " + opt_.pattern + ": rate must be > 0 Hz without a stamps file");
  }
  advance();
  if (!next_) {
    throw core::InvalidInput("image sequence " + opt_.pattern + ": no frame (count 0)");
  }
  const std::string file = nextFile();
  if (!isRegularFile(file))
    throw core::InvalidInput("image sequence: the first image " + file + " does not exist" +
                             (stamps_.empty() ? " (pattern " + opt_.pattern + ", first " + std::to_string(opt_.first) + ")"
                                              : " (first line of " + opt_.stamps_file + ")"));
}

void ImageSequenceSource::advance() {
  next_.reset();
  if (opt_.count >= 0 && sequence_ >= static_cast<std::uint64_t>(opt_.count)) return;
  if (!stamps_.empty()) {
    if (stamp_pos_ < stamps_.size()) next_ = stamps_[stamp_pos_++];
    return;
  }
  StampEntry e;
  e.index = opt_.first + static_cast<std::int64_t>(sequence_);
  e.stamp = static_cast<double>(sequence_) / opt_.rate;
  // Without a stamps file the sequence ends at the first missing file (vpVideoReader's habit).
  if (sequence_ == 0 || isRegularFile(formatFramePattern(opt_.pattern, e.index))) next_ = e;
}

std::optional<core::Timestamp> ImageSequenceSource::nextReadyTime() const {
  if (!next_) return std::nullopt;
  return next_->stamp;
}

std::string ImageSequenceSource::nextFile() const {
  return next_ ? formatFramePattern(opt_.pattern, next_->index) : std::string();
}

std::optional<Frame> ImageSequenceSource::grab() {
  if (!next_) return std::nullopt;
  const std::string file = nextFile();
  if (!isRegularFile(file))
    throw core::InvalidInput("image sequence: " + file + " does not exist" +
                             (stamps_.empty() ? std::string() : " (listed in " + opt_.stamps_file + ")"));
  cv::Mat image = cv::imread(file, cv::IMREAD_UNCHANGED);
  if (image.empty()) throw core::InvalidInput("image sequence: " + file + " cannot be decoded as an image");
  Frame f;
  f.camera = 0;
  f.sequence = sequence_;
  f.stamp = next_->stamp;
  f.capture_time = next_->stamp;  // no truth behind a file
  f.image = toGreyOrBgr(std::move(image), file);
  ++sequence_;
  advance();
  return f;
}

std::string ImageSequenceSource::stampMethod() const {
  if (!stamps_.empty()) return "stamps file " + opt_.stamps_file;
  return "rate " + std::to_string(opt_.rate) + " Hz";
}

// ---------------------------------------------------------------------------- video

VideoSource::VideoSource(VideoOptions options) : opt_(std::move(options)) {
  if (!isRegularFile(opt_.path)) throw core::InvalidInput("video " + opt_.path + " does not exist (or is not a file)");
  if (!opt_.stamps_file.empty()) stamps_ = readStampsFile(opt_.stamps_file);
  cap_ = std::make_unique<cv::VideoCapture>();
  if (!cap_->open(opt_.path, cv::CAP_FFMPEG))
    throw core::InvalidInput("video " + opt_.path + ": OpenCV's FFmpeg back end cannot open it (not a video, or a codec it lacks)");
  nominal_rate_ = cap_->get(cv::CAP_PROP_FPS);
  if (!(nominal_rate_ > 0.0 && std::isfinite(nominal_rate_))) nominal_rate_ = 0.0;
  decodeNext();
  if (!next_) throw core::InvalidInput("video " + opt_.path + ": no frame could be decoded");
}

VideoSource::~VideoSource() = default;

void VideoSource::decodeNext() {
  next_.reset();
  if (opt_.count >= 0 && decoded_ >= static_cast<std::uint64_t>(opt_.count)) return;
  cv::Mat image;
  if (!cap_->read(image) || image.empty()) return;  // end of the file
  const std::string where = opt_.path + ": frame " + std::to_string(decoded_);
  Frame f;
  f.camera = 0;
  f.sequence = decoded_;
  if (!stamps_.empty()) {
    if (decoded_ >= stamps_.size() || stamps_[decoded_].index != static_cast<std::int64_t>(decoded_))
      throw core::InvalidInput(where + " has no line in " + opt_.stamps_file +
                               " (its indices must be the frame numbers 0, 1, 2, ...)");
    f.stamp = stamps_[decoded_].stamp;
  } else {
    // The presentation time of the frame just decoded (FFmpeg back end: the packet's pts). A raw
    // elementary stream (e.g. MPEG-1 video without a system layer) has none: FFmpeg then reports
    // AV_NOPTS_VALUE-derived nonsense (about -7.7e12 s), so the first frame decides: a time in
    // [0, 1e6) s means container times, anything else the nominal rate.
    const double pts = cap_->get(cv::CAP_PROP_POS_MSEC) * 1e-3;
    if (decoded_ == 0) container_stamps_ = std::isfinite(pts) && pts >= 0.0 && pts < 1e6;
    if (container_stamps_) {
      f.stamp = pts;
    } else {
      if (nominal_rate_ <= 0.0)
        throw core::InvalidInput(opt_.path + ": the container gives neither time stamps nor a frame rate; give a stamps file");
      f.stamp = static_cast<double>(decoded_) / nominal_rate_;
    }
  }
  f.capture_time = f.stamp;
  f.image = toGreyOrBgr(std::move(image), where);
  ++decoded_;
  next_ = std::move(f);
}

std::optional<core::Timestamp> VideoSource::nextReadyTime() const {
  if (!next_) return std::nullopt;
  return next_->stamp;
}

std::optional<Frame> VideoSource::grab() {
  if (!next_) return std::nullopt;
  std::optional<Frame> out = std::move(next_);
  decodeNext();
  if (next_ && !(next_->stamp > out->stamp))
    throw core::InvalidInput(opt_.path + ": frame " + std::to_string(next_->sequence) + " has stamp " +
                             std::to_string(next_->stamp) + " s, not after the previous one (" +
                             std::to_string(out->stamp) + " s); give a stamps file");
  return out;
}

std::string VideoSource::stampMethod() const {
  if (!stamps_.empty()) return "stamps file " + opt_.stamps_file;
  if (container_stamps_) return "container time stamps (CAP_PROP_POS_MSEC)";
  return "nominal rate " + std::to_string(nominal_rate_) + " Hz (the container has no usable time stamps)";
}

}  // namespace viewline::runtime
