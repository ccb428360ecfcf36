#pragma once
// Colour thresholds and small image helpers shared by the detectors.
//
// Ranges are in OpenCV's 8-bit conventions: hue in [0, 180) (degrees / 2),
// the other two channels in [0, 255]. For HSV the channels are (H, S, V), for
// HLS (H, L, S). A hue range with hue_lo > hue_hi wraps through 0 (red:
// hue_lo = 170, hue_hi = 10 selects [170, 179] ∪ [0, 10]).

#include <opencv2/core.hpp>
#include <string>

namespace viewline::vision {

/// An 8-bit hue range and two channel ranges (OpenCV conventions; hue in [0, 180) wraps when hue_lo > hue_hi).
struct ColorRange {
  int hue_lo = 0;    ///< inclusive, [0, 179]
  int hue_hi = 179;  ///< inclusive, [0, 179]; < hue_lo means the range wraps through 0
  int c1_lo = 0;     ///< 2nd channel (S for HSV, L for HLS), inclusive
  int c1_hi = 255;  ///< 2nd channel upper bound, inclusive
  int c2_lo = 0;     ///< 3rd channel (V for HSV, S for HLS), inclusive
  int c2_hi = 255;  ///< 3rd channel upper bound, inclusive

  /// True when the hue range wraps through 0 (hue_lo > hue_hi).
  bool wraps() const { return hue_lo > hue_hi; }
  /// Throws core::InvalidInput naming `what` unless every bound is in range and lo <= hi.
  void validate(const std::string& what) const;
  /// True when the pixel (h, c1, c2) lies in the range.
  bool contains(int h, int c1, int c2) const {
    const bool hue_ok = wraps() ? (h >= hue_lo || h <= hue_hi) : (h >= hue_lo && h <= hue_hi);
    return hue_ok && c1 >= c1_lo && c1 <= c1_hi && c2 >= c2_lo && c2 <= c2_hi;
  }
};

/// mask = 255 where the 3-channel 8-bit image `hxx` (HSV or HLS) lies in `range`, else 0.
/// Plain cv::inRange (twice, OR-ed, when the hue wraps).
void thresholdColor(const cv::Mat& hxx, const ColorRange& range, cv::Mat& mask);

/// Throws core::InvalidInput("<what>: ...") unless `image` is a non-empty CV_8UC3 image.
void requireBgrImage(const cv::Mat& image, const std::string& what);
/// Throws core::InvalidInput unless `image` is a non-empty CV_8UC1 or CV_8UC3 image.
void requireGrayOrBgrImage(const cv::Mat& image, const std::string& what);

/// Integer rectangle around (u, v) with the given half size, clipped to the image; empty when
/// the centre is far outside.
cv::Rect squareRoi(double u, double v, double half_size, const cv::Size& image_size);

/// True when the rectangle `box` (in image coordinates) touches the border of `frame`.
inline bool touchesBorder(const cv::Rect& box, const cv::Rect& frame) {
  return box.x <= frame.x || box.y <= frame.y || box.x + box.width >= frame.x + frame.width ||
         box.y + box.height >= frame.y + frame.height;
}

}  // namespace viewline::vision
