#pragma once
// Intrinsic calibration from views of a board.
//
// OpenCV's model (cv::calibrateCamera, extended form: parameter standard deviations and
// per-view errors) is fitted first; ViSP's models are then fitted to the same points with
// vpCalibration (virtual visual servoing), initialised from OpenCV's result:
//   - perspectiveProjWithoutDistortion (px, py, u0, v0),
//   - perspectiveProjWithDistortion (+ kud, kdu: ViSP's one-coefficient radial model in each
//     direction), which is what the rest of viewline uses.

#include <Eigen/Core>
#include <opencv2/core.hpp>
#include <string>
#include <vector>
#include <visp3/core/vpCameraParameters.h>
#include <visp3/core/vpHomogeneousMatrix.h>

#include "viewline/calib/board.h"
#include "viewline/io/camera_io.h"

namespace viewline::calib {

/// One view for intrinsic calibration: its name and the detected board points.
struct ViewInput {
  std::string name;          ///< image file (for messages)
  BoardObservation observation;  ///< matched image and board points of the view
};

/// A view left out of the calibration, with the reason.
struct RejectedView {
  std::string name;  ///< image file (for messages)
  std::string reason;  ///< why it was left out (board not found, error above max_view_rms_px, ...)
};

/// Options of calibrateIntrinsics().
struct IntrinsicsOptions {
  int min_views = 3;                 ///< fewer usable views is an error
  bool fix_k3 = true;                ///< OpenCV: estimate k1 k2 p1 p2 only (k3 = 0)
  double max_view_rms_px = 3.0;      ///< views worse than this after a first fit are rejected, then refit
  bool fit_visp = true;              ///< also fit ViSP's models with vpCalibration
};

/// Result of calibrateIntrinsics(): OpenCV's model with standard deviations and ViSP's two models, with per-
/// view errors.
struct IntrinsicsResult {
  cv::Size image_size;  ///< image size, px
  // OpenCV model
  io::OpenCvIntrinsics opencv;  ///< OpenCV model: camera matrix, distortion, size, RMS
  Eigen::VectorXd std_dev;           ///< fx fy cx cy k1 k2 p1 p2 k3 ... (cv::calibrateCamera stdDeviationsIntrinsics)
  double rms_px = 0.0;               ///< overall RMS reprojection error (OpenCV model)
  std::vector<std::string> view_names;  ///< names of the views used (same order as view_rms_px)
  std::vector<double> view_rms_px;   ///< per used view
  std::vector<cv::Mat> rvecs,        ///< board rotations (Rodrigues) of the used views (OpenCV model)
                       tvecs;        ///< board translations of the used views, m (OpenCV model)
  std::vector<RejectedView> rejected;  ///< views left out, with reasons
  // ViSP models (vpCalibration)
  vpCameraParameters visp_without;  ///< ViSP model without distortion (px, py, u0, v0)
  vpCameraParameters visp_with;  ///< ViSP model with distortion (+ kud, kdu)
  double visp_without_rms_px = -1.0;  ///< RMS reprojection error of visp_without, px (-1: not fitted)
  double visp_with_rms_px = -1.0;  ///< RMS reprojection error of visp_with, px (-1: not fitted)
  std::vector<vpHomogeneousMatrix> visp_c_M_o;  ///< per used view, model with distortion

  /// Human-readable report (parameters, std devs, per-view errors, rejected views).
  std::string report() const;
};

/// Calibrates from observations of images of size `image_size`. Throws InvalidInput with the list
/// of rejection reasons when fewer than options.min_views views are usable.
IntrinsicsResult calibrateIntrinsics(const std::vector<ViewInput>& views, cv::Size image_size,
                                     const IntrinsicsOptions& options = {});

/// Reads the images, detects the board (views where it is not found are rejected with the reason),
/// checks that all images have the same size (else InvalidInput naming the odd one), calibrates.
IntrinsicsResult calibrateFromImages(const std::vector<std::string>& image_files, const BoardSpec& board,
                                     const IntrinsicsOptions& options = {});

/// Writes the ViSP XML (both models) and the OpenCV YAML; either both files appear or none.
/// Empty paths are skipped.
void saveIntrinsics(const IntrinsicsResult& r, const std::string& camera_name, const std::string& visp_xml,
                    const std::string& opencv_yaml);

/// RMS pixel error of ViSP's model over views (points projected through c_M_o and `cam`).
double vispReprojectionRms(const vpCameraParameters& cam, const std::vector<vpHomogeneousMatrix>& c_M_o,
                           const std::vector<BoardObservation>& views);

}  // namespace viewline::calib
