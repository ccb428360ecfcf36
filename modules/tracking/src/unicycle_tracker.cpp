#include "viewline/tracking/unicycle_tracker.h"

#include <algorithm>
#include <cmath>
#include <limits>
#include <string>

#include "viewline/core/error.h"
#include "viewline/estimation/nonlinear.h"

namespace viewline::tracking {

using Eigen::Vector2d;
using Eigen::VectorXd;

void UnicycleTrackerConfig::validate(const char* what) const {
  const std::string w = what;
  if (!(model.q_v >= 0.0) || !(model.q_w >= 0.0) || !std::isfinite(model.q_v) || !std::isfinite(model.q_w))
    throw core::InvalidInput(w + ".q_v/q_w: expected >= 0 and finite");
  if (!(model.input_sigma_v >= 0.0) || !(model.input_sigma_w >= 0.0) || !std::isfinite(model.input_sigma_v) ||
      !std::isfinite(model.input_sigma_w))
    throw core::InvalidInput(w + ".input_sigma_v/input_sigma_w: expected >= 0 and finite");
  if (!(model.input_period > 0.0) || !std::isfinite(model.input_period))
    throw core::InvalidInput(w + ".input_period: expected > 0 and finite");
  if (!(init_speed_sigma > 0.0) || !std::isfinite(init_speed_sigma))
    throw core::InvalidInput(w + ".init_speed_sigma: expected > 0");
  if (!(init_turn_sigma > 0.0) || !std::isfinite(init_turn_sigma))
    throw core::InvalidInput(w + ".init_turn_sigma: expected > 0");
  gate.validate((w + ".gate").c_str());
  if (!(start_window_s > 0.0)) throw core::InvalidInput(w + ".start_window_s: expected > 0");
  if (predictor_window < 2) throw core::InvalidInput(w + ".predictor_window: expected >= 2");
}

namespace {
const UnicycleTrackerConfig& checked(const UnicycleTrackerConfig& c) {
  c.validate();
  return c;
}
}  // namespace

UnicycleTracker::UnicycleTracker(const UnicycleTrackerConfig& config)
    : config_(checked(config)),
      gate_(2, config.gate),
      predictor_(static_cast<std::size_t>(config.predictor_window)) {}

void UnicycleTracker::predictTo(double t) {
  if (!valid_ || t <= est_.t() + 1e-12) return;
  // Q linearised at the prior mean (the held input noise's G depends on θ, v, ω: unicycle.h).
  estimation::ekfPredict(est_, config_.model.transition(t - est_.t(), est_.x()));
}

void UnicycleTracker::start(double t, const Vector2d& z, const Eigen::Matrix2d& R) {
  const Vector2d d = z - *first_;
  const double dt = t - first_t_;
  VectorXd x(5);
  x << z.x(), z.y(), std::atan2(d.y(), d.x()), d.norm() / dt, 0.0;
  const double pos_var = R.trace() / 2.0;
  const double dist = std::max(d.norm(), 1e-3);
  const double th_sigma = std::min(M_PI, std::sqrt(2.0 * pos_var) / dist + 0.2);
  const double v_sigma = std::sqrt(2.0 * pos_var) / dt + config_.init_speed_sigma * 0.5;
  Eigen::MatrixXd P = Eigen::MatrixXd::Zero(5, 5);
  P.topLeftCorner<2, 2>() = R;
  P(2, 2) = th_sigma * th_sigma;
  P(3, 3) = v_sigma * v_sigma;
  P(4, 4) = config_.init_turn_sigma * config_.init_turn_sigma;
  est_ = estimation::StateEstimate(x, P, t);
  valid_ = true;
  predictor_.clear();
  predictor_.add(t, x[3], x[4]);
  first_.reset();
}

UnicycleUpdate UnicycleTracker::update(double t, const Vector2d& z, const Eigen::Matrix2d& R) {
  UnicycleUpdate out;
  out.report.nis = std::numeric_limits<double>::quiet_NaN();
  if (!valid_) {
    if (first_ && t - first_t_ <= config_.start_window_s && t > first_t_) {
      out.decision = gate_.decide(t, out.report.nis);  // no live track in the gate: Start
      start(t, z, R);
      out.fused = true;
      return out;
    }
    first_ = z;
    first_t_ = t;
    return out;
  }
  predictTo(t);
  estimation::NonlinearMeasurement m = estimation::UnicycleModel::positionMeasurement(z, 1.0);
  m.R = R;
  // The update is computed on a copy so that the gate decides on its own report.
  estimation::StateEstimate updated = est_;
  out.report = estimation::ekfUpdate(updated, m);
  out.decision = gate_.decide(t, out.report.nis);
  switch (*out.decision) {
    case GateDecision::Accept:
      est_ = std::move(updated);
      keepSpeedPositive();
      predictor_.add(t, est_.x()[3], est_.x()[4]);
      out.fused = true;
      break;
    case GateDecision::Reject:
      break;
    case GateDecision::Restart:
    case GateDecision::Start:  // Start: the track went stale (gate.max_coast_s)
      // The new track needs two points: this one is the first.
      valid_ = false;
      gate_.drop();
      first_ = z;
      first_t_ = t;
      break;
  }
  return out;
}

void UnicycleTracker::keepSpeedPositive() {
  if (est_.x()[3] >= 0.0) return;
  VectorXd x = est_.x();
  x[2] = estimation::wrapAngle(x[2] + M_PI);
  x[3] = -x[3];
  Eigen::MatrixXd P = est_.P();
  P.row(3) *= -1.0;
  P.col(3) *= -1.0;
  est_.setMean(x);
  est_.setCovariance(P);
  predictor_.clear();  // the speed history had the other sign
}

Vector2d UnicycleTracker::positionAt(double t) const {
  VectorXd x = est_.x();
  const double dt = t - est_.t();
  if (dt > 1e-9) x = config_.model.propagate(x, dt);
  return x.head<2>();
}

}  // namespace viewline::tracking
