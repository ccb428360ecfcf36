#pragma once
// Mobile capture: the chase's perception and command logic, one piece for the simulated loop
// (loop.cpp), the footage session (footage.cpp) and a recording's replay for tuning
// (mobileCaptureRecordedMeasurements, recording.h), so that they cannot drift apart.
//
// Per frame (frame()): the tracker's predicted pixel (the detector's search window), the screened
// detection (detectScreened), its floor point and noise (floorMeasurement: the white pixel noise
// through the ground-projection Jacobian goes into R, the bias does not), the track's update and
// time update, then, with a track, the predicted path (predictPath, [K] eqs 27-29), the capture
// plan from the robot's pose and the bearing of the track in the robot frame (the search's centre).
// Per control period (command()): the search mode from the time since the last detection, then
// either goToPoint towards the capture point and the head towards the prediction one period
// ahead, or the search's sweep and base turn; the bearing follows the base's own rotation.
//
// What the callers add around it is theirs: the loop's truth metrics (localisation, NIS, NEES),
// telemetry and view; the footage session's per-frame samples and its limit checks on commands
// it never executes (a held robot: turn rate 0).

#include <Eigen/Core>
#include <limits>
#include <optional>
#include <vector>

#include "viewline/control/mobile_capture_control.h"
#include "viewline/core/camera.h"
#include "viewline/planning/capture_planner.h"
#include "viewline/robots/differential_drive.h"
#include "viewline/robots/mobile_pan_tilt.h"
#include "viewline/runtime/faults.h"
#include "viewline/runtime/frame_source.h"
#include "viewline/runtime/stale_frames.h"
#include "viewline/scenarios/mobile_capture/config.h"
#include "viewline/scenarios/mobile_capture/world.h"
#include "viewline/tracking/unicycle_tracker.h"
#include "viewline/vision/ball_detector.h"

namespace viewline::scenarios::mobile_capture {

/// What one frame gave the chase: the screened detection, its floor point and the track's update.
struct ChaseObservation {
  std::optional<Eigen::Vector2d> pixel;  ///< px, the screened detection (empty: none survived)
  /// The detection's floor point on the plane z = object_height / 2 and its noise model (empty:
  /// no detection, or its ray misses the plane).
  std::optional<FloorMeasurement> floor;
  /// m², the white-noise covariance the track was given (pixel_sigma² J Jᵀ); zero without a floor point.
  Eigen::Matrix2d R = Eigen::Matrix2d::Zero();
  /// The track's update with the floor point (empty without one).
  std::optional<tracking::UnicycleUpdate> update;
};

/// The screens a grabbed frame passes before it reaches the chase, in every loop of the scenario
/// (the simulated chase, the footage session, a recording's replay for tuning): a frame that a late
/// fault delays past its deadline (faults.h), a frozen camera's repeated image (stale_frames.h) and
/// a stamp that does not move forward (the track only steps forward) are dropped and counted.
class FrameScreen {
public:
  /// True when `frame` goes on to the chase; else counts why in `faults` (frames_late_dropped,
  /// frames_frozen_dropped, frames_stale_stamp_dropped).
  bool admit(runtime::FaultPlan& faults, const runtime::Frame& frame);

private:
  runtime::StaleFrameFilter stale_;
  double last_stamp_ = -std::numeric_limits<double>::infinity();  // s, of the last frame admitted
};

/// One control period's commands.
struct ChaseCommand {
  control::SearchMode mode = control::SearchMode::Sweeping;  ///< the search mode of this period
  control::BaseCommand base;                                  ///< the base's (v m/s, ω rad/s)
  robots::PanTiltJoints head;                                 ///< the head's set point (tilt, pan), rad
};

/// The chase's tracker, detector, planner state and search (header comment).
class ChaseController {
public:
  /// The chase of `cfg` (kept by reference: it must outlive the controller); no track yet, sweeping.
  explicit ChaseController(const MobileCaptureConfig& cfg);

  /// One frame (stamp t = frame.stamp, s): detection around the predicted pixel through `faults`'
  /// detector faults and screens, floor point, track update and time update to t; with a track,
  /// the predicted path, the capture plan from `pose` (world) and the bearing of the track.
  /// `camera`: the estimators' camera at the frame's time (pose c_M_w set).
  ChaseObservation frame(runtime::FaultPlan& faults, const runtime::Frame& frame, const core::Camera& camera,
                         const robots::BasePose& pose);

  /// The commands of the control period at t (s) from the robot's `pose` (world), head kinematics
  /// `head` and joints `q` (rad); `turn_rate` (rad/s, the base's own) turns the search bearing
  /// with the base over the period (0 for a held robot).
  ChaseCommand command(double t, const robots::BasePose& pose, const robots::MobilePanTilt& head,
                       const robots::PanTiltJoints& q, double turn_rate);

  /// The object's track (unicycle EKF on the floor).
  const tracking::UnicycleTracker& track() const { return track_; }
  /// The last capture plan (made on the last frame with a track).
  const planning::CapturePlan& plan() const { return plan_; }
  /// The track's path over the planner's horizon at the last frame with a track, m (world floor).
  const std::vector<Eigen::Vector2d>& prediction() const { return prediction_; }
  /// The search mode of the last control period (Sweeping before the first).
  control::SearchMode mode() const { return mode_; }
  /// Stamp of the last frame with a floor point, s (negative: never seen).
  double lastSeen() const { return last_seen_; }
  /// Height of the plane the object's centre moves on, m (object_height / 2).
  double planeZ() const { return plane_z_; }

private:
  const MobileCaptureConfig& cfg_;
  vision::BallDetector detector_;
  tracking::UnicycleTracker track_;
  control::SearchPattern search_;
  control::GoToPointParams go_;
  double plane_z_;
  planning::CapturePlan plan_;
  std::vector<Eigen::Vector2d> prediction_;
  control::SearchMode mode_ = control::SearchMode::Sweeping;
  double last_seen_ = -1.0, sweep_start_ = -1.0;
  double centre_bearing_ = 0.0;  // rad, robot frame: the track's bearing, the search's centre
  bool have_bearing_ = false;
};

}  // namespace viewline::scenarios::mobile_capture
