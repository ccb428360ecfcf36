#pragma once
// The planar target filter's recent past: one snapshot per measurement of the jump window (the
// measurement and the filter's x(t|t) after it), which the corner detector scans and a detected jump
// re-processes; and the motions those states extrapolate by.

#include <Eigen/Core>
#include <cstdint>
#include <optional>
#include <vector>

#include "viewline/core/time.h"
#include "viewline/estimation/imm.h"
#include "viewline/estimation/state.h"

namespace viewline::tracking {

/// One processed measurement of the planar target filter and the state after it (for jump re-processing).
struct PlanarSnapshot {
  core::Timestamp t = 0.0;  ///< measurement time, s
  Eigen::Vector2d z = Eigen::Vector2d::Zero();  ///< measured position on the plane, m
  Eigen::Matrix2d R = Eigen::Matrix2d::Identity();  ///< its covariance, m²
  estimation::StateEstimate state;       ///< x(t|t) after this measurement
  std::optional<estimation::Imm> imm;  ///< the IMM's full state after this measurement (IMM models only)
  /// Names this snapshot (LegBayesFactors keeps sums by it): increases along a history, and a serial is never
  /// given to another measurement or state (the filter numbers every snapshot it makes).
  std::uint64_t serial = 0;
};
/// The measurements of the last jump window, oldest first.
using PlanarHistory = std::vector<PlanarSnapshot>;

/// The position of state x run by its own model for τ (either sign): (p, v) constant velocity,
/// (p, v, a) constant acceleration, (p, v, ω) coordinated turn.
Eigen::Vector2d extrapolatePosition(const Eigen::VectorXd& x, double tau);

/// atan2 of the state's velocity (rad), NaN when the velocity is ~0.
double velocityDirection(const estimation::StateEstimate& s);

}  // namespace viewline::tracking
