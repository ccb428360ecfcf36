#include "viewline/tracking/rolling_ball_tracker.h"

#include <Eigen/Cholesky>
#include <algorithm>
#include <limits>

#include "viewline/core/checks.h"
#include "viewline/core/error.h"

namespace viewline::tracking {

void RollingBallTrackerConfig::validate() const {
  model.validate();
  core::requirePositive(nominal_period, "RollingBallTrackerConfig.nominal_period");
  core::requirePositive(initial_velocity_std, "RollingBallTrackerConfig.initial_velocity_std");
  gate.validate("RollingBallTrackerConfig.gate");
}

RollingBallTracker::RollingBallTracker(const RollingBallTrackerConfig& config)
    : config_(config), gate_((config.validate(), 2), config.gate) {
  if (config_.stationary_gain) stationary_ = config_.model.stationaryFilter(config_.nominal_period);
}

Eigen::MatrixXd RollingBallTracker::P() const {
  if (stationary_) return stationary_->Pf;
  return initialized_ ? state_.P() : Eigen::MatrixXd::Zero(6, 6);
}

void RollingBallTracker::start(double t, const Eigen::Vector2d& a_xy, const Eigen::Vector2d& y, GateDecision why) {
  const auto& model = config_.model;
  x_ = Eigen::VectorXd::Zero(6);
  x_[0] = y[0];
  x_[2] = y[1];
  model.clamp(x_);
  const double sv = model.sigma_v, sp = config_.initial_velocity_std;
  const double sw = std::max(model.sigma_w, 1e-3);
  Eigen::VectorXd d(6);
  d << sv * sv, sp * sp, sv * sv, sp * sp, sw * sw, sw * sw;
  state_ = estimation::StateEstimate(x_, d.asDiagonal(), t);
  t_ = t;
  initialized_ = true;
  missed_ = 0;
  predictions_ = model.predictPositions(x_, last_dt_, a_xy);
  last_update_ = BallUpdate{why, {}};
  last_update_->report.rows = 2;
}

void RollingBallTracker::step(double t, const Eigen::Vector2d& a_xy, const std::optional<Eigen::Vector2d>& y) {
  core::requireFinite(t, "RollingBallTracker::step: t");
  core::requireFinite(a_xy, "RollingBallTracker::step: a_xy");
  if (y) core::requireFinite(*y, "RollingBallTracker::step: measurement");
  const auto& model = config_.model;
  last_update_.reset();
  if (!initialized_) {
    if (!y) return;
    const GateDecision d = gate_.decide(t, 0.0);  // no track yet: Start
    start(t, a_xy, *y, d);
    return;
  }
  if (!(t > t_)) throw core::InvalidInput("RollingBallTracker::step: time must increase");
  const double dt = t - t_;
  const estimation::LinearTransition tr = model.transition(dt, a_xy);  // rediscretised every frame
  bool fused = false;
  if (stationary_) {
    if (y) {
      const estimation::UpdateReport rep = stationaryInnovation(tr, *y);
      const GateDecision d = gate_.decide(t, rep.nis);
      if (d == GateDecision::Restart) {
        start(t, a_xy, *y, d);
        return;
      }
      last_update_ = BallUpdate{d, rep};
      if (d == GateDecision::Accept) {
        nis_ = rep.nis;
        x_ = model.stationaryStep(*stationary_, tr, x_, *y);
        fused = true;
      }
    }
    if (!fused) {
      x_ = tr.Phi * x_ + tr.Gamma * tr.u;
      model.clamp(x_);
    }
  } else {
    estimation::predict(state_, tr);
    model.clampEstimate(state_);
    if (y) {
      // The update is tried on a copy: the gate decides on its own NIS before it is kept.
      estimation::StateEstimate trial = state_;
      const estimation::UpdateReport rep = estimation::update(trial, model.measurement(*y));
      const GateDecision d = gate_.decide(t, rep.nis);
      if (d == GateDecision::Restart) {
        start(t, a_xy, *y, d);
        return;
      }
      last_update_ = BallUpdate{d, rep};
      if (d == GateDecision::Accept) {
        state_ = std::move(trial);
        nis_ = rep.nis;
        model.clampEstimate(state_);
        fused = true;
      }
    }
    x_ = state_.x();
  }
  missed_ = fused ? 0 : missed_ + 1;
  t_ = t;
  last_dt_ = dt;
  predictions_ = model.predictPositions(x_, dt, a_xy);
}

estimation::UpdateReport RollingBallTracker::stationaryInnovation(const estimation::LinearTransition& tr,
                                                                 const Eigen::Vector2d& y) const {
  // The innovation RollingBallModel::stationaryStep fuses, with the stationary a-priori
  // covariance (read only: the step itself stays the model's).
  Eigen::VectorXd xp = tr.Phi * x_;
  if (tr.u.size() > 0) xp += tr.Gamma * tr.u;
  const estimation::LinearMeasurement m = config_.model.measurement(y);
  estimation::UpdateReport rep;
  rep.rows = 2;
  rep.innovation = y - m.C * xp;
  rep.S = m.C * stationary_->P * m.C.transpose() + m.R;
  const Eigen::LLT<Eigen::MatrixXd> llt(rep.S);
  rep.nis = llt.info() == Eigen::Success ? rep.innovation.dot(llt.solve(rep.innovation))
                                         : std::numeric_limits<double>::quiet_NaN();
  return rep;
}

}  // namespace viewline::tracking
