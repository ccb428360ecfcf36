#include "viewline/planning/motion_profile.h"

#include <algorithm>
#include <cmath>
#include <string>

#include "viewline/core/error.h"

namespace viewline::planning {

using core::InvalidInput;

namespace {

void checkLimits(double v_max, double a_max) {
  if (!(std::isfinite(v_max) && v_max > 0.0)) throw InvalidInput("motion profile: v_max must be positive and finite");
  if (!(std::isfinite(a_max) && a_max > 0.0)) throw InvalidInput("motion profile: a_max must be positive and finite");
}

struct Range {
  double lo, hi;
  bool ok;
};

// Feasible cruise speeds for duration T (tc >= 0, |vc| <= v_max).
Range cruiseRange(double v0, double v_max, double a, double T) {
  if (T < std::abs(v0) / a - 1e-12) return {0.0, 0.0, false};
  const double lo = std::max(-v_max, 0.5 * (v0 - a * T));
  const double hi = std::min(v_max, 0.5 * (v0 + a * T));
  return {lo, hi, lo <= hi};
}

}  // namespace

double profileDistance(double v0, double vc, double a, double T) {
  const double t1 = std::abs(vc - v0) / a;
  const double t3 = std::abs(vc) / a;
  const double tc = std::max(0.0, T - t1 - t3);
  return 0.5 * (v0 + vc) * t1 + vc * tc + 0.5 * vc * t3;
}

std::optional<AxisProfile> AxisProfile::forTime(double p0, double v0, double pf, double v_max, double a_max,
                                                double T) {
  checkLimits(v_max, a_max);
  if (!(std::isfinite(p0) && std::isfinite(v0) && std::isfinite(pf) && std::isfinite(T) && T >= 0.0))
    throw InvalidInput("motion profile: non-finite start, goal or duration");
  v0 = std::clamp(v0, -v_max, v_max);
  const double D = pf - p0;
  const Range r = cruiseRange(v0, v_max, a_max, T);
  if (!r.ok) return std::nullopt;
  const double d_lo = profileDistance(v0, r.lo, a_max, T);
  const double d_hi = profileDistance(v0, r.hi, a_max, T);
  const double tol = 1e-9 * (1.0 + std::abs(D));
  if (D < d_lo - tol || D > d_hi + tol) return std::nullopt;
  double lo = r.lo, hi = r.hi;
  for (int it = 0; it < 200 && hi - lo > 1e-15 * (1.0 + v_max); ++it) {
    const double mid = 0.5 * (lo + hi);
    if (profileDistance(v0, mid, a_max, T) < D) lo = mid;
    else hi = mid;
  }
  AxisProfile pr;
  pr.p0_ = p0;
  pr.v0_ = v0;
  pr.pf_ = pf;
  pr.a_ = a_max;
  pr.vc_ = 0.5 * (lo + hi);
  pr.t1_ = std::abs(pr.vc_ - v0) / a_max;
  pr.t3_ = std::abs(pr.vc_) / a_max;
  pr.tc_ = std::max(0.0, T - pr.t1_ - pr.t3_);
  pr.T_ = pr.t1_ + pr.tc_ + pr.t3_;
  pr.s1_ = pr.vc_ >= v0 ? a_max : -a_max;
  pr.s3_ = pr.vc_ >= 0.0 ? -a_max : a_max;
  return pr;
}

double AxisProfile::minimumTime(double p0, double v0, double pf, double v_max, double a_max) {
  checkLimits(v_max, a_max);
  if (!(std::isfinite(p0) && std::isfinite(v0) && std::isfinite(pf)))
    throw InvalidInput("motion profile: non-finite start or goal");
  v0 = std::clamp(v0, -v_max, v_max);
  const double D = pf - p0;
  auto feasible = [&](double T) {
    const Range r = cruiseRange(v0, v_max, a_max, T);
    if (!r.ok) return false;
    const double tol = 1e-12 * (1.0 + std::abs(D));
    return D >= profileDistance(v0, r.lo, a_max, T) - tol && D <= profileDistance(v0, r.hi, a_max, T) + tol;
  };
  double lo = std::abs(v0) / a_max;
  if (feasible(lo)) return lo;
  double hi = std::max(2.0 * lo, 1e-3);
  while (!feasible(hi)) hi *= 2.0;
  for (int it = 0; it < 200 && hi - lo > 1e-13 * (1.0 + hi); ++it) {
    const double mid = 0.5 * (lo + hi);
    if (feasible(mid)) hi = mid;
    else lo = mid;
  }
  return hi;
}

AxisState AxisProfile::at(double t) const {
  AxisState s;
  if (t <= 0.0) {
    s.p = p0_;
    s.v = v0_;
    s.a = s1_;
    return s;
  }
  if (t < t1_) {
    s.a = s1_;
    s.v = v0_ + s1_ * t;
    s.p = p0_ + v0_ * t + 0.5 * s1_ * t * t;
    return s;
  }
  const double p1 = p0_ + v0_ * t1_ + 0.5 * s1_ * t1_ * t1_;
  if (t < t1_ + tc_) {
    s.v = vc_;
    s.p = p1 + vc_ * (t - t1_);
    return s;
  }
  const double p2 = p1 + vc_ * tc_;
  if (t < T_) {
    const double u = t - t1_ - tc_;
    s.a = s3_;
    s.v = vc_ + s3_ * u;
    s.p = p2 + vc_ * u + 0.5 * s3_ * u * u;
    return s;
  }
  s.p = pf_;  // exact goal (the integration above matches it to rounding)
  return s;
}

double SyncProfile::minimumDuration(const Eigen::Vector3d& p0, const Eigen::Vector3d& v0, const Eigen::Vector3d& pf,
                                    const Eigen::Vector3d& v_max, const Eigen::Vector3d& a_max) {
  double T = 0.0;
  for (int i = 0; i < 3; ++i) T = std::max(T, AxisProfile::minimumTime(p0(i), v0(i), pf(i), v_max(i), a_max(i)));
  return T;
}

SyncProfile SyncProfile::plan(double t0, const Eigen::Vector3d& p0, const Eigen::Vector3d& v0,
                              const Eigen::Vector3d& pf, const Eigen::Vector3d& v_max,
                              const Eigen::Vector3d& a_max) {
  if (!std::isfinite(t0)) throw InvalidInput("SyncProfile::plan: non-finite start time");
  SyncProfile s;
  s.t0_ = t0;
  s.pf_ = pf;
  s.T_ = minimumDuration(p0, v0, pf, v_max, a_max);
  for (int i = 0; i < 3; ++i) {
    // The slowest axis is feasible at T by construction; the others at any T >= their T_min.
    // Bisection tolerances can leave T a hair short for the critical axis: nudge it up.
    std::optional<AxisProfile> ax;
    double T = s.T_;
    for (int k = 0; k < 8 && !ax; ++k) {
      ax = AxisProfile::forTime(p0(i), v0(i), pf(i), v_max(i), a_max(i), T);
      T = T * (1.0 + 1e-12) + 1e-12;
    }
    if (!ax) throw core::NumericalError("SyncProfile::plan: axis " + std::to_string(i) + " infeasible at the common time");
    s.axes_[i] = *ax;
  }
  return s;
}

CartesianSample SyncProfile::at(double t) const {
  CartesianSample c;
  for (int i = 0; i < 3; ++i) {
    const AxisState a = axes_[i].at(t - t0_);
    c.p(i) = a.p;
    c.v(i) = a.v;
    c.a(i) = a.a;
  }
  return c;
}

}  // namespace viewline::planning
