#include "viewline/tracking/rolling_ball_tracker.h"

#include <Eigen/Cholesky>
#include <algorithm>
#include <cmath>
#include <limits>

#include "viewline/core/checks.h"
#include "viewline/core/error.h"

namespace viewline::tracking {

void RollingBallTrackerConfig::validate() const {
  model.validate();
  core::requirePositive(nominal_period, "RollingBallTrackerConfig.nominal_period");
  core::requirePositive(initial_velocity_std, "RollingBallTrackerConfig.initial_velocity_std");
  core::requireNonNegative(impulse_nis, "RollingBallTrackerConfig.impulse_nis");
  core::requirePositive(impulse_std, "RollingBallTrackerConfig.impulse_std");
  core::requireNonNegative(coloured_sigma, "RollingBallTrackerConfig.coloured_sigma");
  if (!(coloured_correlation >= 0.0 && coloured_correlation < 1.0))
    throw core::InvalidInput("RollingBallTrackerConfig.coloured_correlation: expected in [0, 1)");
  if (coloured_sigma > 0.0 && stationary_gain)
    throw core::InvalidInput("RollingBallTrackerConfig.coloured_sigma: not with the stationary gain");
  gate.validate("RollingBallTrackerConfig.gate");
}

RollingBallTracker::RollingBallTracker(const RollingBallTrackerConfig& config)
    : config_(config), gate_((config.validate(), 2), config.gate) {
  if (config_.stationary_gain) stationary_ = config_.model.stationaryFilter(config_.nominal_period);
}

Eigen::MatrixXd RollingBallTracker::P() const {
  if (stationary_) return stationary_->Pf;
  return initialized_ ? Eigen::MatrixXd(state_.P().topLeftCorner(6, 6)) : Eigen::MatrixXd::Zero(6, 6);
}

void RollingBallTracker::start(double t, const Eigen::Vector2d& a_xy, const Eigen::Vector2d& y, GateDecision why) {
  const auto& model = config_.model;
  x_ = Eigen::VectorXd::Zero(6);
  x_[0] = y[0];
  x_[2] = y[1];
  model.clamp(x_);
  const double sv = model.sigma_v, sp = config_.initial_velocity_std;
  const double sw = std::max(model.sigma_w, 1e-3);
  const double se = config_.coloured_sigma;
  Eigen::VectorXd d(stateDim());
  d.head(6) << sv * sv + se * se, sp * sp, sv * sv + se * se, sp * sp, sw * sw, sw * sw;
  if (stateDim() > 6) d.tail(2).setConstant(se * se);  // the first measurement's coloured error
  Eigen::VectorXd xa = Eigen::VectorXd::Zero(stateDim());
  xa.head(6) = x_;
  Eigen::MatrixXd P0 = d.asDiagonal();
  if (stateDim() > 6) {
    // p̂ = y = p + e + v and ê = 0: the two errors are e + v and −e, covariance −σe².
    for (int i : {0, 1}) P0(2 * i, 6 + i) = P0(6 + i, 2 * i) = -se * se;
  }
  state_ = estimation::StateEstimate(xa, P0, t);
  t_ = t;
  a_prev_ = a_xy;
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
  // Discretised for this interval (from the cache of intervals, see discretised()); with the ramp,
  // `hold` is the same step with the newest a_xy held (Γ u0 + Γ1 u1 with u0 = u1: Γ_ZOH = Γ0 + Γ1),
  // for the predictions beyond t.
  const bool ramp = config_.input_hold == InputHold::Ramp;
  const Discretised& step = discretised(dt);
  estimation::LinearTransition tr = step.tr;
  tr.u.resize(ramp ? 4 : 2);
  if (ramp) {
    tr.u << a_prev_, a_xy;
  } else {
    tr.u = a_xy;
  }
  estimation::LinearTransition hold;
  if (ramp) {
    hold.Phi = tr.Phi;
    hold.Gamma = tr.Gamma.leftCols(2) + tr.Gamma.rightCols(2);
    hold.u = a_xy;
    hold.dt = dt;
  }
  a_prev_ = a_xy;
  if (!stationary_) {
    estimation::LinearTransition aug = step.augmented;
    aug.u = tr.u;
    estimation::predict(state_, aug);
    clampState(state_);
  }
  bool fused = false;
  if (y) {
    // The gate decides on the update's own NIS before the update is kept: the time-varying
    // filter tries it on a copy; the stationary one reads its innovation.
    estimation::StateEstimate trial;
    estimation::UpdateReport rep;
    if (stationary_) {
      rep = stationaryInnovation(tr, *y);
    } else {
      trial = state_;
      rep = estimation::update(trial, measurement(*y));
      if (config_.impulse_nis > 0.0 && rep.nis > config_.impulse_nis) {
        // A push: Δv ~ N(0, q I) at a time τ uniform in the interval, so the position moves by
        // Δv (t − τ) too: var p += q dt²/3, cov(p, v) += q dt/2, var v += q per axis.
        Eigen::MatrixXd P = state_.P();
        const double q = config_.impulse_std * config_.impulse_std;
        for (int i : {0, 2}) {
          P(i, i) += q * dt * dt / 3.0;
          P(i, i + 1) += q * dt / 2.0;
          P(i + 1, i) += q * dt / 2.0;
          P(i + 1, i + 1) += q;
        }
        trial = estimation::StateEstimate(state_.x(), P, state_.t());
        rep = estimation::update(trial, measurement(*y));
        ++impulses_;
      }
    }
    const GateDecision d = gate_.decide(t, rep.nis);
    if (d == GateDecision::Restart) {
      start(t, a_xy, *y, d);
      return;
    }
    last_update_ = BallUpdate{d, rep};
    if (d == GateDecision::Accept) {
      nis_ = rep.nis;
      fused = true;
      if (stationary_) {
        x_ = model.stationaryStep(*stationary_, tr, x_, *y);
      } else {
        state_ = std::move(trial);
        clampState(state_);
      }
    }
  }
  if (!stationary_) {
    x_ = state_.x().head(6);
  } else if (!fused) {
    x_ = tr.Phi * x_ + tr.Gamma * tr.u;
    model.clamp(x_);
  }
  missed_ = fused ? 0 : missed_ + 1;
  t_ = t;
  last_dt_ = dt;
  predictions_ = model.predictPositions(x_, ramp ? hold : tr, 0);  // a_xy held beyond t
}

const RollingBallTracker::Discretised& RollingBallTracker::discretised(double dt) {
  for (const Discretised& d : discretised_)
    if (d.dt == dt) return d;  // exact: the same numbers as discretising again
  Discretised d;
  d.dt = dt;
  const Eigen::Vector2d zero = Eigen::Vector2d::Zero();
  d.tr = config_.input_hold == InputHold::Ramp ? config_.model.transitionRamp(dt, zero, zero)
                                                : config_.model.transition(dt, zero);
  d.augmented = augmented(d.tr);
  if (discretised_.size() < kDiscretisedIntervals) {
    discretised_.push_back(std::move(d));
    return discretised_.back();
  }
  Discretised& slot = discretised_[next_slot_];  // the oldest entry
  next_slot_ = (next_slot_ + 1) % kDiscretisedIntervals;
  slot = std::move(d);
  return slot;
}

Eigen::Index RollingBallTracker::stateDim() const { return config_.coloured_sigma > 0.0 ? 8 : 6; }

estimation::LinearTransition RollingBallTracker::augmented(const estimation::LinearTransition& tr) const {
  if (stateDim() == 6) return tr;
  // e_k = φ^(dt/T) e_{k−1} + η, var η = (1 − φ^(2 dt/T)) σe²: a stationary AR(1) of std σe whose
  // correlation per nominal period T is φ.
  const double phi = std::pow(config_.coloured_correlation, tr.dt / config_.nominal_period);
  const double se = config_.coloured_sigma;
  estimation::LinearTransition a;
  a.dt = tr.dt;
  a.Phi = Eigen::MatrixXd::Zero(8, 8);
  a.Phi.topLeftCorner(6, 6) = tr.Phi;
  a.Phi.bottomRightCorner(2, 2) = phi * Eigen::Matrix2d::Identity();
  a.Q = Eigen::MatrixXd::Zero(8, 8);
  a.Q.topLeftCorner(6, 6) = tr.Q;
  a.Q.bottomRightCorner(2, 2) = (1.0 - phi * phi) * se * se * Eigen::Matrix2d::Identity();
  a.u = tr.u;
  if (tr.Gamma.size() > 0) {
    a.Gamma = Eigen::MatrixXd::Zero(8, tr.Gamma.cols());
    a.Gamma.topRows(6) = tr.Gamma;
  }
  return a;
}

estimation::LinearMeasurement RollingBallTracker::measurement(const Eigen::Vector2d& y) const {
  estimation::LinearMeasurement m = config_.model.measurement(y);
  if (stateDim() == 6) return m;
  Eigen::MatrixXd C = Eigen::MatrixXd::Zero(2, 8);
  C.leftCols(6) = m.C;
  C.rightCols(2) = Eigen::Matrix2d::Identity();  // y = p + e + v
  m.C = C;
  return m;
}

void RollingBallTracker::clampState(estimation::StateEstimate& s) const {
  Eigen::VectorXd x = s.x();
  Eigen::VectorXd head = x.head(6);
  if (!config_.model.clamp(head)) return;
  x.head(6) = head;
  s.setMean(x);
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
