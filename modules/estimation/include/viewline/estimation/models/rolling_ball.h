#pragma once
// Ball rolling on a tilting table, with disturbance states ([M] §4.2, eqs
// 4.13-4.30; SPEC §1.2).
//
// State (n = 6), table coordinates (x, y on the surface, z along its normal):
//   x = (p_x, v_x, p_y, v_y, w2_x, w2_y)   [m, m/s, m, m/s, m/s², m/s²]
// Input: u = a_xy [m/s²], the in-plane acceleration of a solid ball rolling
// without slipping,  a_xy = (5/7) [table_R_world · g_world]_xy
// (rollingBallAcceleration; table_R_world from the measured table pose and the
// known camera-to-ground rotation, tableRotationInWorld). On a plane tilted by θ
// its magnitude is (5/7) g sin θ.
// Continuous model, per axis i ∈ {x, y}:
//
//   ṗ_i = v_i
//   v̇_i = a_i + w1_i + w2_i                 w1 white, spectral density σw² [m²/s³]
//   ẇ2_i = −β w2_i + sqrt(2β) σw ε_i        ε unit white noise, so var w2 = σw² (stationary)
//
// The table's own motion (unknown control actions) is the disturbance w1 + w2.
// The input changes every frame (linear time-varying): transition(dt, a_xy) is
// rebuilt for every frame by exact discretisation (Van Loan, discretize()).
// Measurement: y = (p_x, p_y) + e, cov e = σv² I [m²].
// [M]'s tunings: σw = 1, σv = 0.005 (best: close to the measurements but
// smoother) and σw = σv = 1 (lags).
//
// Physical limits ([M] §4.2.1.1): |p_x|, |p_y| <= L/2 − r. Contact with the
// border is inelastic: a position that crosses the limit is clamped to it and
// that velocity component is set to 0 (clamp/clampEstimate). The observer
// outputs the next N (= 10) predicted positions every frame, predicting with
// the clamp (predictPositions), and keeps predicting (predictClamped) while the
// ball is not detected. For a fixed frame interval, Φ and Q do not depend on
// the tilt, so the stationary gain of the DARE (stationaryFilter) can replace
// the time-varying one (stationaryStep).

#include <Eigen/Core>
#include <vector>

#include "viewline/estimation/discretization.h"
#include "viewline/estimation/kalman_filter.h"
#include "viewline/estimation/riccati.h"
#include "viewline/estimation/state.h"

namespace viewline::estimation {

/// a_xy = (5/7) [table_R_world · g_world]_xy  [m/s²]; g_world e.g. (0, 0, −9.81) with z up.
Eigen::Vector2d rollingBallAcceleration(const Eigen::Matrix3d& table_R_world, const Eigen::Vector3d& g_world);

/// table_R_world = c_R_tableᵀ · c_R_world, from the table pose measured by the camera (c_R_table,
/// e.g. solvePnP) and the known camera-to-ground rotation (c_R_world). Both must be rotations.
Eigen::Matrix3d tableRotationInWorld(const Eigen::Matrix3d& c_R_table, const Eigen::Matrix3d& c_R_world);

/// Ball rolling on a tilting table with disturbance states, in table coordinates ([M] §4.2): state (p_x, v_x,
/// p_y, v_y, w2_x, w2_y).
struct RollingBallModel {
  double sigma_w = 1.0;         ///< disturbance intensity σw (w1 density σw², w2 std σw), >= 0
  double beta = 1.0;            ///< inverse correlation time β of w2 [1/s], > 0
  double sigma_v = 0.005;       ///< measurement std σv [m], > 0
  double table_side = 0.3;      ///< table side L [m], > 2 r
  double ball_radius = 0.025;   ///< ball radius r [m], >= 0
  int prediction_steps = 10;    ///< N, predicted positions output every frame, >= 1

  /// State dimension n = 6.
  static constexpr Eigen::Index kStateDim = 6;

  /// A, B, G, Qc of the continuous model (input a_xy, noise (w1_x, w1_y, ε_x, ε_y)).
  ContinuousLinearModel continuous() const;
  /// Φ, Γ, u = a_xy, Q for dt > 0 (rebuild every frame).
  LinearTransition transition(double dt, const Eigen::Vector2d& a_xy) const;
  /// Φ, Γ, Q for dt > 0 with the input ramping from a0 (start of the interval) to a1 (its end):
  /// first-order hold (discretizeFirstOrderHold), Gamma 6 x 4, u = (a0, a1). For a tilt that
  /// the wrist turns between two frames whose tilts are both measured.
  LinearTransition transitionRamp(double dt, const Eigen::Vector2d& a0, const Eigen::Vector2d& a1) const;
  /// C = rows selecting (p_x, p_y), R = σv² I.
  LinearMeasurement measurement(const Eigen::Vector2d& y) const;
  /// L/2 − r [m].
  double positionLimit() const;
  /// Clamps the positions of a state vector to ±positionLimit() and zeroes the velocity of each
  /// clamped axis. Returns true when anything was clamped.
  bool clamp(Eigen::Ref<Eigen::VectorXd> x) const;
  /// The clamp applied to an estimate's mean (covariance unchanged).
  bool clampEstimate(StateEstimate& s) const;
  /// Filter time update followed by the clamp (use while the ball is not detected as well).
  void predictClamped(StateEstimate& s, double dt, const Eigen::Vector2d& a_xy) const;
  /// Noise-free predicted positions at t + dt, ..., t + N dt from mean x with constant input,
  /// clamping at every step; N = `steps` (< 1 means prediction_steps).
  std::vector<Eigen::Vector2d> predictPositions(const Eigen::VectorXd& x, double dt, const Eigen::Vector2d& a_xy,
                                                int steps = 0) const;
  /// The same with the step's transition `tr` already at hand (transition(dt, a_xy)), so a filter
  /// that has just predicted with it does not discretise the model again.
  std::vector<Eigen::Vector2d> predictPositions(const Eigen::VectorXd& x, const LinearTransition& tr, int steps = 0) const;
  /// Stationary filter (DARE) for a fixed frame interval dt.
  StationaryFilter stationaryFilter(double dt) const;
  /// One stationary-gain step: x⁻ = Φ x + Γ u, x⁺ = x⁻ + Kf (y − C x⁻); returns x⁺ (clamped).
  Eigen::VectorXd stationaryStep(const StationaryFilter& sf, const LinearTransition& tr, const Eigen::VectorXd& x,
                                 const Eigen::Vector2d& y) const;
  /// Throws core::InvalidInput naming the field (sigma_w, beta, sigma_v, table_side, ball_radius, prediction_steps).
  void validate() const;
};

}  // namespace viewline::estimation
