#pragma once
// The waypoint region of the planar target filter (TargetFilterConfig::region_*, constant-speed legs).
//
// Waypoint region (region_size > 0; constant-speed legs): the legs join waypoints drawn uniformly in a
// known box B (area A) — a target confined to a known workspace, e.g. [T]'s projection screen. From a
// corner c, the next waypoint w is uniform in B, so in polar coordinates about c its density is r / A
// for r < R(θ), R(θ) the distance from c to B's boundary along u(θ). Hence:
//  - a new leg's direction has the prior p(θ) = R(θ)² / (2A) (more room, more likely; ∫ p dθ = 1),
//    multiplied with the learnt-turn prior when both are on (then normalised on a grid);
//  - the soft mixture's prior odds of "the turn was at t_j" against "no turn yet" come from where the
//    target is along its leg: with s the distance travelled from the leg's start c along u and R = R(θ_u),
//    P(turn in (s_{j−1}, s_j]) : P(no turn by s_n) = (s_j² − s_{j−1}²) : (R² − s_n²),
//    instead of jump_rate × (t_j − t_{j−1}) : 1. A leg cannot leave B, so the odds of a turn grow without
//    bound as the target nears the boundary, and are small just after a corner.
//  The model says the target never leaves B. Once 5 accepted measurements in a row lie outside B by
//  more than 2 of their standard deviations (on either axis), the region is taken to be wrong and is
//  dropped for good (regionDropped()): the filter goes on as without one (θ uniform, jump_rate odds). A
//  too small or shifted box would otherwise make every step near its edge look like a turn. (The
//  measurements, not the estimate: a turn at the edge is detected late, and the estimate overshoots.)

#include <Eigen/Core>
#include <vector>

#include "viewline/core/time.h"
#include "viewline/tracking/planar_target/history.h"

namespace viewline::tracking {

/// Distance from c (inside the box [lo, hi]) to the box's boundary along u(θ) = (cos θ, sin θ).
double boxReach(const Eigen::Vector2d& c, const Eigen::Vector2d& lo, const Eigen::Vector2d& hi, double theta);
/// The same with u(θ) = (cos θ, sin θ) given (computed once by a caller that needs it too).
double boxReach(const Eigen::Vector2d& c, const Eigen::Vector2d& lo, const Eigen::Vector2d& hi, const Eigen::Vector2d& u);

/// The density p(θ) = R(θ)² / (2A) of the direction θ from c to a point drawn uniformly in the box
/// (centre, size = (width, height), area A), R(θ) the distance from c to the box's boundary along
/// (cos θ, sin θ); c is clamped into the box. ∫ p dθ over [−π, π) = 1. (The waypoint-region prior.)
double waypointDirectionDensity(const Eigen::Vector2d& c, const Eigen::Vector2d& center, const Eigen::Vector2d& size,
                                double theta);

/// The box B and whether the measurements still agree with it.
class WaypointRegion {
public:
  /// size (width, height) 0: no region.
  WaypointRegion(const Eigen::Vector2d& center, const Eigen::Vector2d& size) : center_(center), size_(size) {}

  /// True when a region was configured (size > 0).
  bool configured() const { return size_.x() > 0.0 && size_.y() > 0.0; }
  /// Configured and not dropped: the legs use it.
  bool active() const { return configured() && !dropped_; }
  /// True once the measurements left the region (5 in a row): it is no longer used.
  bool dropped() const { return dropped_; }
  /// Centre of the box B (plane coordinates), m.
  const Eigen::Vector2d& center() const { return center_; }
  /// Width and height of B, m.
  const Eigen::Vector2d& size() const { return size_; }
  /// Lower corner of B, m.
  Eigen::Vector2d lo() const { return center_ - 0.5 * size_; }
  /// Upper corner of B, m.
  Eigen::Vector2d hi() const { return center_ + 0.5 * size_; }
  /// c clamped into B less an inset of 1e-3 of its size (an estimate can fall just outside B).
  Eigen::Vector2d clampInside(const Eigen::Vector2d& c) const;
  /// Distance from c (clamped as clampInside) to B's boundary along u(θ).
  double reach(const Eigen::Vector2d& c, double theta) const;

  /// An accepted measurement p with covariance R: drops the region after 5 in a row outside it.
  void check(const Eigen::Vector2d& p, const Eigen::Matrix2d& R);

  /// log prior odds of a turn at each history time j (index into `history`, entry 0 unused) against none,
  /// for the current leg that started at t_c and runs from there with the estimate's position p and
  /// velocity v at the history's last time; empty when the velocity is ~0.
  std::vector<double> jumpOdds(const Eigen::Vector2d& p, const Eigen::Vector2d& v, core::Timestamp t_c,
                               const PlanarHistory& history) const;

  /// An extrapolation from p0 (inside B) that ends at p outside stops on B's boundary with v = a = 0.
  void stopAtBoundary(const Eigen::Vector2d& p0, Eigen::Vector2d& p, Eigen::Vector2d& v, Eigen::Vector2d& a) const;

private:
  Eigen::Vector2d center_, size_;
  bool dropped_ = false;
  int outside_run_ = 0;
};

}  // namespace viewline::tracking
