#pragma once
// Ball catching: what one throw and a session measure.
//
// Caught = the ball centre crosses the (moving) box-front plane within hole_radius − ball_radius
// of the hole centre (5 mm for a 6 cm hole and a 5 cm ball); the true crossing is found on the
// true flight against the robot's actual hole position at that instant.
//
// Reachability (the oracle): a throw is reachable when a robot that knows the true flight from
// the first capture in which the ball is inside at least one camera's image (truth of the
// rendered frame), starting at home at rest with the same limits and command latency, could put
// the hole exactly on the true crossing point by the crossing time:
//     t_first_visible + latency + T_min(home -> crossing) <= t_cross
// (T_min from the planner's own profile generator under the robot's limits, Euclidean or per axis
// (planning::minimumDuration): from rest, the straight bang-coast-bang line; no processing latency).
//
// Miss reasons (each missed throw gets exactly one):
//   not_reachable  the oracle could not have caught it;
//   lost_track     reachable, but the planner never had a target (too few / no detections, or
//                  the crossing prediction never became certain enough to move);
//   late           the hole was more than the clearance away from the planner's final target
//                  at the crossing (still moving, or the planner gave up);
//   off_target     the hole was at the planner's final target but the prediction was off.

#include <Eigen/Core>
#include <cstdint>
#include <map>
#include <nlohmann/json.hpp>
#include <optional>
#include <string>
#include <vector>

#include "viewline/io/log.h"
#include "viewline/planning/catch_planner.h"
#include "viewline/robots/cartesian_robot.h"
#include "viewline/scenarios/ball_catching/config.h"
#include "viewline/runtime/faults.h"
#include "viewline/scenarios/ball_catching/registration.h"

