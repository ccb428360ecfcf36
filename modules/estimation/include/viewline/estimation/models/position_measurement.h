#pragma once
// Position measurement shared by the kinematic models whose state starts with
// the position block (ballistic, constant velocity, constant acceleration,
// Singer): y = [I_d 0] x + e, cov e = σ² I_d, with d = y.size() (1..3) and
// σ in metres.

#include <Eigen/Core>

#include "viewline/estimation/kalman_filter.h"

namespace viewline::estimation {

/// C = [I_d 0] (d = y.size(), state dimension n >= d), R = sigma² I_d. Throws
/// core::InvalidInput for a non-finite y, sigma <= 0 or NaN, or d > n.
LinearMeasurement positionMeasurement(Eigen::Index state_dim, const Eigen::VectorXd& y, double sigma);

}  // namespace viewline::estimation
