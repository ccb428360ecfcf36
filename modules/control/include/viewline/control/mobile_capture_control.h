#pragma once
// Controllers of the mobile-capture robot (SPEC §4, [K]): the base drives to the capture point,
// the pan/tilt head keeps the camera on the target (inverse kinematics), and a search pattern
// finds the target again after it left the view.
//
// Base (GoToPoint): heading error e = wrap(atan2(g - p) - θ),
//     ω = clamp(k_heading e, ±ω_max),
//     v = v_max · max(0, cos e)^2 · clamp((d - stop_distance) / slow_distance, 0, 1)
// (turn on the spot when the goal is behind; drive through the goal until the object is
// `stop_distance` from the axle, i.e. well inside the gripper).
//
// Head (HeadPointing): the set point is the inverse kinematics (robots::MobilePanTilt::pointAtBest)
// towards the target's predicted position at the next control instant; the head's own drive
// (rate-limited) follows it. Nothing else is needed to keep a slow ground object centred: the
// prediction feeds the motion forward.
//
// Search (SearchPattern): when the target has not been seen for `lost_after` seconds, the head
// looks at the last predicted position; after `search_after` seconds it sweeps the pan
// sinusoidally (amplitude `sweep_amplitude`, period `sweep_period`) around the bearing of that
// position at the tilt that looks at the floor `search_range` away, and the base turns on the spot
// towards that bearing (the head cannot look sideways-down, see mobile_pan_tilt.h), slowly
// rotating the whole view when the sweep found nothing for a full period.

#include <Eigen/Core>

#include "viewline/robots/differential_drive.h"
#include "viewline/robots/mobile_pan_tilt.h"

namespace viewline::control {

/// Gains and limits of the base's drive-to-point law (unicycle base, floor frame).
struct GoToPointParams {
  double max_speed = 0.3;        ///< m/s
  double max_turn_rate = 2.0;    ///< rad/s
  double k_heading = 3.0;        ///< 1/s
  double stop_distance = 0.12;   ///< m from the axle centre
  double slow_distance = 0.15;   ///< m over which v ramps down to 0 at stop_distance
  /// Throws core::InvalidInput naming the field.
  void validate() const;
};

/// Velocity command of the unicycle base.
struct BaseCommand {
  double v = 0.0,      ///< forward speed, m/s
         omega = 0.0;  ///< turn rate, rad/s (counter-clockwise seen from above)
};

/// Base command that drives towards `goal` (floor frame, m): turn first when it is behind, slow down near
/// stop_distance.
BaseCommand goToPoint(const robots::BasePose& pose, const Eigen::Vector2d& goal, const GoToPointParams& params);

/// Joint set points that point the head camera at a world point (z up) from a base pose;
/// `angle_error` (optional) receives the residual pointing error of pointAtBest.
robots::PanTiltJoints headSetPoint(const robots::MobilePanTilt& head, const robots::BasePose& pose,
                                   const Eigen::Vector3d& target_w, double* angle_error = nullptr);

/// Timing and geometry of the search for a lost target (head sweep, base turn).
struct SearchParams {
  double lost_after = 0.3;       ///< s without a detection before the target counts as lost
  double search_after = 1.5;     ///< s lost before the sweep starts
  double sweep_amplitude = 0.6;  ///< rad of pan around the centre bearing
  double sweep_period = 3.0;     ///< s
  double search_range = 1.5;     ///< m, floor distance the search tilt looks at
  double base_turn_rate = 0.6;   ///< rad/s of the base while searching without a bearing
  /// Throws core::InvalidInput naming the field.
  void validate() const;
};

/// Search state: target seen recently, lost (look at the last prediction), or sweeping.
enum class SearchMode { Tracking, Lost, Sweeping };

/// State machine of the search; feed it the time of the last detection every control period.
class SearchPattern {
public:
  /// Search with these parameters (validated; throws core::InvalidInput).
  explicit SearchPattern(const SearchParams& params = {});
  /// Mode at time t given the last detection time (negative: never seen).
  SearchMode mode(double t, double last_seen) const;
  /// Head set point while sweeping: pan about the bearing (robot frame) of the last estimate.
  robots::PanTiltJoints sweep(const robots::MobilePanTilt& head, double t, double sweep_start,
                              double centre_bearing) const;
  /// Base command while sweeping: turn towards the centre bearing (robot frame, rad); with no
  /// bearing (never seen), turn at base_turn_rate.
  BaseCommand baseWhileSearching(double centre_bearing, bool have_bearing) const;
  /// The parameters in use.
  const SearchParams& params() const { return params_; }

private:
  SearchParams params_;
};

}  // namespace viewline::control
