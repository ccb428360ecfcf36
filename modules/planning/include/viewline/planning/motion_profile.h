#pragma once
// Time-optimal, synchronised point-to-point motion under per-axis velocity and acceleration
// limits, starting from any state (position AND velocity), ending at rest.
//
// One axis (double integrator, |v| <= v_max, |a| <= a_max) from (p0, v0) at time 0 to (pf, 0)
// at time T uses the three-phase family
//
//   phase 1  0 <= t < t1:        constant acceleration ±a_max from v0 to the cruise speed vc,
//                                t1 = |vc − v0| / a_max
//   phase 2  t1 <= t < t1 + tc:  constant velocity vc
//   phase 3  t1 + tc <= t <= T:  constant acceleration ∓a_max from vc to 0, t3 = |vc| / a_max
//
// with tc = T − t1 − t3 >= 0 and |vc| <= v_max. vc may have either sign, so overshoot-and-return
// (v0 towards the goal and too fast to stop) is in the family. The distance covered is
//
//   D(vc) = sign(vc − v0) (vc² − v0²) / (2 a) + vc tc + vc |vc| / (2 a)
//
// and dD/dvc = tc >= 0 (checked piecewise), so D is monotone on the feasible interval
// vc ∈ [lo, hi], lo = max(−v_max, (v0 − a T)/2), hi = min(v_max, (v0 + a T)/2) (where tc >= 0;
// empty when T < |v0| / a). Hence:
//   - an arrival time T is feasible iff D(lo) <= pf − p0 <= D(hi); the feasible times form
//     [T_min, ∞) and T_min (the bang-bang / trapezoidal time-optimal time) is found by bisection;
//   - for a given feasible T, vc solves D(vc) = pf − p0 by bisection (monotone).
// Synchronisation: T = max over axes of T_min,i; every axis then uses the vc that makes it arrive
// exactly at T, so all axes arrive together (the path is not a straight line when the initial
// velocity is not along the displacement, but every axis respects its limits and the arrival is
// time-optimal for per-axis limits).
// Replanning without jerks: a new profile starts from the current commanded position and
// velocity, so position and velocity are continuous across replans (the acceleration may step,
// as in any bang-bang profile).
//
// Euclidean-norm limits (|v| <= V, |a| <= A: an arm's tool-point limit; planEuclidean). The same
// one-axis family runs on two orthogonal axes of the motion's own frame: e1 along the
// displacement pf − p0 and e2 along the part of v0 across it (the third direction neither moves
// nor has a velocity). Axis k gets the scaled limits (V w_k, A w_k) with w1² + w2² <= 1, so by
// Cauchy-Schwarz |v| <= V |w| <= V and |a| <= A at every instant; w_k >= |v0·e_k| / V keeps the
// start velocity (no step). The arrival time T is the smallest for which the weights each axis
// needs to arrive at T (bisection, monotone in w) fit in the unit disc, found by bisection on T.
// From rest this is the straight bang-coast-bang line, the exact time-optimal motion under norm
// limits; from a moving start it is the best of this family (the velocity across the
// displacement is stopped while the motion along it proceeds), never faster than the true optimum.
// When |v0| = V exactly the weights are forced to w_k = |v0·e_k| / V, which is still feasible:
// axis 1 keeps at most its current speed and axis 2 only has to stop and come back.
// That family turns slowly: at full speed the weights pin axis 1 to V cos θ and axis 2 brakes at
// A sin θ, so a re-plan that turns the goal by θ loses ~(1 − cos θ) V/A and more per re-plan.
// planEuclidean therefore also tries a second family and keeps the faster: the velocity chord.
//   phase 1  0 <= t < t1:  constant acceleration A (V u − v0) / |V u − v0| (the straight chord in
//                          velocity space from v0 to the cruise velocity V u; the chord stays in the
//                          disc |v| <= V, which is convex), t1 = |V u − v0| / A;
//   phase 2:               cruise at V u;   phase 3: brake at −A u for V / A.
// The direction u must make the straight cruise line hit the goal: u = (pf − p1) / |pf − p1| with
// p1 = p0 + (v0 + V u) t1 / 2 (fixed-point iteration; it contracts while |pf − p1| is large against
// the ≤ 2 V² / A of phase 1). It applies when |pf − p1| >= V² / (2A) (the cruise is reached);
// from rest it is the same straight bang-coast-bang line.

#include <Eigen/Core>
#include <optional>

