#pragma once
// Camera intrinsics files.
//  - ViSP camera XML (vpXmlParserCamera): one <camera> per name and image size, holding the
//    model without distortion (px, py, u0, v0) and/or with distortion (+ kud, kdu).
//  - OpenCV YAML (cv::FileStorage), as written by OpenCV's calibration sample and
//    calibrate-camera: camera_matrix, distortion_coefficients, image_width, image_height.
// Writers are atomic (tmp + rename): an error never leaves a partial file.

#include <Eigen/Core>
#include <optional>
#include <string>
#include <visp3/core/vpCameraParameters.h>

namespace viewline::io {

/// Which of ViSP's two camera models to read or write (vpCameraParameters projection type).
enum class Projection { WithoutDistortion, WithDistortion };

/// "without_distortion" / "with_distortion" (the rig file and config spelling).
std::string toString(Projection p);
Projection projectionFromString(const std::string& s);  ///< throws InvalidInput on anything else

/// One camera read from a ViSP XML file: intrinsics of the requested model and the image size.
struct CameraXml {
  vpCameraParameters intrinsics;  ///< px, py, u0, v0 (and kud, kdu with distortion)
  unsigned width = 0;  ///< image width, px
  unsigned height = 0;  ///< image height, px
};

/// Reads camera `camera_name` from a ViSP XML file. width/height 0 = any size (the file's
/// size is returned). Throws InvalidInput naming the file, camera and model when not found.
CameraXml loadVispCameraXml(const std::string& path, const std::string& camera_name, Projection projection,
                            unsigned width = 0, unsigned height = 0);

/// Writes a ViSP XML file (replacing any existing file) with the model without distortion and,
/// when given, the model with distortion, for one camera name and image size.
/// `additional_info` is XML elements put into the file's `<additional_information>`, e.g.
/// `<reprojection_error_px>0.21</reprojection_error_px>` (plain text is dropped by ViSP).
void saveVispCameraXml(const std::string& path, const std::string& camera_name,
                       const vpCameraParameters& without_distortion,
                       const std::optional<vpCameraParameters>& with_distortion, unsigned width, unsigned height,
                       const std::string& additional_info = {});
/// Same, writing to exactly `path` without staging (for use with io::StagedFiles::stage()).
void writeVispCameraXmlTo(const std::string& path, const std::string& camera_name,
                          const vpCameraParameters& without_distortion,
                          const std::optional<vpCameraParameters>& with_distortion, unsigned width,
                          unsigned height, const std::string& additional_info = {});

/// Intrinsics as OpenCV's calibration writes them (cv::FileStorage YAML/XML).
struct OpenCvIntrinsics {
  Eigen::Matrix3d camera_matrix = Eigen::Matrix3d::Identity();  ///< K = [fx 0 cx; 0 fy cy; 0 0 1], px
  Eigen::VectorXd distortion = Eigen::VectorXd::Zero(5);  ///< k1 k2 p1 p2 [k3 [k4 k5 k6 ...]]
  unsigned width = 0;  ///< image width, px
  unsigned height = 0;  ///< image height, px
  double rms_px = -1.0;  ///< avg_reprojection_error when present, else -1
};

/// Reads an OpenCV calibration YAML/XML (cv::FileStorage). Throws naming the file and node.
OpenCvIntrinsics loadOpenCvIntrinsics(const std::string& path);
/// Writes one (atomically); the file's extension picks YAML (.yaml/.yml) or XML.
void saveOpenCvIntrinsics(const std::string& path, const OpenCvIntrinsics& intrinsics);
/// Same, to exactly `path` (for io::StagedFiles); `format_path` selects the format by extension.
void writeOpenCvIntrinsicsTo(const std::string& path, const OpenCvIntrinsics& intrinsics,
                             const std::string& format_path);

/// ViSP parameters from an OpenCV camera matrix when the distortion is negligible
/// (all coefficients below `tolerance`); otherwise throws naming `what`, because ViSP's
/// one-coefficient radial model cannot represent OpenCV's.
vpCameraParameters toVispWithoutDistortion(const OpenCvIntrinsics& intrinsics, const std::string& what,
                                           double tolerance = 1e-12);

}  // namespace viewline::io
