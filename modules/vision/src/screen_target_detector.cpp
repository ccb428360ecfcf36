#include "viewline/vision/screen_target_detector.h"

#include <algorithm>
#include <cmath>
#include <cstring>
#include <optional>
#include <opencv2/core/hal/intrin.hpp>
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
  if (window_half_size_px < 0)
    throw core::InvalidInput("ScreenTargetDetectorConfig.window_half_size_px must be >= 0 (0: always the full frame)");
}

namespace {

// Index of the first / last non-zero byte of p[0, n), or -1; eight bytes at a time (the binary image is
// mostly background).
int firstNonZero(const std::uint8_t* p, int n) {
  int i = 0;
  for (; i + 8 <= n; i += 8) {
    std::uint64_t w;
    std::memcpy(&w, p + i, 8);
    if (w != 0) break;
  }
  for (; i < n; ++i)
    if (p[i] != 0) return i;
  return -1;
}

int lastNonZero(const std::uint8_t* p, int n) {
  int i = n;
  for (; i >= 8; i -= 8) {
    std::uint64_t w;
    std::memcpy(&w, p + i - 8, 8);
    if (w != 0) break;
  }
  for (; i > 0; --i)
    if (p[i - 1] != 0) return i - 1;
  return -1;
}

}  // namespace

BinaryBlobMoments medianBlobMoments(const cv::Mat& binary, int ksize, std::vector<std::int32_t>& scratch) {
  return medianBlobMoments(binary, ksize, scratch, cv::Rect(0, 0, binary.cols, binary.rows));
}

BinaryBlobMoments medianBlobMoments(const cv::Mat& binary, int ksize, std::vector<std::int32_t>& scratch,
                                    const cv::Rect& foreground_roi) {
  if (binary.type() != CV_8UC1 || binary.empty())
    throw core::InvalidInput("medianBlobMoments: expected a non-empty CV_8UC1 image");
  if (ksize < 1 || ksize % 2 == 0) throw core::InvalidInput("medianBlobMoments: ksize must be odd and >= 1");
  const int W = binary.cols, H = binary.rows, r = ksize / 2;
  const cv::Rect roi = foreground_roi & cv::Rect(0, 0, W, H);
  // The median of k² values in {0, 255} is 255 iff at least (k² + 1) / 2 of them are 255: the filter is
  // a majority vote over the window (cv::medianBlur replicates the border, as the clamps below do). A
  // pixel whose window holds no foreground stays 0, so only the input foreground's box grown by r is
  // filtered.
  const int need = (ksize * ksize + 1) / 2;
  // (Only the roi is searched: the caller guarantees 0 outside it.)
  int fx0 = W, fx1 = -1, fy0 = H, fy1 = -1;
  for (int y = roi.y; y < roi.y + roi.height; ++y) {
    const std::uint8_t* row = binary.ptr<std::uint8_t>(y) + roi.x;
    const int first = firstNonZero(row, roi.width);
    if (first < 0) continue;
    fx0 = std::min(fx0, roi.x + first);
    fx1 = std::max(fx1, roi.x + lastNonZero(row, roi.width));
    if (fy1 < 0) fy0 = y;
    fy1 = y;
  }
  BinaryBlobMoments out;
  if (fy1 < 0) return out;
  const int ox0 = std::max(0, fx0 - r), ox1 = std::min(W - 1, fx1 + r);
  const int oy0 = std::max(0, fy0 - r), oy1 = std::min(H - 1, fy1 + r);
  // cv::moments sums 32x32 tiles in integers and the tiles in double (below): per tile the count, Σ x and
  // Σ y of its foreground, in the tile's own coordinates.
  constexpr int kTile = 32;
  const int tiles_x = (W + kTile - 1) / kTile, tiles_y = (H + kTile - 1) / kTile;
  const int cw = (ox1 - ox0 + 1) + 2 * r;  // column sums over x in [ox0 - r, ox1 + r] (clamped into the image)
  scratch.assign(static_cast<std::size_t>(cw + 3 * tiles_x * tiles_y), 0);
  std::int32_t* colsum = scratch.data();
  std::int32_t* tile = colsum + cw;
  const auto addRow = [&](int yy, int sign) {
    const std::uint8_t* row = binary.ptr<std::uint8_t>(std::clamp(yy, 0, H - 1));
    for (int c = 0; c < cw; ++c) colsum[c] += sign * (row[std::clamp(ox0 - r + c, 0, W - 1)] != 0 ? 1 : 0);
  };
  for (int dy = -r; dy <= r; ++dy) addRow(oy0 + dy, 1);
  int bx0 = W, bx1 = -1, by0 = H, by1 = -1;
  for (int y = oy0; y <= oy1; ++y) {
    if (y > oy0) {  // the window moves down one row
      addRow(y + r, 1);
      addRow(y - r - 1, -1);
    }
    int sum = 0;
    for (int c = 0; c < 2 * r; ++c) sum += colsum[c];
    std::int32_t* tile_row = tile + 3 * (y / kTile) * tiles_x;
    for (int i = 0, x = ox0; x <= ox1; ++i, ++x) {
      sum += colsum[i + 2 * r];
      if (sum >= need) {
        std::int32_t* t = tile_row + 3 * (x / kTile);
        t[0] += 1;
        t[1] += x % kTile;
        t[2] += y % kTile;
        bx0 = std::min(bx0, x);
        bx1 = std::max(bx1, x);
        by0 = std::min(by0, y);
        by1 = std::max(by1, y);
      }
      sum -= colsum[i];
    }
  }
  if (by1 < 0) return out;
  out.box = cv::Rect(bx0, by0, bx1 - bx0 + 1, by1 - by0 + 1);
  // cv::moments(binary = true), OpenCV 4.6 imgproc/src/moments.cpp: each tile's integer moments of the
  // 0/255 image are converted to double and scaled by 1./255 (not exact: 255 n * (1./255) may differ
  // from n in the last bit), then added tile by tile in row order, m10 += m10' + x0 m00' (x0, y0 the
  // tile's corner). The same operations in the same order; empty tiles add +0.0 and are skipped.
  const double scale = 1. / 255;
  for (int ty = 0; ty < tiles_y; ++ty) {
    for (int tx = 0; tx < tiles_x; ++tx) {
      const std::int32_t* t = tile + 3 * (ty * tiles_x + tx);
      if (t[0] == 0) continue;
      double mom0 = static_cast<double>(255 * t[0]), mom1 = static_cast<double>(255 * t[1]),
             mom2 = static_cast<double>(255 * t[2]);
      mom0 *= scale;
      mom1 *= scale;
      mom2 *= scale;
      const double xm = (tx * kTile) * mom0, ym = (ty * kTile) * mom0;
      out.m00 += mom0;
      out.m10 += mom1 + xm;
      out.m01 += mom2 + ym;
    }
  }
  return out;
}

