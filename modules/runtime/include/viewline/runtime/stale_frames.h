#pragma once
// A frozen camera: a driver that hands out its last buffer again, with a new stamp. A real
// sensor never gives two bit-identical images (its read-out noise alone changes every frame),
// so an image equal to the previous one of its camera is stale: its stamp says now, its content
// is old, and a tracker fed with it is pulled back to where the target was (ball catching with
// one of two cameras frozen for 0.2 s of each flight then misses most throws, late). The loops
// drop such a frame. A blank image (every value the same: a covered or dark camera, or a
// simulated one without sensor noise) repeats without being stale and is left alone. The comparison is a 64-bit FNV-1a hash of the pixels per camera
// (one pass over the image, no copy kept).

#include <cstddef>
#include <cstdint>
#include <cstring>
#include <opencv2/core.hpp>
#include <vector>

#include "viewline/runtime/frame_source.h"

namespace viewline::runtime {

/// Recognises a frame whose image repeats the previous image of its camera bit for bit.
class StaleFrameFilter {
public:
  /// True when `frame`'s image equals its camera's previous image (an empty image never does).
  bool repeats(const Frame& frame) {
    if (frame.image.empty()) return false;
    if (frame.camera >= last_.size()) last_.resize(frame.camera + 1, 0);
    const std::uint64_t h = hashOf(frame.image);
    const bool same = last_[frame.camera] != 0 && h == last_[frame.camera];
    last_[frame.camera] = h;
    return same && !blank(frame.image);  // the second pass only on a repeat
  }

private:
  static bool blank(const cv::Mat& image) {
    double lo = 0.0, hi = 0.0;
    cv::minMaxLoc(image.reshape(1), &lo, &hi);
    return lo == hi;
  }
  static std::uint64_t hashOf(const cv::Mat& image) {
    std::uint64_t h = 1469598103934665603ull;  // FNV-1a offset basis
    const std::size_t row_bytes = static_cast<std::size_t>(image.cols) * image.elemSize();
    for (int r = 0; r < image.rows; ++r) {
      const unsigned char* p = image.ptr<unsigned char>(r);
      std::size_t i = 0;
      for (; i + 8 <= row_bytes; i += 8) {
        std::uint64_t w;
        std::memcpy(&w, p + i, 8);
        h = (h ^ w) * 1099511628211ull;  // FNV prime
      }
      for (; i < row_bytes; ++i) h = (h ^ p[i]) * 1099511628211ull;
    }
    return h == 0 ? 1 : h;  // 0 marks "no previous image"
  }
  std::vector<std::uint64_t> last_;  // per camera: the hash of its previous image (0: none)
};

}  // namespace viewline::runtime
