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
//
// Speed: with a predicted pixel (the loop's last detection) and a fixed threshold at 50 %, the
// detector first binarises only a window of half side window_half_size_px around it, and reads
// that part of the frame instead of all of it (0.9 MB at 640x480 BGR: the full-frame pass is bound
// by that read). The window's binary image sits in the full-frame one, zero outside the window, so
// the median filter, the moments (in the full frame's 32x32 tiles) and the border test are the full
// frame's arithmetic. It returns the full-frame detection bit for bit whenever the frame's
// foreground lies inside the window, away from its edge (ScreenTargetDetector.WindowEqualsFullFrame*).
// It falls back to the full frame when the window's edge holds foreground (the blob may be cut) or
// when the window gives no valid detection (target elsewhere, occluded, too small, ...), so the
// window can only change a result when foreground lies wholly outside the window (clutter that
// would have made the full frame Ambiguous): on [T]'s screen the disc is the only dark thing.

#include <opencv2/core.hpp>

#include <Eigen/Core>
#include <cstdint>
#include <optional>
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
  /// Half side of the window around a predicted pixel, full-resolution px (0: always the full frame)
  int window_half_size_px = 64;

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

/// medianBlobMoments of an image whose foreground lies inside `foreground_roi` (the pixels outside it must be 0):
/// only the roi is searched for it; the result is the whole image's, bit for bit.
BinaryBlobMoments medianBlobMoments(const cv::Mat& binary, int ksize, std::vector<std::int32_t>& scratch,
                                    const cv::Rect& foreground_roi);

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

  /// `image` is grey CV_8UC1 or BGR CV_8UC3, captured at `stamp`. With `predicted` (full-resolution pixel,
  /// e.g. the last detection) the detector first looks in a window around it and falls back to the full frame
  /// (header: the same result whenever the frame's foreground lies inside the window).
  Result<ScreenTargetMeasurement> detect(const cv::Mat& image, core::Timestamp stamp,
                                         const std::optional<Eigen::Vector2d>& predicted = std::nullopt);

  /// True when the last detect() returned the window's result (no full-frame pass).
  bool usedWindow() const { return used_window_; }

  /// The configuration in use.
  const ScreenTargetDetectorConfig& config() const { return config_; }

private:
  /// The window pass: its detection, or nullopt to fall back to the full frame.
  std::optional<Result<ScreenTargetMeasurement>> detectInWindow(const cv::Mat& cropped, const Eigen::Vector2d& predicted,
                                                                core::Timestamp stamp);
  /// The measurement from the filtered blob's moments (binary_ holds the half-resolution image).
  Result<ScreenTargetMeasurement> measure(const BinaryBlobMoments& m, double level, core::Timestamp stamp) const;

  ScreenTargetDetectorConfig config_;
  cv::Mat gray_, small_, binary_;
  bool binary_clean_ = false;  ///< binary_ is all 0 (the window pass's precondition)
  bool used_window_ = false;
  std::vector<std::int32_t> scratch_;  ///< medianBlobMoments' buffers (kept: no allocation per frame)
};

}  // namespace viewline::vision
