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
//  2. ball on the table from its image circle, three models: known_radius, cone half-angle α,
//     d = r / sin α (the corrected [M] eq 4.12), p_t = t' + d v1 with t' = −Rᵀ t, v1 = Rᵀ v̂
//     (vision::ballOnTableKnownRadius); unknown_radius solves r from z = r first; table_plane
//     (shipped; ours) uses the cone's axis only: the centre of a ball resting on the table lies
//     on the plane z = r of the table frame, so p_t = t' + s v1 with s = (r − t'_z) / v1_z
//     (ballOnTablePlane). The depth then comes from the table pose, not from the circle's size:
//     α is 0.05 px of a 9 px radius off per 0.5 % (the edge of a shaded, blurred sphere sits a
//     little inside its limb), and 0.5 % of d ≈ 0.45 m is the 1.5-2 mm depth bias the known-radius
//     model had; the axis (the mid-point of the radial diameter) is unbiased by such an edge;
//  2b. table pose filter (ours; option table_pose_time_constant τ > 0): the table's pose in the
//     camera is also known from kinematics, c_M_t_kin = c_M_w(t) w_M_t(θ) (the head's measured
//     sway on the calibrated rest pose, the arm's table pose at the tilt θ its wrist is driven
//     to), up to a slowly varying error (camera calibration, arm kinematics) that the per-frame
//     PnP pose sees as a constant offset under its own frame-to-frame noise (0.2-0.3° of
//     rotation, correlated over ~2 frames, ~0.25 mm on the ball; the kinematic pose with the
//     true tilt puts 0.06 mm of noise on the ball and a 1.3 mm calibration offset). The offset
//     Δ = c_M_t_meas c_M_t_kin⁻¹ (camera frame; rotation vector ω and translation τ) is
//     estimated by an exponential average of the per-frame residuals, gain 1 − exp(−dt/τ) (the
//     steady Kalman gain of a random-walk offset: complementary filtering of kinematics and
//     vision; a residual far from the estimate is a wrong pose and skipped), and the ball and
//     the tilt use c_M_t = Δ̂ c_M_t_kin, also in frames where the
//     table was not found. `measured` is the ball on the filtered pose (the filter fuses it);
//     `measured_own_pose` stays the ball on this frame's own PnP pose, the raw measurement
//     (measurement_rmse_mm). τ = 0: the per-frame pose throughout ([M]);
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

/// Ball centre on the table (m, table frame; z = r) from its image circle by the table-plane
/// model (step 2): the cone axis through the circle's radial diameter meets the plane z = r of
/// the table pose c_M_t. Nullopt when the axis is parallel to the table or meets it behind the
/// camera.
std::optional<Eigen::Vector3d> ballOnTablePlane(const core::Camera& camera, const vision::Circle& circle,
                                                const Eigen::Isometry3d& c_M_t, double ball_radius);

/// The table pose filter of step 2b: a camera-frame offset Δ between the measured table pose and
/// the kinematic one, averaged over frames with time constant τ (s).
class TablePoseOffsetFilter {
public:
  /// rad: a residual whose rotation is farther than this from the estimate is a wrong pose (a
  /// quarter turn, a bad corner), not noise (the PnP's is ~0.25°).
  static constexpr double kGateRotation = 0.035;
  /// m: the same for the residual's translation (0.45 m x 2° is 16 mm).
  static constexpr double kGateTranslation = 0.03;
  /// Gated residuals in a row after which the offset restarts from the newest one (the
  /// kinematics changed, e.g. the arm was re-mounted).
  static constexpr int kRestartAfter = 10;