namespace viewline::planning {

/// Position, velocity and acceleration of one axis (m, m/s, m/s²).
struct AxisState {
  double p = 0.0,  ///< position, m
         v = 0.0,  ///< velocity, m/s
         a = 0.0;  ///< acceleration, m/s²
};

/// One axis of the family above. Valid for t in [0, ∞) (holds pf after T).
class AxisProfile {
public:
  AxisProfile() = default;
  /// The profile arriving exactly at T, or nothing when T is infeasible.
  static std::optional<AxisProfile> forTime(double p0, double v0, double pf, double v_max, double a_max, double T);
  /// Time-optimal arrival time (>= 0). v0 is clamped to ±v_max first. Throws InvalidInput on bad limits.
  static double minimumTime(double p0, double v0, double pf, double v_max, double a_max);

  /// Position, velocity and acceleration at time t (s from the start of the profile).
  AxisState at(double t) const;
  /// Arrival time T (s from the start).
  double duration() const { return T_; }
  /// Cruise velocity vc of phase 2 (m/s, signed).
  double cruiseVelocity() const { return vc_; }
  /// A profile of given phases: acceleration s1 for t1 (m/s², s), cruise at v0 + s1 t1 for tc,
  /// acceleration s3 for t3, then at rest where it ends up (the caller keeps it within limits).
  static AxisProfile fromPhases(double p0, double v0, double s1, double t1, double tc, double s3, double t3);

private:
  double p0_ = 0.0, v0_ = 0.0, pf_ = 0.0, a_ = 1.0, vc_ = 0.0;
  double t1_ = 0.0, tc_ = 0.0, t3_ = 0.0, T_ = 0.0;
  double s1_ = 0.0, s3_ = 0.0;  ///< accelerations of phases 1 and 3
};

/// Distance covered by the family for cruise speed vc (exposed for tests).
double profileDistance(double v0, double vc, double a_max, double T);

/// Position, velocity and acceleration of the three axes (world frame; m, m/s, m/s²).
struct CartesianSample {
  Eigen::Vector3d p = Eigen::Vector3d::Zero(),  ///< position, world frame, m
                  v = Eigen::Vector3d::Zero(),  ///< velocity, world frame, m/s
                  a = Eigen::Vector3d::Zero();  ///< acceleration, world frame, m/s²
};

/// Three synchronised axes starting at absolute time t0.
class SyncProfile {
public:
  SyncProfile() = default;
  /// Time-optimal synchronised profile from (p0, v0) at t0 to (pf, 0). Throws InvalidInput for
  /// non-finite input or bad limits.
  static SyncProfile plan(double t0, const Eigen::Vector3d& p0, const Eigen::Vector3d& v0, const Eigen::Vector3d& pf,
                          const Eigen::Vector3d& v_max, const Eigen::Vector3d& a_max);
  /// Minimum synchronised duration (max over axes of T_min), without building the profile.
  static double minimumDuration(const Eigen::Vector3d& p0, const Eigen::Vector3d& v0, const Eigen::Vector3d& pf,
                                const Eigen::Vector3d& v_max, const Eigen::Vector3d& a_max);
  /// Profile from (p0, v0) at t0 to (pf, 0) under Euclidean-norm limits |v| <= v_max (m/s) and
  /// |a| <= a_max (m/s²) (file comment). |v0| above v_max is scaled down to it. Throws InvalidInput
  /// for non-finite input or bad limits.
  static SyncProfile planEuclidean(double t0, const Eigen::Vector3d& p0, const Eigen::Vector3d& v0,
                                   const Eigen::Vector3d& pf, double v_max, double a_max);
  /// Duration (s) of planEuclidean's profile, without building it.
  static double minimumDurationEuclidean(const Eigen::Vector3d& p0, const Eigen::Vector3d& v0,
                                         const Eigen::Vector3d& pf, double v_max, double a_max);
  /// Sample at absolute time t (before t0: the start state; after arrival: at rest at pf).
  CartesianSample at(double t) const;
  /// Start time t0 (s, absolute).
  double startTime() const { return t0_; }
  /// Arrival time t0 + T (s, absolute).
  double arrivalTime() const { return t0_ + T_; }
  /// Duration T (s).
  double duration() const { return T_; }
  /// Goal position (m, world frame).
  const Eigen::Vector3d& goal() const { return pf_; }

private:
  double t0_ = 0.0, T_ = 0.0;
  AxisProfile axes_[3];
  Eigen::Vector3d pf_ = Eigen::Vector3d::Zero();
  bool euclidean_ = false;                             ///< axes_[0..1] run along e1_, e2_ from origin_
  Eigen::Vector3d origin_ = Eigen::Vector3d::Zero();  ///< start point (Euclidean profiles)
  Eigen::Vector3d e1_ = Eigen::Vector3d::Zero(), e2_ = Eigen::Vector3d::Zero();  ///< motion frame
};

}  // namespace viewline::planning
