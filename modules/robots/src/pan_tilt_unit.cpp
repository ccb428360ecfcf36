#include "viewline/robots/pan_tilt_unit.h"

#include <algorithm>
#include <cmath>

#include "viewline/core/checks.h"
#include "viewline/core/frames.h"

namespace viewline::robots {

PanTiltLimits PanTiltLimits::flirPtuD46() {
  PanTiltLimits l;
  l.q_min = Eigen::Vector2d(core::deg2rad(-150.0), core::deg2rad(-47.0));
  l.q_max = Eigen::Vector2d(core::deg2rad(150.0), core::deg2rad(31.0));
  l.qdot_max = Eigen::Vector2d::Constant(core::deg2rad(300.0));
  l.qddot_max = Eigen::Vector2d::Constant(core::deg2rad(1200.0));
  return l;
}

void PanTiltLimits::validate() const {
  core::requireFinite(q_min, "PanTiltLimits.q_min");
  core::requireFinite(q_max, "PanTiltLimits.q_max");
  for (int i = 0; i < 2; ++i) {
    if (!(q_min(i) < q_max(i))) {
      throw core::InvalidInput("PanTiltLimits: q_min must be below q_max on axis " + std::to_string(i));
    }
    core::requirePositive(qdot_max(i), "PanTiltLimits.qdot_max");
    core::requirePositive(qddot_max(i), "PanTiltLimits.qddot_max");
  }
}

JointState predictJointState(const PanTiltLimits& limits, const JointState& now,
                             const std::vector<IssuedCommand>& recent, double latency, core::Timestamp t,
                             double substep) {
  core::requireFinite(now.q, "predictJointState: q");
  core::requireFinite(now.qdot, "predictJointState: qdot");
  if (!(t >= now.t)) throw core::InvalidInput("predictJointState: t is before the state's time");
  core::requirePositive(substep, "predictJointState: substep");
  JointState s = now;
  Eigen::Vector2d active = now.qdot;
  std::size_t next = 0;
  for (; next < recent.size() && recent[next].t + latency <= s.t + 1e-12; ++next) active = recent[next].qdot;
  while (s.t < t - 1e-12) {
    double h = std::min(substep, t - s.t);
    if (next < recent.size()) h = std::min(h, recent[next].t + latency - s.t);
    if (h > 0.0) {
      for (int i = 0; i < 2; ++i) {
        const double a = limits.qddot_max(i);
        const double c = std::clamp(active(i), -limits.qdot_max(i), limits.qdot_max(i));
        const double v0 = s.qdot(i);
        const double v1 = v0 + std::clamp(c - v0, -a * h, a * h);
        s.q(i) = std::clamp(s.q(i) + 0.5 * (v0 + v1) * h, limits.q_min(i), limits.q_max(i));
        s.qdot(i) = v1;
      }
      s.t += h;
    }
    for (; next < recent.size() && recent[next].t + latency <= s.t + 1e-12; ++next) active = recent[next].qdot;
  }
  s.t = t;
  return s;
}

Eigen::Vector2d excursion(double v_e, double v, double hold, double a) {
  // Piecewise-linear velocity: (0, v_e) -> (t1, v1) -> (hold', v1) -> (hold' + |v1|/a, 0), where the
  // ramp may not reach v within hold (then v1 is where it got and hold' = t1 = hold).
  double t1 = std::abs(v - v_e) / a;
  double v1 = v;
  if (t1 > hold) {
    t1 = hold;
    v1 = v_e + (v > v_e ? a : -a) * hold;
  }
  const double knots_t[4] = {0.0, t1, std::max(hold, t1), std::max(hold, t1) + std::abs(v1) / a};
  const double knots_v[4] = {v_e, v1, v1, 0.0};
  double x = 0.0, lo = 0.0, hi = 0.0;
  for (int k = 0; k < 3; ++k) {
    const double dt = knots_t[k + 1] - knots_t[k];
    const double va = knots_v[k], vb = knots_v[k + 1];
    if (dt <= 0.0) continue;
    if (va * vb < 0.0) {  // velocity crosses zero inside: extremum there
      const double tz = dt * va / (va - vb);
      const double xz = x + 0.5 * va * tz;
      lo = std::min(lo, xz);
      hi = std::max(hi, xz);
    }
    x += 0.5 * (va + vb) * dt;
    lo = std::min(lo, x);
    hi = std::max(hi, x);
  }
  return {lo, hi};
}

Eigen::Vector2d limitVelocityCommand(const PanTiltLimits& limits, const Eigen::Vector2d& q_e,
                                     const Eigen::Vector2d& v_e, const Eigen::Vector2d& qdot_desired,
                                     double hold, double margin) {
  core::requireFinite(q_e, "limitVelocityCommand: q_e");
  core::requireFinite(v_e, "limitVelocityCommand: v_e");
  core::requireFinite(qdot_desired, "limitVelocityCommand: qdot_desired");
  if (!(hold >= 0.0) || !(margin >= 0.0)) throw core::InvalidInput("limitVelocityCommand: hold and margin must be >= 0");
  Eigen::Vector2d out = qdot_desired;
  for (int i = 0; i < 2; ++i) {
    const double a = limits.qddot_max(i);
    const double up = limits.q_max(i) - margin - q_e(i);    // room above
    const double down = q_e(i) - (limits.q_min(i) + margin);  // room below
    double v = std::clamp(qdot_desired(i), -limits.qdot_max(i), limits.qdot_max(i));
    if (v > 0.0 && excursion(v_e(i), v, hold, a)(1) > up) {
      if (excursion(v_e(i), 0.0, hold, a)(1) > up) {
        v = 0.0;
      } else {  // largest v in [0, v] with excursion <= up
        double lo = 0.0, hi = v;
        for (int it = 0; it < 60; ++it) {
          const double mid = 0.5 * (lo + hi);
          (excursion(v_e(i), mid, hold, a)(1) <= up ? lo : hi) = mid;
        }
        v = lo;
      }
    } else if (v < 0.0 && -excursion(v_e(i), v, hold, a)(0) > down) {
      if (-excursion(v_e(i), 0.0, hold, a)(0) > down) {
        v = 0.0;
      } else {
        double lo = 0.0, hi = v;  // hi is the negative end
        for (int it = 0; it < 60; ++it) {
          const double mid = 0.5 * (lo + hi);
          (-excursion(v_e(i), mid, hold, a)(0) <= down ? lo : hi) = mid;
        }
        v = lo;
      }
    }
    out(i) = v;
  }
  return out;
}

bool isSafeCommand(const PanTiltLimits& limits, const Eigen::Vector2d& q_e, const Eigen::Vector2d& v_e,
                   const Eigen::Vector2d& qdot, double hold, double tol) {
  for (int i = 0; i < 2; ++i) {
    if (!std::isfinite(qdot(i)) || std::abs(qdot(i)) > limits.qdot_max(i) + tol) return false;
    const Eigen::Vector2d ex = excursion(v_e(i), qdot(i), hold, limits.qddot_max(i));
    // Commands towards a limit must keep the excursion inside; a zero or retreating command is
    // always the safest choice available.
    if (qdot(i) > 0.0 && q_e(i) + ex(1) > limits.q_max(i) + tol) return false;
    if (qdot(i) < 0.0 && q_e(i) + ex(0) < limits.q_min(i) - tol) return false;
  }
  return true;
}

}  // namespace viewline::robots
