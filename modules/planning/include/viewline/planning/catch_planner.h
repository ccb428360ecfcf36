#pragma once
// Interception planner of the ball catcher ([L] §VI.C): moves the hole of a box to the
// point where a tracked ball will cross the box-front plane, in time, under the robot's limits.
//
// Geometry: the hole centre h(t) is the robot's tool point; the box front is the plane through
// h(t) with the fixed unit normal n (towards the thrower). The planner only moves the hole within
// the plane through `home` (its n-coordinate stays at home's), so the plane the ball must cross
// is the plane through home with normal n, and the predicted crossing point IS the target.
//
// At every tracker update (update(now, estimate)):
//  1. predict the crossing (crossing.h) with the configured flight model (drag or ballistic) and
//     its covariance; ignore it when there is none ahead;
//  2. while the crossing point is too uncertain (largest std > start_sigma) do nothing; below it,
//     re-plan a time-optimal synchronised profile (motion_profile.h) to the predicted point (or,
//     with target_prior_std > 0, to its posterior mean under the prior of the throws),
//     starting from the CURRENT commanded position and velocity (no jump, no velocity step);
//  3. the first time the largest std falls below commit_sigma (after at least commit_min_updates
//     updates) the target is "committed" (decision time = commit − first update). At and after
//     the commitment, if the box cannot be there by the crossing time (arrival = now + profile
//     duration + command latency > crossing time + give_up_late), or the point is outside the
//     workspace, the throw is declared unreachable: the planner stops chasing it and goes home
//     (the early decision). Under Euclidean limits the duration in that test is a lower bound of
//     any norm-limited motion's (the per-axis profile with the same numbers, a relaxation): the
//     planner's own profile from a moving start is conservative, and a wrong give-up is a sure miss;
//     with give_up_sigmas > 0 the test takes the crossing that many std nearer and later;
//  4. `home_delay` after the predicted crossing the planner goes home (from the current state).
// The control loop calls setpoint(t) every control period and streams the result to the robot.

#include <Eigen/Core>
#include <functional>
#include <optional>

#include "viewline/estimation/state.h"
#include "viewline/planning/crossing.h"
#include "viewline/planning/motion_profile.h"
#include "viewline/robots/cartesian_robot.h"

namespace viewline::planning {

/// Time-optimal profile from (p0, v0) at t0 to (pf, 0) under the robot's limits: the Euclidean
/// family (SyncProfile::planEuclidean) or the per-axis one (SyncProfile::plan), as limits.norm says.
SyncProfile planProfile(const robots::CartesianLimits& limits, double t0, const Eigen::Vector3d& p0,
                        const Eigen::Vector3d& v0, const Eigen::Vector3d& pf);
/// Duration (s) of planProfile()'s profile from (p0, v0) to (pf, 0), without building it.
double minimumDuration(const robots::CartesianLimits& limits, const Eigen::Vector3d& p0, const Eigen::Vector3d& v0,
                       const Eigen::Vector3d& pf);

/// Configuration of the ball-catching interception planner ([L] §VI.C).
struct CatchPlannerConfig {
  CrossingModel model;  ///< flight model used to predict the crossing (ballistic or drag)
  Eigen::Vector3d home = Eigen::Vector3d(0.0, 0.0, 1.2);   ///< hole centre at rest, world, m
  Eigen::Vector3d normal = Eigen::Vector3d::UnitX();         ///< box-front normal (unit, towards the thrower)
  robots::CartesianLimits limits;                            ///< limits of the hole, Euclidean or per axis (robot's, see below)
  double latency = 0.0;           ///< robot command latency, s (the box follows set points this late; robot's)
  double start_sigma = 0.15;      ///< m, start moving below this crossing-point std
  double commit_sigma = 0.01;     ///< m, commit the target below this std
  int commit_min_updates = 3;     ///< updates (fused images) before a commitment
  double give_up_late = 0.02;     ///< s, a committed target reached later than crossing + this is unreachable
  bool give_up = true;            ///< false: keep chasing unreachable targets (for comparisons)
  /// Give up only when even the crossing give_up_sigmas std closer to the box (along the line to
  /// it, from the crossing covariance) and give_up_sigmas std later is out of reach (0: the
  /// predicted point and time themselves). A wrong give-up is a sure miss; a prediction 1-2 cm off
  /// at the commitment can make a marginal throw look a few ms out of reach.
  double give_up_sigmas = 0.0;
  double home_delay = 0.1;        ///< s after the predicted crossing before going home
  double min_lead = 0.0;          ///< s, ignore crossings sooner than now + latency + this
  /// Prior of where throws cross the plane: N(home, σ0² I) per in-plane axis (0 = no prior).
  /// The box then goes to the posterior mean  home + σ0² (σ0² I + C)⁻¹ (ĉ − home)  of the
  /// predicted crossing ĉ with covariance C: early, uncertain predictions (one camera) move the
  /// box only a little towards where they point, precise ones move it all the way.
  double target_prior_std = 0.0;
  /// Move only on what the prediction has determined: per in-plane axis e the goal's offset from
  /// home, μ = e·(ĉ − home), is shrunk by this many of its std σ = √(eᵀ C e) towards home
  /// (sign(μ) max(0, |μ| − k σ); 0 = off). Going the wrong way at 0.5 m/s on an early guess costs
  /// twice the time it lasted; waiting for a determined direction costs only the wait.
  double move_sigmas = 0.0;
  /// Throws core::InvalidInput naming the field.
  void validate() const;
};

/// Phase of the catch planner: waiting, chasing the prediction, committed, gave up (unreachable), going home.
enum class CatchPhase { Idle, Tracking, Committed, GaveUp, Homing };
/// Lower-case name of a phase ("idle", "tracking", "committed", "gave_up", "homing").
const char* toString(CatchPhase p);

/// What one tracker update did to the plan.
struct PlannerUpdate {
  std::optional<Crossing> crossing;  ///< predicted crossing of this update (if any)
  bool replanned = false;            ///< a new profile was started
  bool feasible = false;             ///< the box can be at the target by the crossing time
  double arrival = 0.0;              ///< predicted arrival of the box at the target (absolute, with latency)
};

/// Moves the box's hole to the predicted crossing of a tracked ball, in time and within the robot's limits.
class CatchPlanner {
public:
  /// `workspace(p)`: can the hole be at p (robot workspace / IK); empty = everywhere.
  explicit CatchPlanner(CatchPlannerConfig cfg, std::function<bool(const Eigen::Vector3d&)> workspace = {});
  /// The planner of `robot` (which must outlive it): the limits, the command latency and the
  /// workspace are asked from the robot, their owner (cfg's limits and latency are ignored).
  CatchPlanner(CatchPlannerConfig cfg, const robots::CartesianRobot& robot);

