#include "viewline/planning/motion_profile.h"

#include <algorithm>
#include <cmath>
#include <cstring>
#include <limits>
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

AxisProfile AxisProfile::fromPhases(double p0, double v0, double s1, double t1, double tc, double s3, double t3) {
  AxisProfile pr;
  pr.p0_ = p0;
  pr.v0_ = v0;
  pr.s1_ = s1;
  pr.t1_ = t1;
  pr.vc_ = v0 + s1 * t1;
  pr.tc_ = tc;
  pr.s3_ = s3;
  pr.t3_ = t3;
  pr.a_ = std::max(std::abs(s1), std::abs(s3));
  pr.T_ = t1 + tc + t3;
  pr.pf_ = p0 + v0 * t1 + 0.5 * s1 * t1 * t1 + pr.vc_ * (tc + t3) + 0.5 * s3 * t3 * t3;
  return pr;
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

namespace {

// One axis of the family can go from (p0, v0) to (pf, 0) in exactly T under (v_max, a_max).
bool axisFeasible(double p0, double v0, double pf, double v_max, double a_max, double T) {
  const double D = pf - p0;
  const Range r = cruiseRange(v0, v_max, a_max, T);
  if (!r.ok) return false;
  const double tol = 1e-12 * (1.0 + std::abs(D));
  return D >= profileDistance(v0, r.lo, a_max, T) - tol && D <= profileDistance(v0, r.hi, a_max, T) + tol;
}

// The Euclidean problem in its motion frame: axis k starts at 0 with speed v0k and ends at dk.
struct NormProblem {
  Eigen::Vector3d e1 = Eigen::Vector3d::UnitX(), e2 = Eigen::Vector3d::Zero();
  double d[2] = {0.0, 0.0}, v0[2] = {0.0, 0.0}, lo[2] = {0.0, 0.0};
  double V = 1.0, A = 1.0;

  bool idle(int k) const { return d[k] == 0.0 && v0[k] == 0.0; }
  // Smallest weight w in [lo_k, 1] with which axis k arrives at T (+inf: none).
  double weightFor(int k, double T) const {
    if (idle(k)) return 0.0;
    auto ok = [&](double w) { return w > 0.0 && axisFeasible(0.0, v0[k], d[k], V * w, A * w, T); };
    if (!ok(1.0)) return std::numeric_limits<double>::infinity();
    if (ok(lo[k])) return lo[k];
    double a = lo[k], b = 1.0;
    for (int it = 0; it < 60 && b - a > 1e-14; ++it) {
      const double m = 0.5 * (a + b);
      if (ok(m)) b = m;
      else a = m;
    }
    return b;
  }
  // Both axes arrive at T within the Euclidean limits when w0 = weightFor(0, T) and
  // w1 = weightFor(1, T) are finite and w0² + w1² <= 1 + 1e-12 (the nested bisection, the
  // reference of planning_test MotionProfile.EuclideanMinimumTimeEqualsTheNestedBisection);
  // feasibleByBounds below gives the same answer with fewer steps.

  // weightFor(k, T)'s bisection, run only as far as a caller needs it: the answer it would
  // return lies in [lower(), upper()] at every step (a only rises, b only falls, and the answer
  // is a later b, a midpoint that passed), and is exact once the loop of weightFor would stop.
  struct Weight {
    double a = 0.0, b = 0.0;
    int it = 0;
    bool exact = false;  // b is the answer
    double lower() const { return exact ? b : a; }
    double upper() const { return b; }
  };
  // Starts weightFor(k, T); false when it answers +inf (axis k cannot arrive at T).
  bool startWeight(int k, double T, Weight& w) const {
    if (idle(k)) {
      w.b = 0.0;
      w.exact = true;
      return true;
    }
    if (!weightOk(k, 1.0, T)) return false;
    if (weightOk(k, lo[k], T)) {
      w.b = lo[k];
      w.exact = true;
      return true;
    }
    w.a = lo[k];
    w.b = 1.0;
    w.it = 0;
    w.exact = !(w.it < 60 && w.b - w.a > 1e-14);
    return true;
  }
  // One step of weightFor's loop (the same midpoint, test and stop rule).
  void refineWeight(int k, double T, Weight& w) const {
    const double m = 0.5 * (w.a + w.b);
    if (weightOk(k, m, T)) w.b = m;
    else w.a = m;
    ++w.it;
    w.exact = !(w.it < 60 && w.b - w.a > 1e-14);
  }
  bool weightOk(int k, double w, double T) const {
    return w > 0.0 && axisFeasible(0.0, v0[k], d[k], V * w, A * w, T);
  }
  // feasible(T) with the same answer, bisecting the weights only until the test is decided:
  // w0² + w1² (rounded) is non-decreasing in each weight >= 0, so the bounds of both weights
  // decide it as soon as both bounds fall on one side of the threshold. Most arrival times the
  // outer bisection tries are far from the minimum; there a few steps of the weights decide.
  bool feasibleByBounds(double T) const {
    Weight w[2];
    if (!startWeight(0, T, w[0]) || !startWeight(1, T, w[1])) return false;
    const double limit = 1.0 + 1e-12;
    for (;;) {
      const double up0 = w[0].upper(), up1 = w[1].upper();
      if (up0 * up0 + up1 * up1 <= limit) return true;
      const double lo0 = w[0].lower(), lo1 = w[1].lower();
      if (lo0 * lo0 + lo1 * lo1 > limit) return false;
      // Undecided: at least one weight is still a bracket; narrow the wider one.
      const int k = w[0].exact ? 1 : w[1].exact ? 0 : (w[0].b - w[0].a >= w[1].b - w[1].a ? 0 : 1);
      refineWeight(k, T, w[k]);
    }
  }

  double minimumTime() const {
    if (idle(0) && idle(1)) return 0.0;
    double lo_t = 0.0, hi_t = 1e-3;
    for (int k = 0; !feasibleByBounds(hi_t); ++k) {
      if (k > 60) throw core::NumericalError("SyncProfile::planEuclidean: no feasible arrival time");
      lo_t = hi_t;
      hi_t *= 2.0;
    }
    for (int it = 0; it < 200 && hi_t - lo_t > 1e-13 * (1.0 + hi_t); ++it) {
      const double mid = 0.5 * (lo_t + hi_t);
      if (feasibleByBounds(mid)) hi_t = mid;
      else lo_t = mid;
    }
    return hi_t;
  }
};

NormProblem normProblem(const Eigen::Vector3d& p0, const Eigen::Vector3d& v0_in, const Eigen::Vector3d& pf,
                        double v_max, double a_max) {
  checkLimits(v_max, a_max);
  if (!(p0.allFinite() && v0_in.allFinite() && pf.allFinite()))
    throw InvalidInput("SyncProfile::planEuclidean: non-finite start or goal");
  NormProblem np;
  np.V = v_max;
  np.A = a_max;
  Eigen::Vector3d v0 = v0_in;
  if (v0.norm() > v_max) v0 *= v_max / v0.norm();
  const Eigen::Vector3d D = pf - p0;
  const double dist = D.norm();
  if (dist > 0.0) np.e1 = D / dist;
  else if (v0.norm() > 0.0) np.e1 = v0.normalized();
  np.d[0] = dist;
  np.v0[0] = v0.dot(np.e1);
  const Eigen::Vector3d across = v0 - np.v0[0] * np.e1;
  if (across.norm() > 1e-12 * v_max) {
    np.e2 = across.normalized();
    np.v0[1] = across.norm();
  }
  np.lo[0] = std::abs(np.v0[0]) / v_max;
  np.lo[1] = np.v0[1] / v_max;
  const double l = std::hypot(np.lo[0], np.lo[1]);
  if (l > 1.0) {  // |v0| = V up to rounding
    np.lo[0] /= l;
    np.lo[1] /= l;
  }
  return np;
}

}  // namespace

namespace {

// The velocity-chord family (file comment): direction u, phase-1 duration t1, cruise tc and the
// motion frame, or nothing when the cruise line cannot be reached (goal too close to turn onto).
struct ChordPlan {
  Eigen::Vector3d u = Eigen::Vector3d::UnitX(), e2 = Eigen::Vector3d::Zero();
  double t1 = 0.0, tc = 0.0, T = 0.0;
};

std::optional<ChordPlan> chordPlan(const Eigen::Vector3d& p0, Eigen::Vector3d v0, const Eigen::Vector3d& pf,
                                   double V, double A) {
  if (v0.norm() > V) v0 *= V / v0.norm();
  const double brake = V * V / (2.0 * A);
  Eigen::Vector3d d = pf - p0;
  if (!(d.norm() > brake)) return std::nullopt;
  ChordPlan c;
  c.u = d.normalized();
  bool converged = false;
  for (int it = 0; it < 40 && !converged; ++it) {
    c.t1 = (V * c.u - v0).norm() / A;
    d = pf - (p0 + 0.5 * (v0 + V * c.u) * c.t1);
    if (!(d.norm() > brake)) return std::nullopt;
    const Eigen::Vector3d un = d.normalized();
    converged = (un - c.u).norm() < 1e-13;
    c.u = un;
  }
  if (!converged) return std::nullopt;
  c.t1 = (V * c.u - v0).norm() / A;
  d = pf - (p0 + 0.5 * (v0 + V * c.u) * c.t1);
  c.tc = (d.norm() - brake) / V;
  c.T = c.t1 + c.tc + V / A;
  const Eigen::Vector3d across = v0 - c.u * c.u.dot(v0);
  if (across.norm() > 1e-15) c.e2 = across.normalized();
  return c;
}

}  // namespace

namespace {

// NormProblem(p0, v0, pf, V, A).minimumTime(), the last answer kept per thread: the catch planner
// asks twice per update with the same numbers (its arrival test, then the profile it plans to
// the same goal from the same state). Keyed on the inputs' bits, so the answer is the same double.
double euclideanMinimumTime(const NormProblem& np, const Eigen::Vector3d& p0, const Eigen::Vector3d& v0,
                            const Eigen::Vector3d& pf, double v_max, double a_max) {
  struct Key {
    double v[11];
  };
  const Key key{{p0.x(), p0.y(), p0.z(), v0.x(), v0.y(), v0.z(), pf.x(), pf.y(), pf.z(), v_max, a_max}};
  thread_local Key last_key{};
  thread_local double last_T = 0.0;
  thread_local bool have = false;
  if (have && std::memcmp(key.v, last_key.v, sizeof key.v) == 0) return last_T;
  const double T = np.minimumTime();
  last_key = key;
  last_T = T;
  have = true;
  return T;
}

}  // namespace

double SyncProfile::minimumDurationEuclidean(const Eigen::Vector3d& p0, const Eigen::Vector3d& v0,
                                             const Eigen::Vector3d& pf, double v_max, double a_max) {
  const double T = euclideanMinimumTime(normProblem(p0, v0, pf, v_max, a_max), p0, v0, pf, v_max, a_max);
  const std::optional<ChordPlan> c = chordPlan(p0, v0, pf, v_max, a_max);
  return c ? std::min(T, c->T) : T;
}

SyncProfile SyncProfile::planEuclidean(double t0, const Eigen::Vector3d& p0, const Eigen::Vector3d& v0,
                                       const Eigen::Vector3d& pf, double v_max, double a_max) {
  if (!std::isfinite(t0)) throw InvalidInput("SyncProfile::planEuclidean: non-finite start time");
  const NormProblem np = normProblem(p0, v0, pf, v_max, a_max);
  SyncProfile s;
  s.t0_ = t0;
  s.pf_ = pf;
  s.euclidean_ = true;
  s.origin_ = p0;
  s.e1_ = np.e1;
  s.e2_ = np.e2;
  s.T_ = euclideanMinimumTime(np, p0, v0, pf, v_max, a_max);
  if (const std::optional<ChordPlan> c = chordPlan(p0, v0, pf, v_max, a_max); c && c->T < s.T_) {
    // The velocity chord is faster (a turn from a moving start): axis 1 along u, axis 2 across.
    const Eigen::Vector3d v = v0.norm() > v_max ? Eigen::Vector3d(v0 * (v_max / v0.norm())) : v0;
    const double v1 = v.dot(c->u), v2 = v.dot(c->e2);
    const double s1 = c->t1 > 0.0 ? (v_max - v1) / c->t1 : 0.0, s2 = c->t1 > 0.0 ? -v2 / c->t1 : 0.0;
    s.e1_ = c->u;
    s.e2_ = c->e2;
    s.T_ = c->T;
    s.axes_[0] = AxisProfile::fromPhases(0.0, v1, s1, c->t1, c->tc, -a_max, v_max / a_max);
    s.axes_[1] = AxisProfile::fromPhases(0.0, v2, s2, c->t1, 0.0, 0.0, 0.0);
    return s;
  }
  for (int k = 0; k < 2; ++k) {
    if (np.idle(k)) continue;  // the default axis stays at 0, at rest
    // Bisection tolerances can leave T a hair short for the critical axis: nudge it up (as plan()).
    std::optional<AxisProfile> ax;
    double T = s.T_;
    for (int it = 0; it < 8 && !ax; ++it) {
      const double w = np.weightFor(k, T);
      if (std::isfinite(w)) ax = AxisProfile::forTime(0.0, np.v0[k], np.d[k], v_max * w, a_max * w, T);
      T = T * (1.0 + 1e-12) + 1e-12;
    }
    if (!ax) throw core::NumericalError("SyncProfile::planEuclidean: axis " + std::to_string(k) + " infeasible");
    s.axes_[k] = *ax;
  }
  return s;
}

CartesianSample SyncProfile::at(double t) const {
  CartesianSample c;
  if (euclidean_) {
    if (t - t0_ >= T_) {
      c.p = pf_;  // exact goal, at rest
      return c;
    }
    const AxisState a = axes_[0].at(t - t0_), b = axes_[1].at(t - t0_);
    c.p = origin_ + a.p * e1_ + b.p * e2_;
    c.v = a.v * e1_ + b.v * e2_;
    c.a = a.a * e1_ + b.a * e2_;
    return c;
  }
  for (int i = 0; i < 3; ++i) {
    const AxisState a = axes_[i].at(t - t0_);
    c.p(i) = a.p;
    c.v(i) = a.v;
    c.a(i) = a.a;
  }
  return c;
}

}  // namespace viewline::planning
