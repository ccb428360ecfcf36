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
//  4. rolling-ball filter (estimation::RollingBallModel): Φ, Γ, Q rediscretised every frame for
//     the actual interval and the measured a_xy (Van Loan), time update with the border clamp,
//     measurement update with y = p_t.xy when the ball was found, else prediction only; or the
//     stationary gain of the DARE (option);
//  5. the next N (= 10) positions predicted from the filtered state (clamped at the borders).
//
// Fast path (ours; option edge_tracking, corners mode): after a frame where table and ball
// were found, the next frame tracks the four sides and the ball locally (TableEdgeTracker) and
// re-solves the same PnP from the previous pose; [M]'s full pipeline runs on the first frame and
// whenever tracking fails.
//
// RollingBallTracker is step 3-5 alone (no images), so other tunings can run on the same
// measurements side by side.

#include <Eigen/Geometry>
#include <memory>
#include <opencv2/core.hpp>
#include <optional>
#include <vector>

#include "viewline/core/camera.h"
#include "viewline/estimation/kalman_filter.h"
#include "viewline/estimation/models/rolling_ball.h"
#include "viewline/estimation/state.h"
#include "viewline/tracking/track_gate.h"
#include "viewline/vision/apriltag_detector.h"
#include "viewline/scenarios/table_edge_tracker.h"
#include "viewline/vision/table_detector.h"

namespace viewline::scenarios {

/// Border-aware re-solution of the table pose (see step 1): image corners of P0..P3 (pixels),
/// the pose to start from, the table side and the border height. Returns the corrected pose.
Eigen::Isometry3d borderAwareTablePose(const core::Camera& camera, const std::array<Eigen::Vector2d, 4>& corners,
                                       const Eigen::Isometry3d& c_M_t, double side, double border_height,
                                       int iterations = 2);

/// Tilt angles (θx, θy) of a table whose orientation in the world is w_R_t = Rx(θx) Ry(θy)
/// (robots::TableTilt convention): θx = atan2(R21, R11), θy = atan2(R02, R00).
Eigen::Vector2d tiltFromTableRotation(const Eigen::Matrix3d& w_R_t);

struct RollingBallTrackerConfig {
  estimation::RollingBallModel model;      ///< σw, β, σv, L, r, N
  bool stationary_gain = false;            ///< use the DARE gain for the nominal frame period
  double nominal_period = 0.02;            ///< s, for the stationary gain
  double initial_velocity_std = 0.5;       ///< m/s, prior on the velocity at the first detection
};

/// What one step did with its measurement. The filter has no gate: the first measurement starts
/// the track (Start, no innovation), every later one is fused (Accept). The report is the
/// update's own: d = y − C x̂(t|t−), S = C P(t|t−) Cᵀ + σv² I (with the stationary gain, P(t|t−)
/// is the DARE's a-priori covariance), NIS = dᵀ S⁻¹ d with 2 degrees of freedom.
struct BallUpdate {
  tracking::GateDecision decision = tracking::GateDecision::Accept;
  estimation::UpdateReport report;
};

/// The filter part of the observer (steps 3-5).
class RollingBallTracker {
public:
  explicit RollingBallTracker(const RollingBallTrackerConfig& config);

  /// Advances to time t with the measured in-plane acceleration a_xy, fusing the ball position
  /// y (table frame, m) when present. Before the first measurement nothing is estimated.
  void step(double t, const Eigen::Vector2d& a_xy, const std::optional<Eigen::Vector2d>& y);

  bool initialized() const { return initialized_; }
  /// State (p_x, v_x, p_y, v_y, w2_x, w2_y) at the last step.
  const Eigen::VectorXd& x() const { return x_; }
  Eigen::Vector2d position() const { return {x_[0], x_[2]}; }
  Eigen::Vector2d velocity() const { return {x_[1], x_[3]}; }
  /// Covariance (time-varying filter) or the stationary filtered covariance.
  Eigen::MatrixXd P() const;
  /// The N predicted positions after the last step (one frame interval apart).
  const std::vector<Eigen::Vector2d>& predictions() const { return predictions_; }
  /// NIS of the last fused measurement (0 before any).
  double lastNis() const { return nis_; }
  /// The last step's measurement update; empty when that step had no measurement.
  const std::optional<BallUpdate>& lastUpdate() const { return last_update_; }
  int missedStreak() const { return missed_; }
  const RollingBallTrackerConfig& config() const { return config_; }

private:
  estimation::UpdateReport stationaryInnovation(const estimation::LinearTransition& tr, const Eigen::Vector2d& y) const;
  RollingBallTrackerConfig config_;
  bool initialized_ = false;
  double t_ = 0.0;
  double last_dt_ = 0.02;
  Eigen::VectorXd x_ = Eigen::VectorXd::Zero(6);
  estimation::StateEstimate state_;
  std::optional<estimation::StationaryFilter> stationary_;
  std::vector<Eigen::Vector2d> predictions_;
  double nis_ = 0.0;
  int missed_ = 0;
  std::optional<BallUpdate> last_update_;
};

enum class TablePoseSource { Corners, AprilTag };
enum class BallGeometry { KnownRadius, UnknownRadius };

struct TableBallObserverConfig {
  TablePoseSource table_pose = TablePoseSource::Corners;
  BallGeometry ball_geometry = BallGeometry::KnownRadius;
  vision::TableDetectorConfig detector;               ///< colours, kernels, refine, L, r
  double border_height = 0.02;                        ///< m, raised border above the surface (0: plain [M] PnP)
  std::vector<vision::TagOnTable> tag_layout;         ///< AprilTag alternative: tags in the table frame
  vision::AprilTagDetectorConfig tag_detector;
  RollingBallTrackerConfig tracker;
  bool edge_tracking = true;                          ///< fast path between full detections (corners mode)
  TableEdgeTrackerConfig edge_tracker;
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
  const RollingBallTracker& tracker() const { return tracker_; }
  const TableBallObserverConfig& config() const { return config_; }

private:
  void filterStep(double t, const std::optional<Eigen::Vector2d>& y);
  core::Camera camera_;
  TableBallObserverConfig config_;
  vision::TableDetector detector_;
  std::unique_ptr<vision::AprilTagTableDetector> tags_;
  RollingBallTracker tracker_;
  TableEdgeTracker edges_;
  ObserverFrame frame_;
  bool have_table_ = false;
  bool need_prior_ = true;
  Eigen::Isometry3d c_M_t_ = Eigen::Isometry3d::Identity();
};

}  // namespace viewline::scenarios
