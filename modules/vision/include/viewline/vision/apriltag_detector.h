#pragma once
// AprilTag detection with ViSP's vpDetectorAprilTag (tag36h11 by default):
// tag ids, corners and poses c_M_o, and a table pose from tags fixed on the
// table (the robust alternative to [M]'s red-corner pipeline).

#include <Eigen/Geometry>
#include <array>
#include <map>
#include <memory>
#include <opencv2/core.hpp>
#include <string>
#include <vector>
#include <visp3/core/vpCameraParameters.h>
#include <visp3/core/vpImage.h>
#include <visp3/detection/vpDetectorAprilTag.h>

#include "viewline/core/camera.h"
#include "viewline/vision/detection.h"
#include "viewline/vision/table_detector.h"

namespace viewline::vision {

/// Configuration of the AprilTag detector (family, pose method, tag sizes in m, corner noise).
struct AprilTagDetectorConfig {
  /// Tag family (vpDetectorAprilTag; default 36h11)
  vpDetectorAprilTag::vpAprilTagFamily family = vpDetectorAprilTag::TAG_36h11;
  /// ViSP's tag pose method
  vpDetectorAprilTag::vpPoseEstimationMethod pose_method = vpDetectorAprilTag::HOMOGRAPHY_VIRTUAL_VS;
  double tag_size_m = 0.053;              ///< side of the black square, for ids not listed below
  std::map<int, double> tag_sizes_m;      ///< per-id sizes
  float quad_decimate = 1.0F;             ///< >= 1; 2 halves the resolution of the quad search
  int threads = 1;  ///< detector threads
  double corner_sigma_px = 0.3;           ///< corner noise for the covariances
  /// The AprilTag library reports corners with pixel centres at +0.5; this much is subtracted
  /// (and the pose refined on the shifted corners). 0 = ViSP's raw corners and pose.
  double apriltag_pixel_offset = 0.5;

  void validate() const;  ///< throws core::InvalidInput naming the field
  /// Side (m) of tag `id`: its entry in tag_sizes_m, else tag_size_m.
  double sizeOf(int id) const;
};

/// One detected tag: id, corners (px), centre and pose c_M_o of the tag frame in the camera.
struct TagObservation {
  int id = -1;  ///< tag id in its family
  std::string message;                         ///< ViSP's "36h11 id: 8"
  std::array<Eigen::Vector2d, 4> corners;      ///< (u, v), in vpDetectorAprilTag::getPolygon order
  Eigen::Vector2d center = Eigen::Vector2d::Zero();  ///< ViSP's centre of gravity
  Eigen::Isometry3d c_M_o = Eigen::Isometry3d::Identity();  ///< tag frame in the camera frame
  double size_m = 0.0;  ///< side of the black square used for the pose, m
  /// The tag-frame points (±size/2, ±size/2, 0) of `corners`, matched by projecting them with
  /// c_M_o (so no assumption on ViSP's corner order).
  std::array<Eigen::Vector3d, 4> corners_3d;
};

/// pixel = mean of the tag centres; pixel_covariance for that mean.
struct AprilTagMeasurement : Measurement {
  std::vector<TagObservation> tags;  ///< every tag detected in the image
};

/// AprilTag detector on ViSP's vpDetectorAprilTag: ids, corners with covariances and poses c_M_o.
class AprilTagDetector {
public:
  /// Detector with this configuration (validated; throws core::InvalidInput).
  explicit AprilTagDetector(AprilTagDetectorConfig config = {});
  ~AprilTagDetector();
  AprilTagDetector(const AprilTagDetector&) = delete;
  AprilTagDetector& operator=(const AprilTagDetector&) = delete;

  /// Tags in a grey ViSP image with ViSP intrinsics (distortion used if the model has it).
  Result<AprilTagMeasurement> detect(const vpImage<unsigned char>& image, const vpCameraParameters& cam,
                                     core::Timestamp stamp);
  /// Same on an OpenCV image (CV_8UC1 or BGR CV_8UC3) with the camera's intrinsics.
  Result<AprilTagMeasurement> detect(const cv::Mat& image, const core::Camera& camera, core::Timestamp stamp);

  /// The configuration in use.
  const AprilTagDetectorConfig& config() const { return config_; }

private:
  AprilTagDetectorConfig config_;
  std::unique_ptr<vpDetectorAprilTag> detector_;
  vpImage<unsigned char> gray_;
  cv::Mat gray_cv_;
};

/// A tag fixed on the table: its pose in the table frame (see table_geometry.h). The tag frame is
/// vpDetectorAprilTag's (the frame of TagObservation::c_M_o: origin at the tag centre, x right and
/// y up along the printed code, z out of the tag towards the viewer). A simulated tag
/// (sim::makeTag36h11, z into the surface) needs sim::simTag_M_vispTag() on the right.
struct TagOnTable {
  int id = 0;  ///< tag id
  double size_m = 0.05;  ///< side of the black square, m
  /// Pose of the tag frame (vpDetectorAprilTag's) in the table frame
  Eigen::Isometry3d t_M_tag = Eigen::Isometry3d::Identity();
};

/// Table pose from all visible tags of a known layout: each tag's corners expressed in the table
/// frame, one joint PnP (start: the best single-tag pose, then cv::solvePnP iterative / LM on
/// undistorted pixels). Fails with NotFound when no tag of the layout is seen.
class AprilTagTableDetector {
public:
  /// Detector for a table carrying the tags of `layout`, seen by `camera` (intrinsics used to undistort).
  AprilTagTableDetector(core::Camera camera, std::vector<TagOnTable> layout,
                        AprilTagDetectorConfig config = {});

  /// Table pose c_M_t from the visible layout tags in an image (grey or BGR) captured at `stamp` (s).
  Result<TableMeasurement> detect(const cv::Mat& image, core::Timestamp stamp);
  /// The tags of the last call (all detected tags, also those outside the layout).
  const Result<AprilTagMeasurement>& lastTags() const { return last_; }

private:
  core::Camera camera_;
  std::vector<TagOnTable> layout_;
  AprilTagDetector detector_;
  Result<AprilTagMeasurement> last_ = Result<AprilTagMeasurement>::fail(FailureReason::NotFound, "");
};

}  // namespace viewline::vision
