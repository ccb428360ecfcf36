#pragma once
// [T]'s detector of a dark disc projected on a bright screen (SPEC §5):
// crop the margins, resize by 50 %, binarise, median filter, centroid.
//
// Coordinates: cv::resize with INTER_AREA and factor s = 1/2 makes half-
// resolution pixel i the mean of full pixels 2i and 2i+1, whose centre is
// 2i + 0.5. So a half-resolution position q maps back to
//     u = crop_left + (q + 0.5) / s - 0.5      (= crop_left + 2 q + 0.5),
// likewise v with crop_top.
//
// Covariance: the centroid of a disc of radius R whose boundary is displaced by
// independent errors of std σe per boundary pixel has var σe² / (π R) per axis
// (see ball_detector.h); at half resolution one boundary pixel is 2 full-res
// pixels, so σe is taken as edge_noise_px / scale in full-resolution pixels and
// the boundary sample count halves: var = (σe/s)² / (π R s).

#include <opencv2/core.hpp>

#include <cstdint>
#include <vector>

#include "viewline/vision/detection.h"

namespace viewline::vision {

/// Configuration of [T]'s dark-disc-on-screen detector: crop, scale, threshold, median filter, gates and noise.
struct ScreenTargetDetectorConfig {
  int crop_left = 0,    ///< margin removed on the left, px
      crop_top = 0,     ///< margin removed at the top, px
      crop_right = 0,   ///< margin removed on the right, px
      crop_bottom = 0;  ///< margin removed at the bottom, px
  double scale = 0.5;      ///< resize factor ([T]: 50 %)
  int threshold = -1;      ///< binarisation level on the grey image, or < 0 for Otsu
  bool dark_target = true; ///< the target is darker than the screen
  int median_ksize = 5;    ///< median filter aperture (odd >= 3, or 1 = none)
  double min_area_px = 20.0;     ///< full-resolution pixels; fewer -> TooSmall
  double min_fill = 0.5;         ///< foreground / bounding-box area below this -> Ambiguous
  double edge_noise_px = 0.5;    ///< σe at the processing resolution
  double min_sigma_px = 0.1;  ///< σ floor of the centre, px

  void validate() const;  ///< throws core::InvalidInput naming the field
};

/// The detected screen target: centroid pixel (full resolution) with covariance, area and fill.
struct ScreenTargetMeasurement : Measurement {
  double area_px = 0.0;  ///< foreground area in full-resolution pixels
  double fill = 0.0;     ///< foreground / bounding-box area (π/4 for a disc)
  int threshold_used = 0;  ///< binarisation level actually used (Otsu's when config.threshold < 0)
};

/// The centroid moments and bounding box of a median-filtered binary image, in full-image pixels.
struct BinaryBlobMoments {
  double m00 = 0.0,  ///< foreground pixel count, as cv::moments(filtered, true).m00
         m10 = 0.0,  ///< Σ x over the foreground (px), as cv::moments(filtered, true).m10
         m01 = 0.0;  ///< Σ y over the foreground (px), as cv::moments(filtered, true).m01
  cv::Rect box;      ///< cv::boundingRect(filtered): the foreground's bounding box (empty: no foreground)
};

/// Median filter of aperture `ksize` (odd, 1 = none) of a binary CV_8UC1 image (values 0 or 255), then the
/// moments and box of the result, equal bit for bit to cv::medianBlur + cv::moments(binary = true) +
/// cv::boundingRect (OpenCV 4.6), but only over the foreground's neighbourhood. `scratch` is reused.
BinaryBlobMoments medianBlobMoments(const cv::Mat& binary, int ksize, std::vector<std::int32_t>& scratch);

/// Grey, 50 % INTER_AREA resize and a fixed threshold `level` in one pass over an 8-bit grey or BGR image of even
/// size: equal bit for bit to cv::cvtColor(BGR2GRAY) + cv::resize(0.5, INTER_AREA) + cv::threshold(level, 255,
/// dark_target ? THRESH_BINARY_INV : THRESH_BINARY) (OpenCV 4.6). `binary` gets the (cols/2 x rows/2) result.
void halfScaleBinary(const cv::Mat& image, int level, bool dark_target, cv::Mat& binary);

/// [T]'s screen target detector: crop, half-resolution, binarise, median filter, centroid.
class ScreenTargetDetector {
public:
  /// Detector with this configuration (validated; throws core::InvalidInput).
  explicit ScreenTargetDetector(ScreenTargetDetectorConfig config = {});

  /// `image` is grey CV_8UC1 or BGR CV_8UC3, captured at `stamp`.
  Result<ScreenTargetMeasurement> detect(const cv::Mat& image, core::Timestamp stamp);

  /// The configuration in use.
  const ScreenTargetDetectorConfig& config() const { return config_; }

private:
  ScreenTargetDetectorConfig config_;
  cv::Mat gray_, small_, binary_;
  std::vector<std::int32_t> scratch_;  ///< medianBlobMoments' buffers (kept: no allocation per frame)
};

}  // namespace viewline::vision