  /// `time_constant`: τ of the exponential average, s (> 0).
  explicit TablePoseOffsetFilter(double time_constant);
  /// Folds in the residual of a table pose measured at t (s): c_M_t_meas c_M_t_kin⁻¹ (the first
  /// one is taken as it is; one outside the gate is skipped, kRestartAfter in a row restart).
  /// Returns false when the residual was skipped.
  bool update(double t, const Eigen::Isometry3d& c_M_t_measured, const Eigen::Isometry3d& c_M_t_kinematic);
  /// Residuals skipped by the gate so far.
  int gated() const { return gated_; }
  /// True once a measured pose has been folded in.
  bool valid() const { return valid_; }
  /// The filtered table pose Δ̂ c_M_t_kin for a kinematic pose (camera frame; identity offset before any update).
  Eigen::Isometry3d apply(const Eigen::Isometry3d& c_M_t_kinematic) const;
  /// The estimated offset's rotation vector (rad, camera frame).
  const Eigen::Vector3d& rotation() const { return omega_; }
  /// The estimated offset's translation (m, camera frame).
  const Eigen::Vector3d& translation() const { return tau_; }

private:
  double time_constant_;
  bool valid_ = false;
  int gated_ = 0, gated_in_a_row_ = 0;
  double t_ = 0.0;
  Eigen::Vector3d omega_ = Eigen::Vector3d::Zero();
  Eigen::Vector3d tau_ = Eigen::Vector3d::Zero();
};

/// Tilt angles (θx, θy) of a table whose orientation in the world is w_R_t = Rx(θx) Ry(θy)
/// (robots::TableTilt convention): θx = atan2(R21, R11), θy = atan2(R02, R00).
Eigen::Vector2d tiltFromTableRotation(const Eigen::Matrix3d& w_R_t);

/// Where the table pose comes from.
enum class TablePoseSource {
  Corners,   ///< [M]'s red-surface corners + solvePnP (vision::TableDetector)
  AprilTag,  ///< AprilTags fixed around the borders (vision::AprilTagTableDetector)
};
/// How the ball's position on the table is found from its image circle.
enum class BallGeometry {
  KnownRadius,    ///< d = r / sin α with the configured radius ([M] eq 4.12, corrected)
  UnknownRadius,  ///< r solved from the contact condition z = r first
  TablePlane,     ///< the cone's axis meets the plane z = r of the table (depth from the table pose)
};

/// Settings of TableBallObserver.
struct TableBallObserverConfig {
  TablePoseSource table_pose = TablePoseSource::Corners;  ///< corners ([M]) or AprilTags
  BallGeometry ball_geometry = BallGeometry::TablePlane;  ///< how the ball's depth is found
  vision::TableDetectorConfig detector;               ///< colours, kernels, refine, L, r
  double border_height = 0.02;                        ///< m, raised border above the surface (0: plain [M] PnP)
  std::vector<vision::TagOnTable> tag_layout;         ///< AprilTag alternative: tags in the table frame
  vision::AprilTagDetectorConfig tag_detector;        ///< AprilTag alternative: detector settings
  tracking::RollingBallTrackerConfig tracker;  ///< the rolling-ball filter (steps 4-5)
  bool edge_tracking = true;                          ///< fast path between full detections (corners mode)
  /// s, time constant τ of the table pose filter (step 2b); 0: the per-frame PnP pose ([M]).
  double table_pose_time_constant = 0.0;
  vision::TableEdgeTrackerConfig edge_tracker;  ///< the fast path's settings
  Eigen::Vector3d gravity_w = Eigen::Vector3d(0.0, 0.0, -9.81);  ///< gravity in the world frame, m/s²
};

