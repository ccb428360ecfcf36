#pragma once
// Where and when does a flying object cross a plane, and how certain is that point?
//
// Plane: {p : n·(p − c) = 0}, n a unit normal pointing towards the incoming object (the object
// is in front while n·(p − c) > 0 and crosses when that becomes 0 with n·v < 0).
// Flight models on the state x = (p, v) (world frame):
//   Ballistic  p̈ = g                      (exact: the crossing time is the smallest positive root of
//                                           n·(p0 − c) + n·v0 τ + ½ n·g τ² = 0)
//   Drag       p̈ = g − k |v| v            (estimation::DragBallisticModel: RK4 marching in steps
//                                           of `step` to bracket the crossing, then Newton on τ,
//                                           τ ← τ − n·(p(τ) − c) / n·v(τ), each iterate propagated
//                                           from the bracketing state)
//
// Uncertainty. With x0 ~ N(x̂0, P0) at t0, the state at the nominal crossing time τ has
//   P_τ = F P0 Fᵀ + Q(τ),   F = ∂x(τ)/∂x0 (exact for Ballistic; RK4 variational equations for
//                                          Drag), Q(τ) the model's process noise over τ.
// Linearising the crossing condition n·(p(τ + δτ) − c) = 0 about the nominal crossing,
//   δτ = −nᵀ δp / (n·v),         δc = δp + v δτ = (I − v nᵀ / (n·v)) δp = A δp,
// so   var(τ) = nᵀ P_pp n / (n·v)²   and   cov(crossing point) = A P_pp Aᵀ
// (rank 2: the point lies in the plane; A is the oblique projection onto the plane along v).

#include <Eigen/Core>
#include <optional>

#include "viewline/core/time.h"
#include "viewline/estimation/state.h"

namespace viewline::planning {

/// A plane {p : n·(p − c) = 0} in the world frame, normal towards the incoming object.
struct CrossingPlane {
  Eigen::Vector3d point = Eigen::Vector3d::Zero();  ///< a point c of the plane, world frame, m
  Eigen::Vector3d normal = Eigen::Vector3d::UnitX();  ///< unit, towards the incoming object
};

/// Flight model of the crossing prediction: drag-free ballistic or quadratic drag.
enum class FlightModel { Ballistic, Drag };
/// Lower-case name of a flight model ("ballistic", "drag").
const char* toString(FlightModel m);

/// How crossings are predicted: flight model, gravity, drag, process noise and horizon.
struct CrossingModel {
  FlightModel kind = FlightModel::Drag;  ///< flight model
  Eigen::Vector3d gravity_w = Eigen::Vector3d(0.0, 0.0, -9.81);  ///< gravity in the world frame, m/s² (z up by default)
  double drag_k = 0.0;       ///< k = ρ Cd A / (2 m), 1/m (Drag only)
  double accel_psd = 0.0;    ///< process noise q of the prediction, m²/s³ (0: none)
  double max_horizon = 3.0;  ///< s; no crossing further ahead is reported
  double step = 0.01;        ///< s, RK4 bracketing step (Drag)
  /// Throws core::InvalidInput naming the field.
  void validate() const;
};

/// A predicted plane crossing: time, point, velocity and their uncertainty.
struct Crossing {
  core::Timestamp t = 0.0;           ///< absolute crossing time
  Eigen::Vector3d p = Eigen::Vector3d::Zero();  ///< crossing point (on the plane)
  Eigen::Vector3d v = Eigen::Vector3d::Zero();  ///< velocity at the crossing
  Eigen::Matrix3d cov_p = Eigen::Matrix3d::Zero();  ///< covariance of the crossing point, m²
  double var_t = 0.0;                ///< variance of the crossing time, s²
  /// Largest standard deviation of the crossing point (in the plane), m.
  double sigmaMax() const;
};

/// Crossing of the state estimate `est` (x = (p, v), P, time t0) with the plane, if the object
/// crosses it (from the front, n·v < 0) within the horizon. Throws InvalidInput for a state that
/// is not 6-dimensional or a plane normal that is not unit.
std::optional<Crossing> predictCrossing(const estimation::StateEstimate& est, const CrossingPlane& plane,
                                        const CrossingModel& model);

/// The mean-only version (no covariance), for a known state (truth, Monte-Carlo tests).
std::optional<Crossing> predictCrossing(const Eigen::Matrix<double, 6, 1>& x0, core::Timestamp t0,
                                        const CrossingPlane& plane, const CrossingModel& model);

}  // namespace viewline::planning
