#include "viewline/scenarios/mobile_capture/chase.h"

#include <cmath>

namespace viewline::scenarios::mobile_capture {

using Eigen::Vector2d;
using Eigen::Vector3d;

bool FrameScreen::admit(runtime::FaultPlan& faults, const runtime::Frame& frame) {
  if (faults.missesDeadline(frame)) {  // stale: dropped as a lost frame (faults.h)
    faults.note("frames_late_dropped");
    return false;
  }
  if (stale_.repeats(frame)) {  // a frozen camera's old image, new stamp (stale_frames.h)
    faults.note("frames_frozen_dropped");
    return false;
  }
  if (!(frame.stamp > last_stamp_)) {  // a repeated or backward stamp: the track only steps forward
    faults.note("frames_stale_stamp_dropped");
    return false;
  }
  last_stamp_ = frame.stamp;
  return true;
}

ChaseController::ChaseController(const MobileCaptureConfig& cfg)
    : cfg_(cfg), detector_(cfg.detector), track_(cfg.filter), search_(cfg.search), go_(cfg.goParams()),
      plane_z_(0.5 * cfg.object_height) {}

ChaseObservation ChaseController::frame(runtime::FaultPlan& faults, const runtime::Frame& frame,
                                        const core::Camera& camera, const robots::BasePose& pose) {
  const double t = frame.stamp;
  ChaseObservation o;
  // The detector searches around where the track puts the object now.
  std::optional<Vector2d> predicted_px;
  if (track_.valid()) {
    const Vector2d p = track_.positionAt(t);
    predicted_px = camera.project(Vector3d(p.x(), p.y(), plane_z_));
  }
  o.pixel = detectScreened(detector_, faults, frame, t, predicted_px);
  if (o.pixel) {
    // The floor point and its noise: white pixel noise through the range-dependent
    // ground-projection Jacobian goes into R; the calibration and centroid bias does not (the
    // innovations cannot see a bias that barely changes between frames, so in R it would only
    // shrink the NIS): the track estimates the apparent position s = p + b, and the object's
    // covariance is P_s + B (floorMeasurement(), world.h).
    o.floor = floorMeasurement(cfg_, camera, *o.pixel, plane_z_);
    if (o.floor) {
      last_seen_ = t;
      o.R = cfg_.pixel_sigma * cfg_.pixel_sigma * o.floor->unit_pixel_cov;
      o.update = track_.update(t, o.floor->z, o.R);
    }
  }
  track_.predictTo(t);
  if (track_.valid()) {
    prediction_ = predictPath(track_, cfg_);
    plan_ = planning::planCapture(prediction_, {{pose.x, pose.y}, pose.theta}, cfg_.plannerParams());
    const Vector2d rel = toRobot(pose, track_.state().x().head<2>());
    centre_bearing_ = std::atan2(rel.y(), rel.x());
    have_bearing_ = true;
  }
  return o;
}

ChaseCommand ChaseController::command(double t, const robots::BasePose& pose, const robots::MobilePanTilt& head,
                                      const robots::PanTiltJoints& q, double turn_rate) {
  const control::SearchMode new_mode = track_.valid() ? search_.mode(t, last_seen_) : control::SearchMode::Sweeping;
  if (new_mode == control::SearchMode::Sweeping && mode_ != control::SearchMode::Sweeping) sweep_start_ = t;
  if (sweep_start_ < 0.0) sweep_start_ = t;
  mode_ = new_mode;
  ChaseCommand c;
  c.mode = mode_;
  c.head = q;
  if (mode_ != control::SearchMode::Sweeping) {
    c.base = control::goToPoint(pose, plan_.point, go_);
    const Vector2d p = track_.positionAt(t + cfg_.controlPeriod());
    c.head = control::headSetPoint(head, pose, Vector3d(p.x(), p.y(), plane_z_));
  } else {
    c.head = search_.sweep(head, t, sweep_start_, have_bearing_ ? centre_bearing_ : 0.0);
    c.base = search_.baseWhileSearching(centre_bearing_, have_bearing_);
    if (have_bearing_) {
      // The base turns towards the bearing; it is expressed in the robot frame at the last
      // estimate, so update it with the base's own rotation.
      centre_bearing_ = std::remainder(centre_bearing_ - turn_rate * cfg_.controlPeriod(), 2.0 * M_PI);
    }
  }
  return c;
}

}  // namespace viewline::scenarios::mobile_capture
