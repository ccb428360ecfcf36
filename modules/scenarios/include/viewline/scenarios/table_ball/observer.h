#pragma once
// [M]'s table-ball observer (SPEC §3, §1.2): image -> table pose -> ball on the table ->
// rolling-ball Kalman filter -> N predicted positions.
//
// Per frame (capture time t, known camera-to-ground rotation c_R_w from the head's kinematics):
//  1. table pose c_M_t: [M]'s red-corner pipeline + solvePnP(AP3P) (vision::TableDetector), or
//     the AprilTag alternative (vision::AprilTagTableDetector, tags fixed around the borders);
//     the square's quarter-turn ambiguity is resolved with the arm's nominal pose as a prior;
//     Border-aware PnP (ours, beyond [M]): the raised borders (height h) hide a strip of the red
//     surface along every side whose border lies between the camera and the surface, so the
//     red quadrilateral's corners are not (±L/2, ±L/2, 0). With the camera centre at t' in the
//     table frame, the border's top inner edge casts (from the camera) a line on z = 0 shifted
//     inwards by  δ = h · max(0, t'·n − L/2) / (t'_z − h)  (n the side's outward normal), the
//     same along the whole side; the object corners are moved accordingly and the pose is
//     re-solved (Gauss-Newton on the reprojection error from the previous solution, twice).
//     Without it a 2 cm border seen from a head 0.45 m away tilts the pose by about a degree.
//  2. ball on the table from its image circle: cone half-angle α, d = r / sin α (the corrected
//     [M] eq 4.12), p_t = t' + d v1 with t' = −Rᵀ t, v1 = Rᵀ v̂ (vision::ballOnTableKnownRadius);
//     the unknown-radius variant solves r from z = r first;
//  3. measured tilt: table_R_world = c_R_tᵀ c_R_w, input a_xy = (5/7)[table_R_world g_w]_xy
//     (estimation::rollingBallAcceleration). Without a table pose the last one is kept;
//  4-5. tracking::RollingBallTracker: the rolling-ball filter (estimation::RollingBallModel)
//     fed y = p_t.xy when the ball was found, else prediction only, and the next N (= 10)
//     predicted positions.
//
// Fast path (ours; option edge_tracking, corners mode): after a frame where table and ball
// were found, the next frame tracks the four sides and the ball locally (TableEdgeTracker) and
// re-solves the same PnP from the previous pose; [M]'s full pipeline runs on the first frame and
// whenever tracking fails (vision::TableEdgeTracker).

#include <Eigen/Geometry>
#include <memory>
#include <opencv2/core.hpp>
#include <optional>
#include <vector>

#include "viewline/core/camera.h"
#include "viewline/tracking/rolling_ball_tracker.h"
#include "viewline/vision/apriltag_detector.h"
#include "viewline/vision/table_detector.h"
#include "viewline/vision/table_edge_tracker.h"

namespace viewline::scenarios {

/// Border-aware re-solution of the table pose (see step 1): image corners of P0..P3 (pixels),
/// the pose to start from, the table side and the border height. Returns the corrected pose.
Eigen::Isometry3d borderAwareTablePose(const core::Camera& camera, const std::array<Eigen::Vector2d, 4>& corners,
                                       const Eigen::Isometry3d& c_M_t, double side, double border_height,
                                       int iterations = 2);

/// Tilt angles (θx, θy) of a table whose orientation in the world is w_R_t = Rx(θx) Ry(θy)
/// (robots::TableTilt convention): θx = atan2(R21, R11), θy = atan2(R02, R00).
Eigen::Vector2d tiltFromTableRotation(const Eigen::Matrix3d& w_R_t);

enum class TablePoseSource { Corners, AprilTag };
enum class BallGeometry { KnownRadius, UnknownRadius };

struct TableBallObserverConfig {
  TablePoseSource table_pose = TablePoseSource::Corners;
  BallGeometry ball_geometry = BallGeometry::KnownRadius;
  vision::TableDetectorConfig detector;               ///< colours, kernels, refine, L, r
  double border_height = 0.02;                        ///< m, raised border above the surface (0: plain [M] PnP)
  std::vector<vision::TagOnTable> tag_layout;         ///< AprilTag alternative: tags in the table frame
  vision::AprilTagDetectorConfig tag_detector;
  tracking::RollingBallTrackerConfig tracker;  ///< the rolling-ball filter (steps 4-5)
  bool edge_tracking = true;                          ///< fast path between full detections (corners mode)
  vision::TableEdgeTrackerConfig edge_tracker;  ///< the fast path's settings
  Eigen::Vector3d gravity_w = Eigen::Vector3d(0.0, 0.0, -9.81);
};

/// What the observer made of one frame.
struct ObserverFrame {
  double t = 0.0;
  bool image = false;                    ///< false: no image this step (dropped frame)
  bool table_found = false;
  bool tracked = false;                  ///< table and ball came from the fast path
  bool ball_found = false;
  std::string failure;                   ///< why the table or the ball was not measured
  Eigen::Isometry3d c_M_t = Eigen::Isometry3d::Identity();  ///< last valid table pose
  std::array<Eigen::Vector2d, 4> corners{};  ///< detected corners (corner pipeline)
  std::optional<vision::Circle> ball_circle;
  std::optional<vision::Circle> ball_circle_prev;  ///< circle of a found ball (seeds the fast path)
  Eigen::Vector2d measured = Eigen::Vector2d::Constant(std::numeric_limits<double>::quiet_NaN());
  Eigen::Vector2d measured_tilt = Eigen::Vector2d::Zero();  ///< (θx, θy) from the table pose
  Eigen::Vector2d a_xy = Eigen::Vector2d::Zero();
  bool estimate_valid = false;
  Eigen::VectorXd x = Eigen::VectorXd::Zero(6);
  std::vector<Eigen::Vector2d> predictions;
  double seconds = 0.0;                  ///< wall-clock cost of detection + filter
};

class TableBallObserver {
public:
  TableBallObserver(const core::Camera& camera, const TableBallObserverConfig& config);
  ~TableBallObserver();
  TableBallObserver(const TableBallObserver&) = delete;
  TableBallObserver& operator=(const TableBallObserver&) = delete;

  /// One frame: BGR image captured at t, camera-to-ground rotation c_R_w at that instant, and
  /// the table pose expected from the arm's kinematics (resolves the square's quarter turns;
  /// used when the table was lost or on the first frame).
  const ObserverFrame& process(const cv::Mat& bgr, double t, const Eigen::Matrix3d& c_R_w,
                               const Eigen::Isometry3d& c_M_t_nominal);
  /// A step without an image (dropped frame): prediction only.
  const ObserverFrame& predictOnly(double t);

  const ObserverFrame& last() const { return frame_; }
  const tracking::RollingBallTracker& tracker() const { return tracker_; }
  const TableBallObserverConfig& config() const { return config_; }

private:
  void filterStep(double t, const std::optional<Eigen::Vector2d>& y);
  core::Camera camera_;
  TableBallObserverConfig config_;
  vision::TableDetector detector_;
  std::unique_ptr<vision::AprilTagTableDetector> tags_;
  tracking::RollingBallTracker tracker_;
  vision::TableEdgeTracker edges_;
  ObserverFrame frame_;
  bool have_table_ = false;
  bool need_prior_ = true;
  Eigen::Isometry3d c_M_t_ = Eigen::Isometry3d::Identity();
};

}  // namespace viewline::scenarios