void halfScaleBinary(const cv::Mat& image, int level, bool dark_target, cv::Mat& binary) {
  if ((image.type() != CV_8UC1 && image.type() != CV_8UC3) || image.empty() || image.cols % 2 != 0 || image.rows % 2 != 0)
    throw core::InvalidInput("halfScaleBinary: expected a non-empty CV_8UC1 or CV_8UC3 image of even size");
  if (level < 0 || level > 255) throw core::InvalidInput("halfScaleBinary: level must be in [0, 255]");
  const int cn = image.channels(), W = image.cols / 2, H = image.rows / 2;
  binary.create(H, W, CV_8UC1);
  // OpenCV 4.6, 8-bit: BGR2GRAY is (3735 B + 19235 G + 9798 R + 2^14) >> 15 (imgproc/src/color.hpp, BY15 GY15
  // RY15 and gray_shift = 15, used by RGB2Gray<uchar> in color_rgb.simd.hpp; not the 14-bit yuv coefficients
  // 1868 9617 4899 of OpenCV 3, which round differently near .5); INTER_AREA at exactly 1/2 is the fast area path, (a + b + c + d + 2) >> 2
  // (imgproc/src/resize.cpp, ResizeAreaFastVec); THRESH_BINARY(_INV) at an integer level is v > level.
  const auto grey = [cn](const std::uint8_t* p) {
    return cn == 1 ? int{p[0]} : (3735 * p[0] + 19235 * p[1] + 9798 * p[2] + (1 << 14)) >> 15;
  };
  // The grey level lies between the smallest and the largest of a pixel's channels (the weights sum to
  // 2^15, the rounding adds half), and so does the mean of four: a block whose bytes are all > level
  // (dark target; all <= level for a bright one) is background whatever the exact values, and only the
  // other blocks (the target's, dark clutter) are computed exactly.
  constexpr int kBlock = 16;  // output pixels per block
  for (int y = 0; y < H; ++y) {
    const std::uint8_t* r0 = image.ptr<std::uint8_t>(2 * y);
    const std::uint8_t* r1 = image.ptr<std::uint8_t>(2 * y + 1);
    // The frame is read once, from memory (it is larger than the caches): the next row pair is prefetched
    // block by block while this one is tested (~1.5x faster than leaving it to the hardware prefetcher,
    // whose streams restart at every row of a cropped view).
    const std::uint8_t* next0 = image.ptr<std::uint8_t>(std::min(2 * y + 2, image.rows - 2));
    const std::uint8_t* next1 = image.ptr<std::uint8_t>(std::min(2 * y + 3, image.rows - 1));
    std::uint8_t* out = binary.ptr<std::uint8_t>(y);
    for (int x0 = 0; x0 < W; x0 += kBlock) {
      const int n = std::min(kBlock, W - x0), bytes = 2 * n * cn;
      const std::uint8_t* a = r0 + 2 * x0 * cn;
      const std::uint8_t* b = r1 + 2 * x0 * cn;
#if defined(__GNUC__)
      for (int o = 0; o < bytes; o += 64) {
        __builtin_prefetch(next0 + 2 * x0 * cn + o);
        __builtin_prefetch(next1 + 2 * x0 * cn + o);
      }
#endif
      bool background = false, tested = false;
#if CV_SIMD128
      if (bytes % 16 == 0) {  // whole blocks: 16 bytes at a time
        cv::v_uint8x16 lo = cv::v_setall_u8(255), hi = cv::v_setzero_u8();
        for (int i = 0; i < bytes; i += 16) {
          const cv::v_uint8x16 va = cv::v_load(a + i), vb = cv::v_load(b + i);
          if (dark_target)
            lo = cv::v_min(lo, cv::v_min(va, vb));
          else
            hi = cv::v_max(hi, cv::v_max(va, vb));
        }
        background = dark_target ? cv::v_reduce_min(lo) > level : cv::v_reduce_max(hi) <= level;
        tested = true;
      }
#endif
      if (!tested && dark_target) {
        std::uint8_t lo = 255;
        for (int i = 0; i < bytes; ++i) lo = std::min(lo, std::min(a[i], b[i]));
        background = lo > level;
      } else if (!tested) {
        std::uint8_t hi = 0;
        for (int i = 0; i < bytes; ++i) hi = std::max(hi, std::max(a[i], b[i]));
        background = hi <= level;
      }
      if (background) {
        std::memset(out + x0, 0, static_cast<std::size_t>(n));
        continue;
      }
      for (int x = x0; x < x0 + n; ++x) {
        const int sum = grey(r0 + 2 * x * cn) + grey(r0 + (2 * x + 1) * cn) + grey(r1 + 2 * x * cn) +
                        grey(r1 + (2 * x + 1) * cn);
        out[x] = ((sum + 2) >> 2 > level) != dark_target ? 255 : 0;
      }
    }
  }
}