namespace viewline::scenarios {

/// Fused images of a track before its accepted images count in the NIS statistics.
constexpr int kConsistencyBurnIn = 4;
/// A throw's NEES sample is taken after this many fused images.
constexpr int kNeesFusedImage = 8;

/// Everything one throw measured: the draw, the truth, what the tracker and planner did, the
/// outcome (world frame, s and m unless the name says otherwise).
struct ThrowResult {
  int index = 0;           ///< throw index (0-based)
  std::uint64_t seed = 0;  ///< the throw's own seed (deriveSeed(runBallCatching's seed, index))
  // Throw
  Eigen::Vector3d release = Eigen::Vector3d::Zero(),          ///< release point, m (world)
                  launch_velocity = Eigen::Vector3d::Zero();  ///< velocity at release, m/s (world)
  double launch_speed = 0.0,          ///< |launch_velocity|, m/s
         launch_elevation_deg = 0.0,  ///< launch angle above the horizontal, degrees
         distance = 0.0;              ///< release to the box plane along its normal, m
  // Truth
  double t_cross = 0.0;                                 ///< true crossing time (release at 0)
  Eigen::Vector3d cross_true = Eigen::Vector3d::Zero(); ///< true crossing point
  double t_first_visible = -1.0;                        ///< first capture with the ball in an image
  bool reachable = false;                               ///< the oracle could have caught it
  double oracle_time = 0.0;                             ///< T_min home -> crossing, s
  // Run
  int frames = 0,      ///< images captured over all cameras
      detections = 0,  ///< images in which the detector found the ball
      fused = 0,       ///< detections the tracker fused
      gated = 0;       ///< detections the tracker's gate rejected
  /// Sum over the detections of the squared per-axis pixel error (before the extra detection
  /// noise) against the estimator camera's projection of the true ball at the stamp, px².
  double detection_sq_error_px2 = 0.0;
  /// Sum over the detections of the per-axis std the tracker was told, squared, px².
  double told_variance_px2 = 0.0;
  int detection_errors = 0;  ///< detections in detection_sq_error_px2 (each contributes 2 axes)
  /// The tracker's NIS (dᵀ S⁻¹ d, 2 dof) of every accepted image once its track has
  /// kConsistencyBurnIn fused images (the tuning adapter's count).
  std::vector<double> nis;
  /// The tracker's NEES (position and velocity, 6 dof) against the true flight after the
  /// kNeesFusedImage-th fused image (-1: the throw had fewer, or the object is not a ball).
  double nees = -1.0;
  double t_first_detection = -1.0;                      ///< s, first detection's stamp (-1: none)
  double t_first_move = -1.0;                           ///< planner's first move towards a target
  bool had_target = false,  ///< the planner had a crossing target at some point
       committed = false,   ///< the planner committed to a target
       gave_up = false;     ///< the planner decided the throw was not catchable
  double give_up_lead = -1.0;                           ///< true crossing − give-up decision, s
  double decision_time = -1.0;                          ///< commit − first update, s
  Eigen::Vector3d target = Eigen::Vector3d::Zero();     ///< planner's final target
  double prediction_error = -1.0;                       ///< |target − true crossing|, m
  double prediction_error_lead = -1.0;                  ///< same, last prediction >= prediction_lead_s before it
  Eigen::Vector3d hole_at_cross = Eigen::Vector3d::Zero();  ///< actual hole centre at t_cross, m
  double miss_distance = 0.0;                           ///< in-plane |ball − hole| at the crossing, m
  bool caught = false;                                  ///< crossed within the clearance of the hole
  std::string miss_reason;                              ///< "" when caught
  std::size_t limit_violations = 0,  ///< set points over the velocity or acceleration limits
              refused_setpoints = 0;  ///< set points refused (no IK solution, or outside the workspace)
  double max_speed = 0.0,  ///< largest set-point speed, m/s (measured as robot.limit_norm says)
         max_acceleration = 0.0;  ///< largest set-point acceleration |Δv| / Δt, m/s² (same measure)
  double wall_s = 0.0;  ///< wall-clock time the throw took to simulate, s
  runtime::FaultReport faults;  ///< injected faults and what the loop did (empty without faults)
};

/// The figures of runBallCatching() (the summary JSON): catch rates, prediction errors, decisions, limits.
struct CatchSummary {
  std::uint64_t seed = 0;  ///< the seed runBallCatching() was given
  int throws = 0,            ///< throws run
      reachable_throws = 0,  ///< throws the oracle could catch
      caught = 0,            ///< throws caught
      caught_reachable = 0;  ///< reachable throws caught
  double catch_rate_all = 0.0,        ///< caught / throws
         catch_rate_reachable = 0.0;  ///< caught_reachable / reachable_throws
  std::map<std::string, int> miss_reasons;  ///< count per miss reason (see the file comment)
  double prediction_error_mm_median = 0.0,  ///< median |final target − true crossing|, mm
         prediction_error_mm_p95 = 0.0;     ///< 95th percentile of the same, mm
  double prediction_error_lead_mm_median = 0.0,  ///< median error of the prediction_lead_s-early prediction, mm
         prediction_error_lead_mm_p95 = 0.0;     ///< 95th percentile of the same, mm
  int predictions_at_lead = 0;  ///< throws that had a prediction prediction_lead_s early
  double decision_time_s_median = 0.0,  ///< median time from the first update to the commit, s
         decision_time_s_p95 = 0.0;     ///< 95th percentile of the same, s
  int decisions = 0;  ///< throws with a commit (the decision-time sample size)
  int gave_up_unreachable = 0;   ///< not-reachable throws the planner gave up on (early decision)
  int gave_up_reachable = 0;     ///< reachable throws it gave up on (wrong decisions)
  double give_up_lead_s_median = 0.0;  ///< how long before the crossing it gave up (unreachable ones)
  double miss_distance_mm_median_reachable = 0.0;  ///< median in-plane miss of reachable throws, mm
  std::size_t limit_violations = 0,   ///< sum over the throws
              refused_setpoints = 0;  ///< sum over the throws
  double max_speed = 0.0,         ///< largest set-point speed over the throws, m/s
         max_acceleration = 0.0;  ///< largest set-point acceleration over the throws, m/s²
  int frames = 0,      ///< images over all throws and cameras
      detections = 0;  ///< of which the ball was detected in
  double detection_rate = 0.0;  ///< detections / frames
  /// RMS per pixel axis of the detections against the estimator cameras' projection of the true
  /// ball (before the extra detection noise): the detector's own error as the tracker sees it, px.
  double detection_error_px_rms = 0.0;
  /// RMS per pixel axis of the std the tracker was told, without the extra noise's share, px.
  double told_sigma_px_rms = 0.0;
  double nis_mean = 0.0;  ///< mean of every throw's NIS samples (2 dof)
  int nis_samples = 0;    ///< how many
  double nis_band_lo = 0.0;  ///< lower end of the two-sided 99 % chi-square band of nis_mean
  double nis_band_hi = 0.0;  ///< upper end of that band
  double nees_mean = 0.0;  ///< mean of the throws' NEES samples (6 dof)
  int nees_samples = 0;    ///< how many (one per throw)
  double nees_band_lo = 0.0;  ///< lower end of the two-sided 99 % chi-square band of nees_mean
  double nees_band_hi = 0.0;  ///< upper end of that band
  std::optional<RegistrationResult> registration;  ///< the camera registration, when enabled
  double launch_speed_min = 0.0,   ///< m/s, over the throws
         launch_speed_max = 0.0,   ///< m/s
         launch_speed_mean = 0.0;  ///< m/s
  double elevation_deg_min = 0.0,  ///< launch elevation over the throws, degrees
         elevation_deg_max = 0.0;  ///< degrees
  double flight_time_min = 0.0,  ///< release to crossing over the throws, s
         flight_time_max = 0.0;  ///< s
  double wall_s = 0.0,        ///< wall-clock time of all throws, s (set by the caller)
         ms_per_frame = 0.0;  ///< wall-clock per image, ms
  std::vector<ThrowResult> results;  ///< every throw, in throw order
  runtime::FaultReport faults;  ///< injected faults and outcomes summed over the throws
};

/// The end of a throw: caught or not (and why), the oracle, the planner's decisions, the robot's
/// limit counters. `lead_prediction`: the last predicted crossing available prediction_lead_s or
/// more before the true crossing.
void scoreThrow(ThrowResult& res, const BallCatchingConfig& cfg, const robots::SimulatedCartesianRobot& robot,
                const planning::CatchPlanner& planner, const std::optional<Eigen::Vector3d>& lead_prediction);

/// The session's figures over `results` (in throw order); wall_s is left to the caller.
CatchSummary summarise(std::vector<ThrowResult> results, std::uint64_t seed,
                       std::optional<RegistrationResult> registration);

/// The summary as JSON (rates, medians, miss reasons, registration) with the config's key values.
nlohmann::json summaryJson(const CatchSummary& s, const BallCatchingConfig& cfg);

/// The console summary: a figure over no throw says "not scored" instead of printing nan.
std::string summaryText(const CatchSummary& s, const BallCatchingConfig& cfg);

/// One row per throw (throws.csv in a --log folder).
void writeThrowsCsv(io::LogDirectory& log, const std::vector<ThrowResult>& results);

}  // namespace viewline::scenarios
