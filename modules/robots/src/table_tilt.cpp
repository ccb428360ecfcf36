#include "viewline/robots/table_tilt.h"

#include <algorithm>
#include <cmath>
#include <limits>
#include <string>

#include "viewline/core/checks.h"
#include "viewline/core/error.h"

namespace viewline::robots {

void TableTiltLimits::validate() const {
  core::requirePositive(max_angle, "TableTiltLimits.max_angle");
  core::requirePositive(max_rate, "TableTiltLimits.max_rate");
  core::requireFinite(delay, "TableTiltLimits.delay");
  if (delay < 0.0) throw core::InvalidInput("TableTiltLimits.delay: expected >= 0, got " + std::to_string(delay));
}

Eigen::Vector2d TableTiltLimits::clampAngle(const Eigen::Vector2d& tilt) const {
  return tilt.cwiseMax(-max_angle).cwiseMin(max_angle);
}

bool TableTiltLimits::withinAngle(const Eigen::Vector2d& tilt, double tol) const {
  return tilt.cwiseAbs().maxCoeff() <= max_angle + tol;
}

SimulatedTableTilt::SimulatedTableTilt(const TableTiltLimits& limits, const Eigen::Vector2d& initial_tilt, double t0)
    : limits_(limits), tilt_(initial_tilt), target_(initial_tilt), t_(t0),
      last_command_t_(-std::numeric_limits<double>::infinity()) {
  limits_.validate();
  core::requireFinite(initial_tilt, "SimulatedTableTilt: initial tilt");
  core::requireFinite(t0, "SimulatedTableTilt: t0");
  if (!limits_.withinAngle(initial_tilt)) {
    throw core::InvalidInput("SimulatedTableTilt: initial tilt exceeds max_angle");
  }
}

void SimulatedTableTilt::command(double t, const Eigen::Vector2d& tilt) {
  core::requireFinite(t, "SimulatedTableTilt::command: t");
  core::requireFinite(tilt, "SimulatedTableTilt::command: tilt");
  if (t < last_command_t_) throw core::InvalidInput("SimulatedTableTilt::command: time goes backwards");
  if (t + limits_.delay < t_ - 1e-12) {
    throw core::InvalidInput("SimulatedTableTilt::command: a command at t = " + std::to_string(t) +
                             " would act at " + std::to_string(t + limits_.delay) +
                             ", before the already simulated time " + std::to_string(t_));
  }
  last_command_t_ = t;
  pending_.emplace_back(t + limits_.delay, limits_.clampAngle(tilt));
}

void SimulatedTableTilt::slew(double t) {
  const double dt = t - t_;
  if (dt <= 0.0) return;
  const double max_step = limits_.max_rate * dt;
  tilt_ += (target_ - tilt_).cwiseMax(-max_step).cwiseMin(max_step);
  t_ = t;
}

Eigen::Vector2d SimulatedTableTilt::actual(double t) {
  core::requireFinite(t, "SimulatedTableTilt::actual: t");
  if (t < t_ - 1e-12) throw core::InvalidInput("SimulatedTableTilt::actual: time goes backwards");
  while (!pending_.empty() && pending_.front().first <= t) {
    slew(pending_.front().first);
    target_ = pending_.front().second;
    pending_.pop_front();
  }
  slew(t);
  return tilt_;
}

}  // namespace viewline::robots