ScreenTargetDetector::ScreenTargetDetector(ScreenTargetDetectorConfig config)
    : config_(std::move(config)) {
  config_.validate();
}

namespace {
// True when a row or column on the edge of `win` (inside `binary`) holds a foreground pixel.
bool edgeHasForeground(const cv::Mat& binary, const cv::Rect& win) {
  const std::uint8_t* top = binary.ptr<std::uint8_t>(win.y) + win.x;
  const std::uint8_t* bottom = binary.ptr<std::uint8_t>(win.y + win.height - 1) + win.x;
  if (firstNonZero(top, win.width) >= 0 || firstNonZero(bottom, win.width) >= 0) return true;
  for (int y = win.y; y < win.y + win.height; ++y) {
    const std::uint8_t* row = binary.ptr<std::uint8_t>(y);
    if (row[win.x] != 0 || row[win.x + win.width - 1] != 0) return true;
  }
  return false;
}
}  // namespace

Result<ScreenTargetMeasurement> ScreenTargetDetector::detect(const cv::Mat& image, core::Timestamp stamp,
                                                             const std::optional<Eigen::Vector2d>& predicted) {
  requireGrayOrBgrImage(image, "ScreenTargetDetector::detect");
  core::requireFinite(stamp, "ScreenTargetDetector::detect: stamp");
  used_window_ = false;
  const int w = image.cols - config_.crop_left - config_.crop_right;
  const int h = image.rows - config_.crop_top - config_.crop_bottom;
  if (w < 8 || h < 8)
    throw core::InvalidInput("ScreenTargetDetectorConfig.crop_*: margins leave less than 8x8 px of a " +
                             std::to_string(image.cols) + "x" + std::to_string(image.rows) + " image");
  const cv::Rect crop(config_.crop_left, config_.crop_top, w, h);
  const double s = config_.scale;
  double level = config_.threshold;
  const bool one_pass = config_.threshold >= 0 && s == 0.5 && w % 2 == 0 && h % 2 == 0;
  if (one_pass && predicted && config_.window_half_size_px > 0 && predicted->allFinite()) {
    if (auto r = detectInWindow(image(crop), *predicted, stamp)) {
      used_window_ = true;
      return std::move(*r);
    }
  }
  binary_clean_ = false;
  if (one_pass) {
    // 1.-3. crop, grey, resize 50 %, binarise (target = 255) in one pass (halfScaleBinary: the same
    // image as the OpenCV calls below, bit for bit)
    halfScaleBinary(image(crop), config_.threshold, config_.dark_target, binary_);
  } else {
    // 1. crop, grey
    if (image.channels() == 3)
      cv::cvtColor(image(crop), gray_, cv::COLOR_BGR2GRAY);
    else
      gray_ = image(crop);
    // 2. resize 50 %
    if (s < 1.0)
      cv::resize(gray_, small_, cv::Size(), s, s, cv::INTER_AREA);
    else
      small_ = gray_;
    // 3. binarise (target = 255)
    const int type = config_.dark_target ? cv::THRESH_BINARY_INV : cv::THRESH_BINARY;
    if (config_.threshold < 0)
      level = cv::threshold(small_, binary_, 0, 255, type | cv::THRESH_OTSU);
    else
      cv::threshold(small_, binary_, level, 255, type);
  }
  // 4.-5. median filter, then the centroid and bounding box of the binary image (medianBlobMoments:
  // cv::medianBlur + cv::moments + cv::boundingRect bit for bit, over the foreground's neighbourhood only).
  return measure(medianBlobMoments(binary_, config_.median_ksize, scratch_), level, stamp);
}

