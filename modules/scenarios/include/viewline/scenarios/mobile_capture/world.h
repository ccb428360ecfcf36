#pragma once
// Mobile capture: the simulated world of one run (object, floor, robot, head camera) and the
// geometry the loop, the oracle and the metrics share.

#include <Eigen/Core>
#include <Eigen/Geometry>
#include <cstdint>
#include <functional>
#include <memory>
#include <optional>
#include <vector>

#include "viewline/core/camera.h"
#include "viewline/core/random.h"
#include "viewline/runtime/faults.h"
#include "viewline/runtime/frame_source.h"
#include "viewline/scenarios/mobile_capture/config.h"
#include "viewline/sim/physics.h"
#include "viewline/tracking/unicycle_tracker.h"
#include "viewline/vision/ball_detector.h"

namespace viewline::scenarios::mobile_capture {

/// Independent random streams of one run, all derived from the run seed.
struct Streams {
  core::Rng object,  ///< the object's input noise (ξv, ξω)
            room,    ///< the floor texture
            render,  ///< image sensor noise (and the filter test's measurement noise)
            drive;   ///< the base's encoder noise
  /// Stream k (1..4 in the order above) is seeded with deriveSeed(seed, k).
  explicit Streams(std::uint64_t seed);
};

/// The camera that renders (truth: the rig's truth.yaml, or the inline pinhole) and the one the
/// estimators use (the rig's calibration; the same perfect pinhole without a rig).
core::Camera renderCamera(const MobileCaptureConfig& cfg);
/// The estimators' camera (rig calibration, or the same perfect pinhole as renderCamera()).
core::Camera estimatorCamera(const MobileCaptureConfig& cfg);
/// c_M_w of the true head camera at joints q on the base pose (x, y, θ): the DH head.
Eigen::Isometry3d trueCamera_c_M_w(const robots::MobilePanTilt& head, const robots::PanTiltJoints& q, double x,
                                   double y, double theta);
/// The estimators' camera pose from the same joints and pose: c'_M_w = c'_M_c · c_M_w (rig), else c_M_w.
Eigen::Isometry3d estimatorCamera_c_M_w(const MobileCaptureConfig& cfg, const Eigen::Isometry3d& true_c_M_w);

/// What the loop reads of the robot when it takes a frame: the base pose from odometry and the
/// head's joint encoders. The estimators' camera at that frame is a function of it alone
/// (estimatorCamera_c_M_w below), so a recording that holds it (head.csv, recording.h) places the
/// frame's detection on the floor without the robot, exactly as the loop did.
struct HeadReading {
  robots::BasePose base;    ///< x, y (m, world floor), θ (rad, from the world x axis)
  robots::PanTiltJoints q;  ///< tilt, pan (rad)
};
/// The estimators' camera pose at reading `r` of the head `head`:
/// c'_M_w = estimatorCamera_c_M_w(cfg, trueCamera_c_M_w(head, r.q, r.base.x, r.base.y, r.base.θ)).
/// The one place a frame's camera pose is built (the loop, the footage session, a recording's replay).
Eigen::Isometry3d estimatorCamera_c_M_w(const MobileCaptureConfig& cfg, const robots::MobilePanTilt& head,
                                        const HeadReading& r);

/// The object's motion ([K]'s profile) over `duration` s.
sim::GroundTargetParams targetParams(const MobileCaptureConfig& cfg, sim::GroundProfile profile, double duration);
/// How long the capture runs' object path must last (the run plus the planner's horizon).
double targetDuration(const MobileCaptureConfig& cfg);

/// The floor measurement of one detected blob and its two noise parts (see floorMeasurement()).
struct FloorMeasurement {
  Eigen::Vector2d z = Eigen::Vector2d::Zero();  ///< m, the pixel back-projected onto the plane (world floor)
  /// m²/px², J Jᵀ with J = ∂z/∂(u, v) (the ground-projection Jacobian): the white noise is σ_px² J Jᵀ.
  Eigen::Matrix2d unit_pixel_cov = Eigen::Matrix2d::Zero();
  /// m², covariance of the slowly varying bias of z: the camera-to-ground calibration (rotation
  /// and height errors through ∂z/∂(pose)) and the blob centroid's offset from the box centre.
  Eigen::Matrix2d bias_cov = Eigen::Matrix2d::Zero();
};

/// The floor point of pixel `uv` seen by `camera` on the plane z = plane_z with its noise model:
/// white pixel noise mapped by the range-dependent Jacobian J = ∂z/∂(u, v), and a bias
/// B = Σ_k σ_k² J_k J_kᵀ over the calibrated pose's errors (a rotation of the camera about each world
/// axis through its centre, σ = calibration_angle_sigma; its height, σ = calibration_height_sigma)
/// plus floor_sigma² I (centroid offset). Both Jacobians by central differences of the exact
/// back-projection. Empty when the ray (or a perturbed one) misses the plane.
std::optional<FloorMeasurement> floorMeasurement(const MobileCaptureConfig& cfg, const core::Camera& camera,
                                                 const Eigen::Vector2d& uv, double plane_z);

/// The object's pixel in one frame, detected and screened as every loop of the scenario does (the
/// simulated chase and the footage session): the detector in its window around `predicted_px`
/// (runtime::guardedDetect: a detector exception is counted, not thrown), the fault plan's detector
/// faults, and runtime::usablePixel (a non-finite or outside pixel is counted and dropped).
/// `t`: the frame's stamp, s. Empty when no detection survives.
std::optional<Eigen::Vector2d> detectScreened(vision::BallDetector& detector, runtime::FaultPlan& faults,
                                              const runtime::Frame& frame, double t,
                                              const std::optional<Eigen::Vector2d>& predicted_px);

/// A floor point in the robot frame (x forward, y left).
Eigen::Vector2d toRobot(const robots::BasePose& pose, const Eigen::Vector2d& p_w);

/// Control ticks i = 0..last at t = i · control_period (the product, not a running sum: every
/// time stamp of the scenario is computed this one way).
struct TickClock {
  double period = 0.01;  ///< s, the control period
  long last = 0;         ///< index of the last tick (max_time / period, rounded)
  /// Time of tick i, s.
  double time(long i) const { return static_cast<double>(i) * period; }
  /// The clock of a run: period = cfg.controlPeriod(), up to max_time.
  static TickClock of(const MobileCaptureConfig& cfg);
  /// Control ticks per vision frame (vision_period / control_period, an integer).
  static long visionEvery(const MobileCaptureConfig& cfg);
};

/// One simulated robot: base (wheels, PID, odometry) and rate-limited head joints.
struct RobotSim {
  const MobileCaptureConfig& cfg;  ///< the run's config (must outlive the robot)
  robots::MobilePanTilt head;      ///< head kinematics (DH) on the base
  robots::DifferentialDrive base;  ///< base dynamics, wheel PID and odometry
  robots::PanTiltJoints q;         ///< current head joints (tilt, pan), rad
  /// The base at the config's start pose, at rest; the head pointed 2 m ahead of it.
  explicit RobotSim(const MobileCaptureConfig& c);
  /// What the loop reads now: the base pose (odometry) and the joints (encoders).
  HeadReading reading() const { return {base.pose(), q}; }
  /// One control period of the head servo towards `target` (clamped to the joint limits).
  void stepHead(const robots::PanTiltJoints& target);
};

/// The head camera as a frame source: the simulator's renderer drawing the floor and the object
/// from where the head camera is when the frame is grabbed (`camera_pose`), with sensor noise and
/// the configured blackout. Frames every vision_every control ticks (capture_time = stamp = that
/// tick's time, zero exposure); the source ends after the last tick.
class RenderedHeadCamera final : public runtime::FrameSource {
public:
  /// c_M_w of the true camera at the time of a grab.
  using PoseProvider = std::function<Eigen::Isometry3d()>;
  /// Renders `target` on the textured floor (rng.room: texture, rng.render: noise); cfg, target
  /// and rng are kept by reference.
  RenderedHeadCamera(const MobileCaptureConfig& cfg, const sim::GroundTarget& target, Streams& rng,
                     PoseProvider camera_pose);
  ~RenderedHeadCamera() override;
  std::size_t cameraCount() const override { return 1; }
  std::optional<core::Timestamp> nextReadyTime() const override;
  std::optional<runtime::Frame> grab() override;

private:
  struct Impl;
  std::unique_ptr<Impl> impl_;
};

/// [K] eqs 27-29: the track's path over the planner's horizon, with the LS accelerations of its
/// predictor once its window is full, clamped to plausible bounds (early slopes from a few noisy
/// estimates are wild).
std::vector<Eigen::Vector2d> predictPath(const tracking::UnicycleTracker& track, const MobileCaptureConfig& cfg);
/// The object's true path at t + m T, m = 1..M (the oracle's knowledge).
std::vector<Eigen::Vector2d> truePath(const sim::GroundTarget& target, double t, double T, int M);

}  // namespace viewline::scenarios::mobile_capture
