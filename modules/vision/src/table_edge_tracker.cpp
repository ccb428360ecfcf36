#include "viewline/vision/table_edge_tracker.h"

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdint>
#include <opencv2/imgproc.hpp>

#include "viewline/vision/ball_detector.h"
#include "viewline/vision/color.h"

namespace viewline::vision {

namespace {

/// R − max(G, B) of the BGR image at (u, v), bilinear; NaN outside.
double redFeature(const cv::Mat& bgr, double u, double v) {
  if (!(u >= 0.0 && v >= 0.0 && u < bgr.cols - 1.0 && v < bgr.rows - 1.0)) return std::nan("");
  const int x = static_cast<int>(u), y = static_cast<int>(v);
  const double fx = u - x, fy = v - y;
  const cv::Vec3b* r0 = bgr.ptr<cv::Vec3b>(y) + x;
  const cv::Vec3b* r1 = bgr.ptr<cv::Vec3b>(y + 1) + x;
  double f[3];
  for (int k = 0; k < 3; ++k) {
    f[k] = (1 - fy) * ((1 - fx) * r0[0][k] + fx * r0[1][k]) + fy * ((1 - fx) * r1[0][k] + fx * r1[1][k]);
  }
  return f[2] - std::max(f[0], f[1]);
}

bool fitLine(std::vector<Eigen::Vector2d>& pts, Eigen::Vector2d& c, Eigen::Vector2d& d, int min_points) {
  for (int pass = 0; pass < 2; ++pass) {
    if (static_cast<int>(pts.size()) < min_points) return false;
    c.setZero();
    for (const auto& p : pts) c += p;
    c /= static_cast<double>(pts.size());
    Eigen::Matrix2d S = Eigen::Matrix2d::Zero();
    for (const auto& p : pts) S += (p - c) * (p - c).transpose();
    // Principal direction of the 2x2 scatter (closed form).
    const double a = S(0, 0), b = S(0, 1), e = S(1, 1);
    const double ang = 0.5 * std::atan2(2.0 * b, a - e);
    d = Eigen::Vector2d(std::cos(ang), std::sin(ang));
    if (pass == 0) {
      const Eigen::Vector2d n(-d.y(), d.x());
      pts.erase(std::remove_if(pts.begin(), pts.end(), [&](const Eigen::Vector2d& p) { return std::abs(n.dot(p - c)) > 1.0; }),
                pts.end());
    }
  }
  return true;
}

/// BORDER_REFLECT_101 index (OpenCV's borderInterpolate) into [0, n).
int reflect101(int i, int n) {
  if (n == 1) return 0;
  while (i < 0 || i >= n) {
    if (i < 0) i = -i;
    if (i >= n) i = 2 * n - 2 - i;
  }
  return i;
}

/// The body of gaussianBlurWindow for the binomial kernel of size K (3 or 5); see there.
template <int K>
void blurWindowBinomial(const cv::Mat& bgr, const cv::Rect& roi, cv::Mat& dst) {
  static_assert(K == 3 || K == 5, "binomial taps of size 3 or 5");
  constexpr int kR = K / 2;
  constexpr std::array<std::uint16_t, K> kTaps = [] {
    if constexpr (K == 3) {
      return std::array<std::uint16_t, K>{1, 2, 1};
    } else {
      return std::array<std::uint16_t, K>{1, 4, 6, 4, 1};
    }
  }();
  constexpr int kShift = K == 3 ? 4 : 8;  // log2 of the 2-D weight
  // Every sum fits 16 bits (at most 255 · 256 + half), so the passes run on 16-bit lanes.
  constexpr std::uint16_t kHalf = 1U << (kShift - 1);
  const int w = roi.width, h = roi.height;
  const std::size_t stride = static_cast<std::size_t>(w) * 3;
  // Scratch kept between calls (per thread), so the steady state does not allocate: the padded
  // source row and the row sums of the window's rows and the K − 1 around them.
  thread_local std::vector<std::uint8_t> padded;
  thread_local std::vector<std::uint16_t> sums;
  padded.resize(stride + 6 * kR);
  sums.resize(static_cast<std::size_t>(h + 2 * kR) * stride);
  const bool inside_x = roi.x >= kR && roi.x + w + kR <= bgr.cols;
  for (int yy = 0; yy < h + 2 * kR; ++yy) {
    const std::uint8_t* row = bgr.ptr<std::uint8_t>(reflect101(roi.y - kR + yy, bgr.rows));
    const std::uint8_t* src = row + 3 * (roi.x - kR);
    if (!inside_x) {
      for (int i = 0; i < w + 2 * kR; ++i) {
        const std::uint8_t* p = row + 3 * reflect101(roi.x - kR + i, bgr.cols);
        std::copy(p, p + 3, padded.data() + 3 * i);
      }
      src = padded.data();
    }
    std::uint16_t* out = sums.data() + static_cast<std::size_t>(yy) * stride;
    for (std::size_t q = 0; q < stride; ++q) {
      std::uint16_t sum = 0;
      for (int j = 0; j < K; ++j)
        sum = static_cast<std::uint16_t>(sum + kTaps[static_cast<std::size_t>(j)] * src[q + 3 * static_cast<std::size_t>(j)]);
      out[q] = sum;
    }
  }
  dst.create(h, w, CV_8UC3);
  // A window that is the whole image is no submatrix: OpenCV's bit-exact path, half up throughout.
  const bool whole = roi.width == bgr.cols && roi.height == bgr.rows;
  const std::size_t vector_end = whole ? 0 : stride / 4 * 4;
  for (int y = 0; y < h; ++y) {
    std::uint8_t* out = dst.ptr<std::uint8_t>(y);
    const std::uint16_t* in = sums.data() + static_cast<std::size_t>(y) * stride;
    auto sumAt = [&](std::size_t q) {
      std::uint16_t sum = 0;
      for (int i = 0; i < K; ++i)
        sum = static_cast<std::uint16_t>(sum + kTaps[static_cast<std::size_t>(i)] * in[static_cast<std::size_t>(i) * stride + q]);
      return sum;
    };
    // Half to even: adding half − 1 plus the truncated result's lowest bit rounds a tie up only
    // from an odd value.
    for (std::size_t q = 0; q < vector_end; ++q) {
      const std::uint16_t sum = sumAt(q);
      out[q] = static_cast<std::uint8_t>(static_cast<std::uint16_t>(sum + kHalf - 1 + ((sum >> kShift) & 1U)) >> kShift);
    }
    for (std::size_t q = vector_end; q < stride; ++q)
      out[q] = static_cast<std::uint8_t>(static_cast<std::uint16_t>(sumAt(q) + kHalf) >> kShift);
  }
}

}  // namespace

void gaussianBlurWindow(const cv::Mat& bgr, const cv::Rect& roi, int ksize, cv::Mat& dst) {
  const bool inside = roi.width > 0 && roi.height > 0 && (roi & cv::Rect(0, 0, bgr.cols, bgr.rows)) == roi;
  // A submatrix image would be read beyond its edges by OpenCV: that case stays OpenCV's.
  if (bgr.type() != CV_8UC3 || (ksize != 3 && ksize != 5) || !inside || bgr.isSubmatrix()) {
    cv::GaussianBlur(bgr(roi), dst, cv::Size(ksize, ksize), 0.0);
    return;
  }
  // What OpenCV 4.6 does for a submatrix that is not isolated (its separable filter engine, not
  // the bit-exact path of whole images): the binomial taps (1 2 1)/4 and (1 4 6 4 1)/16 in 8.8
  // fixed point, an exact integer row pass, and a column pass whose float sums are exact too
  // (at most 17 significant bits), so the only rounding is the last one of the 2-D sum S (weight
  // 16 or 256): half to even on the elements of a row its SIMD loops cover (the first
  // 4·floor(n/4) of the n = 3·width channel values, whatever the vector width), half up on the
  // rest (its scalar tail); a window that is the whole image goes OpenCV's bit-exact way, the
  // same sums rounded half up. The window reads the image around it and reflects at the image's
  // edges (BORDER_REFLECT_101). WindowBlurIsOpenCvsGaussianBlur checks it value for value.
  if (ksize == 3) {
    blurWindowBinomial<3>(bgr, roi, dst);
  } else {
    blurWindowBinomial<5>(bgr, roi, dst);
  }
}

TableEdgeTracker::TableEdgeTracker(const TableDetectorConfig& detector, const TableEdgeTrackerConfig& config)
    : detector_(detector), config_(config) {
  if (detector_.ball_open_kernel_px > 1) {
    kernel_ = cv::getStructuringElement(cv::MORPH_ELLIPSE, cv::Size(detector_.ball_open_kernel_px, detector_.ball_open_kernel_px));
  }
}

std::optional<std::array<Eigen::Vector2d, 4>> TableEdgeTracker::trackCorners(
    const cv::Mat& bgr, const std::array<Eigen::Vector2d, 4>& previous) const {
  Eigen::Vector2d centre = Eigen::Vector2d::Zero();
  for (const auto& p : previous) centre += 0.25 * p;
  std::array<Eigen::Vector2d, 4> line_c, line_d;
  constexpr double kStep = 0.25;
  const int count = static_cast<int>(2.0 * config_.search_px / kStep) + 1;
  std::vector<double> prof(static_cast<std::size_t>(count));
  std::vector<Eigen::Vector2d> pts;
  for (std::size_t i = 0; i < 4; ++i) {
    const Eigen::Vector2d a = previous[i], b = previous[(i + 1) % 4];
    Eigen::Vector2d n(-(b - a).y(), (b - a).x());
    n.normalize();
    if (n.dot(0.5 * (a + b) - centre) < 0.0) n = -n;  // outward
    pts.clear();
    for (int k = 0; k < config_.samples_per_side; ++k) {
      const double s = 0.15 + 0.7 * (k + 0.5) / config_.samples_per_side;
      const Eigen::Vector2d p0 = a + s * (b - a);
      // The profile is read lazily: its two ends first (inside the image and contrast), then
      // from the inside end up to the first crossing only. Each coordinate of the sample points
      // is monotone in j (a rounded affine function), so both ends inside the image put every
      // point between them inside; the values are those of the whole profile, read the same way.
      auto sample = [&](int j) {
        const Eigen::Vector2d p = p0 + (-config_.search_px + j * kStep) * n;
        return redFeature(bgr, p.x(), p.y());
      };
      prof[0] = sample(0);
      prof[static_cast<std::size_t>(count - 1)] = sample(count - 1);
      if (std::isnan(prof[0]) || std::isnan(prof[static_cast<std::size_t>(count - 1)])) continue;
      prof[1] = sample(1);
      prof[static_cast<std::size_t>(count - 2)] = sample(count - 2);
      const double in = 0.5 * (prof[0] + prof[1]), out = 0.5 * (prof[static_cast<std::size_t>(count - 1)] + prof[static_cast<std::size_t>(count - 2)]);
      if (in - out < config_.min_contrast) continue;
      const double level = 0.5 * (in + out);
      double f0 = prof[0];
      for (int j = 0; j + 1 < count; ++j) {
        const double f1 = (j + 1 == 1 || j + 1 == count - 2 || j + 1 == count - 1) ? prof[static_cast<std::size_t>(j + 1)] : sample(j + 1);
        if (f0 >= level && f1 < level) {
          const double sj = -config_.search_px + kStep * (j + (f0 - level) / (f0 - f1));
          pts.push_back(p0 + sj * n);
          break;
        }
        f0 = f1;
      }
    }
    if (!fitLine(pts, line_c[i], line_d[i], config_.min_points)) return std::nullopt;
  }
  std::array<Eigen::Vector2d, 4> out;
  for (std::size_t i = 0; i < 4; ++i) {
    // Corner i is the meeting point of side i-1 (P_{i-1} P_i) and side i (P_i P_{i+1}).
    const std::size_t j = (i + 3) % 4;
    Eigen::Matrix2d A;
    A.col(0) = line_d[j];
    A.col(1) = -line_d[i];
    if (std::abs(A.determinant()) < 1e-6) return std::nullopt;
    const Eigen::Vector2d t = A.partialPivLu().solve(line_c[i] - line_c[j]);
    out[i] = line_c[j] + t(0) * line_d[j];
    if ((out[i] - previous[i]).norm() > config_.search_px) return std::nullopt;
  }
  return out;
}

std::optional<Circle> TableEdgeTracker::trackBall(const cv::Mat& bgr, const Circle& previous) {
  const double half = config_.ball_window_factor * previous.radius + config_.ball_margin_px;
  const cv::Rect roi = vision::squareRoi(previous.center.x(), previous.center.y(), half, bgr.size());
  if (roi.width < 8 || roi.height < 8) return std::nullopt;
  const int k = detector_.blur_ksize;
  if (k > 1) {
    gaussianBlurWindow(bgr, roi, k, blurred_);
  } else {
    bgr(roi).copyTo(blurred_);
  }
  // HLS and the range test on the rows that can hold a green pixel only. OpenCV's hue of a pixel
  // whose red is its largest channel (ties included: its R branch comes first) is 60° off red at
  // most, 8-bit H in [0, 30] ∪ [150, 180]; a range inside (30, 150) can only hold pixels with
  // R < max(G, B). The conversion is per pixel and each converted row is whole (its SIMD and
  // scalar parts are those of the full conversion), so the band's values are the full ones and
  // the rows outside it are all zero in the full mask too.
  const ColorRange& green = detector_.green_hls;
  int band0 = 0, band1 = blurred_.rows;  // [band0, band1)
  if (!green.wraps() && green.hue_lo > 30 && green.hue_hi < 150) {
    band0 = blurred_.rows;
    band1 = 0;
    for (int y = 0; y < blurred_.rows; ++y) {
      const std::uint8_t* p = blurred_.ptr<std::uint8_t>(y);
      bool any = false;
      for (int x = 0; x < 3 * blurred_.cols; x += 3) any |= p[x + 2] < std::max(p[x], p[x + 1]);
      if (any) {
        band0 = std::min(band0, y);
        band1 = y + 1;
      }
    }
  }
  mask_.create(blurred_.size(), CV_8UC1);
  mask_.setTo(0);
  if (band0 < band1) {
    cv::cvtColor(blurred_.rowRange(band0, band1), hls_, cv::COLOR_BGR2HLS);
    cv::Mat band = mask_.rowRange(band0, band1);
    vision::thresholdColor(hls_, green, band);
    if (band.data != mask_.ptr(band0)) band.copyTo(mask_.rowRange(band0, band1));  // a reallocated header
  }
  if (!kernel_.empty()) {
    // The opening as erosion then dilation into kept buffers: cv::morphologyEx's values (its
    // default border), without the filter engine it builds on every call.
    vision::morphologyStep(mask_, eroded_, kernel_, true);
    vision::morphologyStep(eroded_, mask_, kernel_, false);
  }
  // Contours of the mask's non-zero bounding box only: findContours pads its input with a zero
  // frame, so the crop (zeros cut off around it) gives the same contours, point for point and in
  // the same (raster) order, from fewer pixels.
  int x0 = mask_.cols, x1 = -1, y0 = mask_.rows, y1 = -1;
  for (int y = 0; y < mask_.rows; ++y) {
    const std::uint8_t* m = mask_.ptr<std::uint8_t>(y);
    int first = -1, last = -1;
    for (int x = 0; x < mask_.cols; ++x) {
      if (m[x] != 0) {
        if (first < 0) first = x;
        last = x;
      }
    }
    if (first < 0) continue;
    x0 = std::min(x0, first);
    x1 = std::max(x1, last);
    y0 = std::min(y0, y);
    y1 = y;
  }
  if (x1 < 0) return std::nullopt;  // an empty mask has no contour
  const cv::Rect nonzero(x0, y0, x1 - x0 + 1, y1 - y0 + 1);
  cv::findContours(mask_(nonzero), contours_, cv::RETR_EXTERNAL, cv::CHAIN_APPROX_NONE, roi.tl() + nonzero.tl());
  double best = 0.0;
  const std::vector<cv::Point>* ball = nullptr;
  for (const auto& c : contours_) {
    const double a = cv::contourArea(c);
    if (a > best) {
      best = a;
      ball = &c;
    }
  }
  if (ball == nullptr || best < detector_.min_ball_area_px) return std::nullopt;
  const cv::Rect box = cv::boundingRect(*ball);
  if (vision::touchesBorder(box, roi)) return std::nullopt;  // cut by the window: let the full detector look
  // Coarse circle, then the outline at sub-pixel precision: along 32 rays from the centre, the
  // crossing of the green feature G − max(R, B) half-way between inside and outside; the circle
  // is the least-squares ellipse's centre and semi-major axis of those points.
  cv::Point2f centre;
  float r = 0.0F;
  cv::minEnclosingCircle(*ball, centre, r);
  Circle c{Eigen::Vector2d(static_cast<double>(centre.x), static_cast<double>(centre.y)), static_cast<double>(r)};
  std::vector<cv::Point2f> edge;
  constexpr double kStep = 0.25;
  constexpr double reach = 3.0;
  constexpr int count = static_cast<int>(2.0 * reach / kStep) + 1;
  std::array<double, count> prof{};
  std::array<bool, count> have{};
  for (int ray = 0; ray < 32; ++ray) {
    const double ang = 2.0 * 3.14159265358979323846 * ray / 32.0;
    const Eigen::Vector2d dir(std::cos(ang), std::sin(ang));
    // The profile is read lazily (its ends, then up to the crossings): each coordinate of the
    // sample points is monotone in j, so both ends inside the image put every point inside, and
    // each value read is the one the whole profile would hold.
    have.fill(false);
    auto value = [&](int j) {
      const auto jj = static_cast<std::size_t>(j);
      if (!have[jj]) {
        const Eigen::Vector2d p = c.center + (c.radius - reach + j * kStep) * dir;
        const double u = p.x(), v = p.y();
        const int x = static_cast<int>(u), y = static_cast<int>(v);
        const double fx = u - x, fy = v - y;
        const cv::Vec3b* r0 = bgr.ptr<cv::Vec3b>(y) + x;
        const cv::Vec3b* r1 = bgr.ptr<cv::Vec3b>(y + 1) + x;
        double f[3];
        for (int q = 0; q < 3; ++q) f[q] = (1 - fy) * ((1 - fx) * r0[0][q] + fx * r0[1][q]) + fy * ((1 - fx) * r1[0][q] + fx * r1[1][q]);
        prof[jj] = f[1] - std::max(f[0], f[2]);
        have[jj] = true;
      }
      return prof[jj];
    };
    auto inside = [&](int j) {
      const Eigen::Vector2d p = c.center + (c.radius - reach + j * kStep) * dir;
      const double u = p.x(), v = p.y();
      return u >= 0.0 && v >= 0.0 && u < bgr.cols - 1.0 && v < bgr.rows - 1.0;
    };
    if (!inside(0) || !inside(count - 1)) continue;
    const double in = 0.5 * (value(0) + value(1));
    const double out = 0.5 * (value(count - 1) + value(count - 2));
    if (in - out < 0.5 * config_.min_contrast) continue;
    // Crossing of the mid level; then once more with the levels 1.25 px either side of it (the
    // shaded sphere darkens towards its limb, so the far inside plateau would bias the edge).
    auto crossing = [&](double level, int from, int to, double& s_out) {
      for (int j = std::max(from, 0); j + 1 < count && j < to; ++j) {
        const double f0 = value(j), f1 = value(j + 1);
        if (f0 >= level && f1 < level) {
          s_out = kStep * (j + (f0 - level) / (f0 - f1));
          return true;
        }
      }
      return false;
    };
    double s_edge = 0.0;
    if (!crossing(0.5 * (in + out), 0, count, s_edge)) continue;
    const int ie = static_cast<int>(std::lround(s_edge / kStep));
    constexpr int kGap = 5;
    if (ie - kGap >= 0 && ie + kGap < count) {
      const double in2 = value(ie - kGap), out2 = value(ie + kGap);
      double s2 = 0.0;
      if (in2 - out2 >= 0.5 * config_.min_contrast && crossing(0.5 * (in2 + out2), ie - kGap, ie + kGap, s2)) s_edge = s2;
    }
    const Eigen::Vector2d p = c.center + (c.radius - reach + s_edge) * dir;
    edge.emplace_back(static_cast<float>(p.x()), static_cast<float>(p.y()));
  }
  if (edge.size() >= 12) {
    const cv::RotatedRect e = cv::fitEllipse(edge);
    c.center = Eigen::Vector2d(static_cast<double>(e.center.x), static_cast<double>(e.center.y));
    c.radius = 0.5 * static_cast<double>(std::max(e.size.width, e.size.height));
  }
  return c;
}

}  // namespace viewline::vision