/// What the observer made of one frame.
struct ObserverFrame {
  double t = 0.0;                        ///< capture time stamp, s
  bool image = false;                    ///< false: no image this step (dropped frame)
  bool table_found = false;              ///< a table pose was measured in this frame
  bool tracked = false;                  ///< table and ball came from the fast path
  bool ball_found = false;               ///< a ball position on the table was measured
  std::string failure;                   ///< why the table or the ball was not measured
  Eigen::Isometry3d c_M_t = Eigen::Isometry3d::Identity();  ///< table pose the ball and tilt used (filtered with step 2b)
  std::array<Eigen::Vector2d, 4> corners{};  ///< detected corners (corner pipeline)
  std::optional<vision::Circle> ball_circle;        ///< the ball's image circle (pixels), when detected
  std::optional<vision::Circle> ball_circle_prev;  ///< circle of a found ball (seeds the fast path)
  /// Measured ball position on the table (m, table frame), the one the filter fused: on the
  /// filtered table pose with step 2b; NaN when not measured.
  Eigen::Vector2d measured = Eigen::Vector2d::Constant(std::numeric_limits<double>::quiet_NaN());
  /// The raw measurement: the ball on this frame's own PnP table pose (m, table frame; equal to
  /// `measured` without step 2b); NaN when not measured or off the table.
  Eigen::Vector2d measured_own_pose = Eigen::Vector2d::Constant(std::numeric_limits<double>::quiet_NaN());
  Eigen::Vector2d measured_tilt = Eigen::Vector2d::Zero();  ///< (θx, θy) from the table pose
  Eigen::Vector2d a_xy = Eigen::Vector2d::Zero();  ///< in-plane acceleration fed to the filter, m/s² (table frame)
  bool estimate_valid = false;           ///< the filter has started (x and predictions are valid)
  Eigen::VectorXd x = Eigen::VectorXd::Zero(6);  ///< filter state (p_x, v_x, p_y, v_y, w2_x, w2_y), table frame
  std::vector<Eigen::Vector2d> predictions;  ///< the next N predicted positions (m, table frame)
  double seconds = 0.0;                  ///< wall-clock cost of detection + filter
};

/// CPU time spent in each stage of one TableBallObserver::process call (s, by the clock passed
/// in), for the latency bench; a stage that did not run this frame keeps 0.
struct ObserverStageTimes {
  double table = 0.0;   ///< table: edge tracking of the four sides (fast path) or the full detection (table and ball)
  double ball = 0.0;    ///< ball: the windowed ball tracker (fast path; the full detection counts under table)
  double pose = 0.0;    ///< border-aware PnP refinement of the table pose
  double geometry = 0.0;  ///< table pose filter, tilt and the ball on the table
  double filter = 0.0;  ///< the rolling-ball filter step and predictions
};

/// [M]'s observer: one camera image in, table pose, ball on the table and the filtered and
/// predicted ball out (the steps at the top of this file).
class TableBallObserver {
public:
  /// `camera`: the calibrated head camera (intrinsics; its pose is given per frame through c_R_w
  /// and the table pose). Throws core::InvalidInput for an invalid config.
  TableBallObserver(const core::Camera& camera, const TableBallObserverConfig& config);
  ~TableBallObserver();
  TableBallObserver(const TableBallObserver&) = delete;
  TableBallObserver& operator=(const TableBallObserver&) = delete;

  /// One frame: BGR image captured at t, camera-to-ground rotation c_R_w at that instant, and
  /// the table pose expected from the arm's kinematics at t (resolves the square's quarter turns;
  /// the kinematic pose of the table pose filter, step 2b).
  /// With `clock` (seconds, e.g. thread CPU time) and `times`, also the time of each stage.
  const ObserverFrame& process(const cv::Mat& bgr, double t, const Eigen::Matrix3d& c_R_w,
                               const Eigen::Isometry3d& c_M_t_nominal, double (*clock)() = nullptr,
                               ObserverStageTimes* times = nullptr);
  /// A step without an image (dropped frame): prediction only.
  const ObserverFrame& predictOnly(double t);

  /// The last frame's result.
  const ObserverFrame& last() const { return frame_; }
  /// The rolling-ball filter (state, covariance, gate counts).
  const tracking::RollingBallTracker& tracker() const { return tracker_; }
  /// The config the observer was built with.
  const TableBallObserverConfig& config() const { return config_; }

private:
  void filterStep(double t, const std::optional<Eigen::Vector2d>& y);
  std::optional<Eigen::Vector2d> ballOnTable(const vision::Circle& circle, const Eigen::Isometry3d& c_M_t) const;
  core::Camera camera_;
  TableBallObserverConfig config_;
  vision::TableDetector detector_;
  std::unique_ptr<vision::AprilTagTableDetector> tags_;
  tracking::RollingBallTracker tracker_;
  vision::TableEdgeTracker edges_;
  ObserverFrame frame_;
  bool have_table_ = false;
  bool need_prior_ = true;
  Eigen::Isometry3d c_M_t_ = Eigen::Isometry3d::Identity();  // the last PnP pose (the fast path starts from it)
  std::optional<TablePoseOffsetFilter> pose_filter_;
};

}  // namespace viewline::scenarios
