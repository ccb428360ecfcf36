#include "viewline/robots/simulated_pan_tilt.h"

#include <algorithm>
#include <cmath>

#include "viewline/core/checks.h"

namespace viewline::robots {

void SimulatedPanTiltParams::validate() const {
  limits.validate();
  if (!(latency >= 0.0) || !std::isfinite(latency)) throw core::InvalidInput("SimulatedPanTiltParams.latency must be >= 0");
  core::requirePositive(substep, "SimulatedPanTiltParams.substep");
  core::requirePositive(history_seconds, "SimulatedPanTiltParams.history_seconds");
  core::requireFinite(q0, "SimulatedPanTiltParams.q0");
  for (int i = 0; i < 2; ++i) {
    if (q0(i) < limits.q_min(i) || q0(i) > limits.q_max(i)) {
      throw core::InvalidInput("SimulatedPanTiltParams.q0 is outside the joint limits");
    }
  }
}

SimulatedPanTiltUnit::SimulatedPanTiltUnit(const SimulatedPanTiltParams& params, core::Timestamp t0) : params_(params) {
  params_.validate();
  core::requireFinite(t0, "SimulatedPanTiltUnit: t0");
  state_.t = t0;
  state_.q = params_.q0;
  history_.push_back(state_);
}

void SimulatedPanTiltUnit::commandVelocity(core::Timestamp t, const Eigen::Vector2d& qdot) {
  core::requireFinite(t, "SimulatedPanTiltUnit::commandVelocity: t");
  core::requireFinite(qdot, "SimulatedPanTiltUnit::commandVelocity: qdot");
  if (t < last_command_t_) throw core::InvalidInput("SimulatedPanTiltUnit::commandVelocity: time goes backwards");
  if (t < state_.t - 1e-12) throw core::InvalidInput("SimulatedPanTiltUnit::commandVelocity: command in the simulated past");
  last_command_t_ = t;
  log_.push_back({t, qdot});
  Eigen::Vector2d c = qdot;
  for (int i = 0; i < 2; ++i) {
    if (std::abs(c(i)) > params_.limits.qdot_max(i) * (1.0 + 1e-9)) {
      ++rate_violations_;
      c(i) = std::clamp(c(i), -params_.limits.qdot_max(i), params_.limits.qdot_max(i));
    }
  }
  pending_.push_back({t + params_.latency, c});
}

void SimulatedPanTiltUnit::step(double h) {
  const double t_end = state_.t + h;
  for (int i = 0; i < 2; ++i) {
    const double a = params_.limits.qddot_max(i);
    const double v0 = state_.qdot(i);
    const double v1 = v0 + std::clamp(active_(i) - v0, -a * h, a * h);
    double q = state_.q(i) + 0.5 * (v0 + v1) * h;
    double v = v1;
    if (q > params_.limits.q_max(i)) {
      q = params_.limits.q_max(i);
      if (v0 > 0.0) ++limit_hits_;  // arrived at the stop while moving into it
      v = std::min(v, 0.0);
    } else if (q < params_.limits.q_min(i)) {
      q = params_.limits.q_min(i);
      if (v0 < 0.0) ++limit_hits_;
      v = std::max(v, 0.0);
    }
    state_.q(i) = q;
    state_.qdot(i) = v;
  }
  state_.t = t_end;
  history_.push_back(state_);
  while (history_.size() > 2 && history_.front().t < state_.t - params_.history_seconds) history_.pop_front();
}

void SimulatedPanTiltUnit::advanceTo(core::Timestamp t) {
  core::requireFinite(t, "SimulatedPanTiltUnit::advanceTo: t");
  if (t < state_.t - 1e-12) throw core::InvalidInput("SimulatedPanTiltUnit::advanceTo: time goes backwards");
  while (state_.t < t - 1e-12) {
    while (!pending_.empty() && pending_.front().t <= state_.t + 1e-12) {
      active_ = pending_.front().qdot;
      pending_.pop_front();
    }
    double h = std::min(params_.substep, t - state_.t);
    if (!pending_.empty()) h = std::min(h, pending_.front().t - state_.t);
    step(h);
  }
  // The sub-steps' sums can stop up to 1e-12 short of t: land on t, so that now().t is the time asked
  // for (a command at now().t after one at t must not look like time going backwards).
  if (state_.t < t) {
    state_.t = t;
    history_.back().t = t;
  }
}

JointState SimulatedPanTiltUnit::read(core::Timestamp t) {
  core::requireFinite(t, "SimulatedPanTiltUnit::read: t");
  if (t >= state_.t) {
    advanceTo(t);
    return state_;
  }
  if (t <= history_.front().t) return history_.front();
  const auto it = std::lower_bound(history_.begin(), history_.end(), t,
                                   [](const JointState& s, double tt) { return s.t < tt; });
  const JointState& b = *it;
  const JointState& a = *(it - 1);
  const double w = (b.t > a.t) ? (t - a.t) / (b.t - a.t) : 0.0;
  JointState out;
  out.t = t;
  out.q = a.q + w * (b.q - a.q);
  out.qdot = a.qdot + w * (b.qdot - a.qdot);
  return out;
}

}  // namespace viewline::robots