  /// New throw: the commanded state is (p, v) at time t, phase Idle.
  void reset(double t, const Eigen::Vector3d& p, const Eigen::Vector3d& v = Eigen::Vector3d::Zero());
  /// A tracker update available at `now` (the estimate may be at an earlier time).
  PlannerUpdate update(double now, const estimation::StateEstimate& est);
  /// The set point to stream at time t (non-decreasing); switches to homing after the crossing.
  robots::CartesianState setpoint(double t);

  /// Current phase.
  CatchPhase phase() const { return phase_; }
  /// True once the target was committed (crossing std below commit_sigma).
  bool committed() const { return commit_time_.has_value(); }
  /// Time of the first tracker update of this throw (s).
  std::optional<double> firstUpdateTime() const { return first_update_; }
  /// Time of the commitment (s), if any.
  std::optional<double> commitTime() const { return commit_time_; }
  /// Time the throw was declared unreachable (s), if any.
  std::optional<double> giveUpTime() const { return give_up_time_; }
  /// First update that moved the box towards a predicted crossing.
  std::optional<double> firstMoveTime() const { return first_move_; }
  /// The crossing the current plan aims at (last accepted prediction).
  const std::optional<Crossing>& target() const { return target_; }
  /// The profile the set points currently follow.
  const SyncProfile& profile() const { return profile_; }
  /// Tracker updates seen since reset().
  int updates() const { return updates_; }
  /// Number of profiles planned since reset().
  int replans() const { return replans_; }
  /// The configuration in use (limits and latency as asked from the robot when built from one).
  const CatchPlannerConfig& config() const { return cfg_; }
  /// The plane the ball must cross: through home, with the box-front normal.
  CrossingPlane plane() const { return {cfg_.home, cfg_.normal}; }

private:
  void planTo(double now, const Eigen::Vector3d& goal);
  CatchPlannerConfig cfg_;
  std::function<bool(const Eigen::Vector3d&)> workspace_;
  CatchPhase phase_ = CatchPhase::Idle;
  SyncProfile profile_;
  double last_t_ = 0.0;
  std::optional<Crossing> target_;
  std::optional<double> first_update_, commit_time_, give_up_time_, first_move_;
  int updates_ = 0, replans_ = 0;
};

}  // namespace viewline::planning