std::optional<Result<ScreenTargetMeasurement>> ScreenTargetDetector::detectInWindow(const cv::Mat& cropped,
                                                                                    const Eigen::Vector2d& predicted,
                                                                                    core::Timestamp stamp) {
  // The half-resolution image is (cropped.cols / 2) x (cropped.rows / 2); the predicted pixel maps to
  // q = (u − crop_left + 0.5) s − 0.5 there (the inverse of the header's u = crop_left + (q + 0.5) / s − 0.5).
  const int W = cropped.cols / 2, H = cropped.rows / 2;
  const double s = config_.scale;
  const double qu = (predicted.x() - config_.crop_left + 0.5) * s - 0.5;
  const double qv = (predicted.y() - config_.crop_top + 0.5) * s - 0.5;
  const double half = std::ceil(config_.window_half_size_px * s);
  // (Clamped in double first: a prediction far off the image must not overflow the int conversion.)
  const auto lo = [half](double q, int n) { return static_cast<int>(std::clamp(std::floor(q - half), 0.0, double(n))); };
  const auto hi = [half](double q, int n) { return static_cast<int>(std::clamp(std::floor(q + half) + 1.0, 0.0, double(n))); };
  const int x0 = lo(qu, W), x1 = hi(qu, W), y0 = lo(qv, H), y1 = hi(qv, H);
  if (x1 - x0 < 3 || y1 - y0 < 3) return std::nullopt;  // the prediction is off the image
  if (x1 - x0 == W && y1 - y0 == H) return std::nullopt;  // the window is the whole frame
  if (!binary_clean_ || binary_.rows != H || binary_.cols != W || binary_.type() != CV_8UC1) {
    binary_.create(H, W, CV_8UC1);
    binary_.setTo(0);
    binary_clean_ = true;
  }
  const cv::Rect win(x0, y0, x1 - x0, y1 - y0);
  cv::Mat part = binary_(win);
  halfScaleBinary(cropped(cv::Rect(2 * x0, 2 * y0, 2 * win.width, 2 * win.height)), config_.threshold,
                  config_.dark_target, part);
  std::optional<Result<ScreenTargetMeasurement>> out;
  // Foreground on the window's edge may continue outside it: the full frame decides.
  if (!edgeHasForeground(binary_, win)) {
    auto r = measure(medianBlobMoments(binary_, config_.median_ksize, scratch_, win), config_.threshold, stamp);
    if (r.ok()) out = std::move(r);  // a failure (no target here, too small, ...): the full frame decides
  }
  part.setTo(0);  // binary_ stays all 0 for the next window
  return out;
}

Result<ScreenTargetMeasurement> ScreenTargetDetector::measure(const BinaryBlobMoments& m, double level,
                                                              core::Timestamp stamp) const {
  const double s = config_.scale;
  const double full_area = m.m00 / (s * s);
  if (m.m00 <= 0.0)
    return Result<ScreenTargetMeasurement>::fail(FailureReason::NotFound,
                                                 "no target pixels after binarisation");
  if (full_area < config_.min_area_px)
    return Result<ScreenTargetMeasurement>::fail(
        FailureReason::TooSmall, "target area " + std::to_string(full_area) + " px < min_area_px");
  const cv::Rect& box = m.box;
  if (touchesBorder(box, cv::Rect(0, 0, binary_.cols, binary_.rows)))
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
