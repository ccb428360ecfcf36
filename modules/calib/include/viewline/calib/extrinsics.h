#pragma once
// Board poses and multi-camera rig extrinsics.

#include <Eigen/Geometry>
#include <optional>
#include <string>
#include <vector>

#include "viewline/calib/board.h"
#include "viewline/core/camera.h"
#include "viewline/io/camera_io.h"

namespace viewline::calib {

/// Intrinsics used to compute poses: OpenCV's camera matrix and distortion coefficients
/// (from an OpenCV YAML), or a ViSP camera converted exactly (no distortion) or through
/// ViSP's own projection (with kud).
struct PoseCamera {
  cv::Mat K;  ///< 3x3 CV_64F
  cv::Mat D;  ///< distortion coefficients (OpenCV), empty = none
  std::optional<vpCameraParameters> visp;  ///< when set, poses are refined with ViSP's model (vpPose)

  /// Camera from OpenCV intrinsics (K and distortion coefficients).
  static PoseCamera fromOpenCv(const io::OpenCvIntrinsics& o);
  /// Camera from ViSP parameters: K without distortion, poses refined with ViSP's model (kud) when it has one.
  static PoseCamera fromVisp(const vpCameraParameters& cam);
  /// Normalised (undistorted) coordinates of pixels.
  std::vector<cv::Point2f> normalize(const std::vector<cv::Point2f>& px) const;
  /// Pixels of board points seen from c_M_o.
  /// (double precision: used inside numeric derivatives).
  std::vector<cv::Point2d> project(const std::vector<cv::Point3f>& pts, const Eigen::Isometry3d& c_M_o) const;
};

/// Pose of a board (or tag) in a camera, with its reprojection error.
struct BoardPose {
  Eigen::Isometry3d c_M_o = Eigen::Isometry3d::Identity();  ///< board frame o in the camera: p_c = c_M_o * p_o
  double rms_px = 0.0;  ///< RMS reprojection error after refinement, px
  std::size_t points = 0;  ///< number of points used
};

/// Pose of the board (or of one tag) from an observation: PnP (IPPE for planar targets)
/// followed by Levenberg-Marquardt refinement on the reprojection error.
BoardPose estimatePose(const PoseCamera& cam, const std::vector<cv::Point3f>& object_points,
                       const std::vector<cv::Point2f>& image_points);

/// Poses of each detected tag (board type apriltag): id -> pose of the tag frame (ViSP's).
std::map<int, BoardPose> estimateTagPoses(const PoseCamera& cam, const cv::Mat& gray, const BoardSpec& board);

// ---- rig -------------------------------------------------------------------------------------

/// Observations of one board by several cameras at the same instants: views[k][i] is what
/// camera i saw at instant k (nullopt when it did not see the board).
struct RigObservations {
  std::vector<PoseCamera> cameras;  ///< intrinsics of camera i
  /// Views[k][i]: what camera i saw at instant k (nullopt: not seen)
  std::vector<std::vector<std::optional<BoardObservation>>> views;
};

/// Result of calibrateRig(): camera poses relative to the reference camera, board poses and errors.
struct RigResult {
  std::vector<Eigen::Isometry3d> c_M_ref;     ///< camera i pose: maps reference-camera coords to camera i
  std::vector<Eigen::Isometry3d> ref_M_board; ///< board pose per instant in the reference camera (identity when unseen)
  std::vector<double> camera_rms_px;          ///< reprojection RMS per camera after the joint refinement
  double rms_px = 0.0;                        ///< overall
  std::vector<std::size_t> views_used;        ///< per camera
  int iterations = 0;  ///< Levenberg-Marquardt iterations of the joint refinement
};

/// Joint estimation of the camera poses (reference = camera `reference`) and of the board poses
/// from all views, intrinsics fixed: initial guess from per-view PnP (median of relative poses),
/// then Levenberg-Marquardt on the reprojection error of every point in every camera.
/// Every camera must share at least `min_shared` instants with the reference (directly; chains are
/// not supported) or InvalidInput is thrown naming the camera.
RigResult calibrateRig(const RigObservations& obs, std::size_t reference = 0, std::size_t min_shared = 3);

/// Average of rotations (chordal L2 mean via quaternions) and of translations.
Eigen::Isometry3d averagePoses(const std::vector<Eigen::Isometry3d>& poses);

/// b_M_g: the "ground" frame (z up, same origin and x axis) of a board lying printed side up on
/// the floor. Boards have z into the paper, so this is a half turn about x; a single AprilTag's
/// frame (ViSP) already has z out of the paper, so it is the identity.
Eigen::Isometry3d groundFromBoard(BoardType type);

/// Camera to ground (SPEC §3: the camera's rotation to the ground), from poses c_M_o of a board
/// or tag lying flat on the floor, printed side up (averaged over the views).
struct GroundResult {
  Eigen::Isometry3d c_M_g = Eigen::Isometry3d::Identity();  ///< ground frame (z up, origin on the board) in the camera
  double height_m = 0.0;      ///< camera centre above the ground plane
  double pitch_rad = 0.0;     ///< optical axis below the horizontal (positive looking down)
  double roll_rad = 0.0;      ///< rotation about the optical axis: camera x axis above the horizontal
  double spread_rad = 0.0;    ///< largest angle between a view's rotation and the average
  /// Gravity direction (unit, pointing down) in camera coordinates.
  Eigen::Vector3d down_c() const { return c_M_g.linear() * Eigen::Vector3d(0, 0, -1); }
};
/// Ground frame, height, pitch and roll of the camera from poses c_M_o of a board lying flat on the floor
/// (throws InvalidInput for no pose).
GroundResult cameraToGround(const std::vector<Eigen::Isometry3d>& c_M_o, BoardType type);

}  // namespace viewline::calib
