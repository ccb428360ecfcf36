// Motion profiles: limits respected, exact arrival, synchronised arrival, optimality, continuity
// of replanning from a moving state.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <limits>

#include "viewline/core/error.h"
#include "viewline/core/random.h"
#include "viewline/planning/motion_profile.h"

using namespace viewline;
using planning::AxisProfile;
using planning::SyncProfile;

namespace {

// Checks a sampled profile against the limits and the integration p' = v (finite differences).
void expectWithinLimits(const SyncProfile& pr, const Eigen::Vector3d& vmax, const Eigen::Vector3d& amax) {
  const double dt = 1e-4;
  auto prev = pr.at(pr.startTime());
  for (double t = pr.startTime() + dt; t <= pr.arrivalTime() + 0.05; t += dt) {
    const auto s = pr.at(t);
    for (int i = 0; i < 3; ++i) {
      ASSERT_LE(std::abs(s.v(i)), vmax(i) * (1 + 1e-9)) << "axis " << i << " t " << t;
      ASSERT_LE(std::abs(s.v(i) - prev.v(i)) / dt, amax(i) * (1 + 1e-6)) << "axis " << i << " t " << t;
      // position consistent with the velocity: the trapezoid rule is exact for linear v and off
      // by at most |Δa| dt² / 8 <= a_max dt² / 4 when the step contains a phase switch
      ASSERT_NEAR(s.p(i) - prev.p(i), 0.5 * (s.v(i) + prev.v(i)) * dt, amax(i) * dt * dt / 4 + 1e-12)
          << "axis " << i << " t " << t;
    }
    prev = s;
  }
}

}  // namespace

TEST(MotionProfile, RestToRestMatchesTrapezoidFormula) {
  // 1-D rest to rest: T = D/v + v/a when D > v²/a, else 2 sqrt(D/a).
  EXPECT_NEAR(AxisProfile::minimumTime(0, 0, 0.3, 0.5, 13), 0.3 / 0.5 + 0.5 / 13, 1e-9);
  EXPECT_NEAR(AxisProfile::minimumTime(0, 0, 0.01, 0.5, 13), 2 * std::sqrt(0.01 / 13), 1e-9);
  EXPECT_NEAR(AxisProfile::minimumTime(1, 0, 0.7, 0.5, 13), 0.3 / 0.5 + 0.5 / 13, 1e-9);
  EXPECT_EQ(AxisProfile::minimumTime(0.2, 0, 0.2, 0.5, 13), 0.0);
}

TEST(MotionProfile, MovingStartNeedsOvershoot) {
  // Moving at 0.5 m/s towards a goal 1 cm ahead: stopping takes 0.5²/26 = 9.6 mm... plus it must
  // come back when the goal is closer than the stopping distance.
  const double T = AxisProfile::minimumTime(0, 0.5, 0.005, 0.5, 13);
  auto pr = AxisProfile::forTime(0, 0.5, 0.005, 0.5, 13, T);
  ASSERT_TRUE(pr);
  EXPECT_LT(pr->cruiseVelocity(), 0.0);  // comes back
  EXPECT_NEAR(pr->at(T).p, 0.005, 1e-9);
  EXPECT_NEAR(pr->at(T - 1e-9).v, 0.0, 1e-6);
  // A slightly shorter time is infeasible.
  EXPECT_FALSE(AxisProfile::forTime(0, 0.5, 0.005, 0.5, 13, T * 0.99));
}

TEST(MotionProfile, RandomProfilesRespectLimitsAndArriveTogether) {
  core::Rng rng = core::makeRng(7);
  const Eigen::Vector3d vmax(0.5, 0.4, 0.6), amax(13, 10, 8);
  for (int k = 0; k < 200; ++k) {
    Eigen::Vector3d p0, v0, pf;
    for (int i = 0; i < 3; ++i) {
      p0(i) = core::uniform(rng, -0.5, 0.5);
      pf(i) = core::uniform(rng, -0.5, 0.5);
      v0(i) = core::uniform(rng, -vmax(i), vmax(i));
    }
    const double t0 = core::uniform(rng, 0, 3);
    const SyncProfile pr = SyncProfile::plan(t0, p0, v0, pf, vmax, amax);
    // Starts at the given state.
    EXPECT_LT((pr.at(t0).p - p0).norm(), 1e-12);
    EXPECT_LT((pr.at(t0).v - v0).norm(), 1e-12);
    // Every axis is at its goal at rest exactly at the common arrival time, none before.
    const auto end = pr.at(pr.arrivalTime());
    EXPECT_LT((end.p - pf).norm(), 1e-9);
    for (int i = 0; i < 3; ++i) {
      const double Ti = AxisProfile::minimumTime(p0(i), v0(i), pf(i), vmax(i), amax(i));
      EXPECT_LE(Ti, pr.duration() + 1e-9);
      const auto before = pr.at(pr.arrivalTime() - 1e-3);
      if (std::abs(pf(i) - p0(i)) > 1e-3 || std::abs(v0(i)) > 1e-2) {
        EXPECT_TRUE(std::abs(before.p(i) - pf(i)) > 1e-12 || std::abs(before.v(i)) > 1e-9)
            << "axis " << i << " arrived early";
      }
    }
    EXPECT_NEAR(pr.duration(), SyncProfile::minimumDuration(p0, v0, pf, vmax, amax), 1e-12);
    expectWithinLimits(pr, vmax, amax);
  }
}

TEST(MotionProfile, MinimumTimeIsOptimal) {
  // No profile of the family is feasible at 0.999 T_min, for random starts.
  core::Rng rng = core::makeRng(11);
  for (int k = 0; k < 300; ++k) {
    const double p0 = core::uniform(rng, -1, 1), pf = core::uniform(rng, -1, 1), v0 = core::uniform(rng, -0.5, 0.5);
    const double T = AxisProfile::minimumTime(p0, v0, pf, 0.5, 13);
    EXPECT_TRUE(AxisProfile::forTime(p0, v0, pf, 0.5, 13, T).has_value());
    if (T > 1e-6) {
      EXPECT_FALSE(AxisProfile::forTime(p0, v0, pf, 0.5, 13, 0.999 * T).has_value());
    }
    // Any longer time is feasible (the feasible set is [T_min, inf)).
    EXPECT_TRUE(AxisProfile::forTime(p0, v0, pf, 0.5, 13, 1.5 * T + 0.01).has_value());
  }
}

TEST(MotionProfile, ReplanningFromTheCurrentStateIsContinuous) {
  const Eigen::Vector3d vmax = Eigen::Vector3d::Constant(0.5), amax = Eigen::Vector3d::Constant(13);
  core::Rng rng = core::makeRng(3);
  SyncProfile pr = SyncProfile::plan(0, Eigen::Vector3d::Zero(), Eigen::Vector3d::Zero(),
                                     Eigen::Vector3d(0, 0.3, -0.2), vmax, amax);
  double t = 0;
  const double dt = 1e-3;
  auto prev = pr.at(0);
  for (int step = 1; step < 1500; ++step) {
    t = step * dt;
    if (step % 20 == 0) {  // new goal every 20 ms, from the current commanded state
      const auto s = pr.at(t);
      pr = SyncProfile::plan(t, s.p, s.v,
                             Eigen::Vector3d(0, core::uniform(rng, -0.3, 0.3), core::uniform(rng, -0.3, 0.3)), vmax,
                             amax);
    }
    const auto s = pr.at(t);
    for (int i = 0; i < 3; ++i) {
      ASSERT_LE(std::abs(s.v(i) - prev.v(i)), amax(i) * dt * (1 + 1e-6)) << "velocity step at t " << t;
      ASSERT_LE(std::abs(s.p(i) - prev.p(i)), vmax(i) * dt * (1 + 1e-6)) << "position jump at t " << t;
    }
    prev = s;
  }
}

TEST(MotionProfile, RejectsBadInput) {
  EXPECT_THROW(AxisProfile::minimumTime(0, 0, 1, 0.0, 13), core::InvalidInput);
  EXPECT_THROW(AxisProfile::minimumTime(0, 0, 1, 0.5, -1), core::InvalidInput);
  EXPECT_THROW(AxisProfile::minimumTime(0, 0, NAN, 0.5, 13), core::InvalidInput);
}

namespace {

// Samples a profile every 0.1 ms: |v| and the mean |Δv / Δt| under the Euclidean limits, and p' = v.
void expectWithinNormLimits(const SyncProfile& pr, double vmax, double amax) {
  const double dt = 1e-4;
  auto prev = pr.at(pr.startTime());
  for (double t = pr.startTime() + dt; t <= pr.arrivalTime() + 0.05; t += dt) {
    const auto s = pr.at(t);
    ASSERT_LE(s.v.norm(), vmax * (1 + 1e-9)) << "t " << t;
    ASSERT_LE(s.a.norm(), amax * (1 + 1e-9)) << "t " << t;
    ASSERT_LE((s.v - prev.v).norm() / dt, amax * (1 + 1e-6)) << "t " << t;
    ASSERT_LE((s.p - prev.p - 0.5 * (s.v + prev.v) * dt).norm(), amax * dt * dt / 4 + 1e-12) << "t " << t;
    prev = s;
  }
}

}  // namespace

// From rest the Euclidean profile is the straight bang-coast-bang line: its time is the 1-D
// trapezoid time of the distance under (v_max, a_max), whatever the direction; the per-axis
// profile of a diagonal move is faster (each axis gets the full limit), by up to √3.
TEST(MotionProfile, EuclideanFromRestIsTheStraightTrapezoid) {
  const Eigen::Vector3d p0(4.0, 0.0, 1.1);
  for (const Eigen::Vector3d& d : {Eigen::Vector3d(0, 0.3, 0), Eigen::Vector3d(0, 0.3, -0.3),
                                   Eigen::Vector3d(0.2, 0.2, 0.2), Eigen::Vector3d(0, 0.004, 0.003)}) {
    const double T = SyncProfile::minimumDurationEuclidean(p0, Eigen::Vector3d::Zero(), p0 + d, 0.5, 13);
    EXPECT_NEAR(T, AxisProfile::minimumTime(0, 0, d.norm(), 0.5, 13), 1e-9) << d.transpose();
    const SyncProfile pr = SyncProfile::planEuclidean(0.0, p0, Eigen::Vector3d::Zero(), p0 + d, 0.5, 13);
    EXPECT_NEAR(pr.duration(), T, 1e-12);
    for (double f : {0.1, 0.37, 0.8}) {  // on the segment
      const Eigen::Vector3d q = pr.at(f * T).p - p0;
      EXPECT_LT((q - d * q.dot(d) / d.squaredNorm()).norm(), 1e-12);
    }
    expectWithinNormLimits(pr, 0.5, 13);
  }
  const Eigen::Vector3d diag(0.0, 0.4, 0.4);
  const double per_axis = SyncProfile::minimumDuration(p0, Eigen::Vector3d::Zero(), p0 + diag,
                                                       Eigen::Vector3d::Constant(0.5), Eigen::Vector3d::Constant(13));
  const double norm = SyncProfile::minimumDurationEuclidean(p0, Eigen::Vector3d::Zero(), p0 + diag, 0.5, 13);
  EXPECT_GT(norm, 1.3 * per_axis);  // 0.566 m at 0.5 m/s against 0.4 m per axis
}

// From random moving starts (|v0| up to the limit, including exactly at it), the Euclidean profile
// starts at the given state, ends at the goal at rest at its duration, and never exceeds the norms.
TEST(MotionProfile, EuclideanRandomProfilesRespectTheNormLimits) {
  core::Rng rng = core::makeRng(17);
  for (int k = 0; k < 150; ++k) {
    Eigen::Vector3d p0, v0, pf;
    for (int i = 0; i < 3; ++i) {
      p0(i) = core::uniform(rng, -0.4, 0.4);
      pf(i) = core::uniform(rng, -0.4, 0.4);
      v0(i) = core::uniform(rng, -1, 1);
    }
    if (k % 5 == 0) pf = p0;  // already there, moving
    v0 *= (k % 3 == 0 ? 0.5 : core::uniform(rng, 0.0, 0.5)) / v0.norm();  // every third exactly at |v| = V
    const double t0 = core::uniform(rng, 0, 2);
    const SyncProfile pr = SyncProfile::planEuclidean(t0, p0, v0, pf, 0.5, 13);
    EXPECT_LT((pr.at(t0).p - p0).norm(), 1e-12);
    EXPECT_LT((pr.at(t0).v - v0).norm(), 1e-9);
    const auto end = pr.at(pr.arrivalTime());
    EXPECT_LT((end.p - pf).norm(), 1e-9);  // t0 + T - t0 may round below T: the last phase's end
    EXPECT_LT(end.v.norm(), 1e-9);
    const auto after = pr.at(pr.arrivalTime() + 1e-6);  // then exactly at the goal, at rest
    EXPECT_EQ((after.p - pf).norm(), 0.0);
    EXPECT_EQ(after.v.norm(), 0.0);
    EXPECT_LT((pr.at(pr.arrivalTime() - 1e-9).p - pf).norm(), 1e-6);  // continuous at the arrival
    EXPECT_NEAR(pr.duration(), SyncProfile::minimumDurationEuclidean(p0, v0, pf, 0.5, 13), 1e-12);
    // Never faster than the per-axis family (which is allowed up to √3 V along a diagonal).
    EXPECT_GE(pr.duration() + 1e-9, SyncProfile::minimumDuration(p0, v0, pf, Eigen::Vector3d::Constant(0.5),
                                                                  Eigen::Vector3d::Constant(13)));
    expectWithinNormLimits(pr, 0.5, 13);
  }
}

// Replanning every 20 ms to a new goal from the current commanded state (as the catch planner
// does): no position jump, no velocity step above a_max dt, never above the norms.
TEST(MotionProfile, EuclideanReplanningIsContinuousAndWithinTheNorms) {
  core::Rng rng = core::makeRng(5);
  SyncProfile pr = SyncProfile::planEuclidean(0, Eigen::Vector3d::Zero(), Eigen::Vector3d::Zero(),
                                              Eigen::Vector3d(0, 0.3, -0.2), 0.5, 13);
  const double dt = 1e-3;
  auto prev = pr.at(0);
  for (int step = 1; step < 1500; ++step) {
    const double t = step * dt;
    if (step % 20 == 0) {
      const auto s = pr.at(t);
      pr = SyncProfile::planEuclidean(
          t, s.p, s.v, Eigen::Vector3d(0, core::uniform(rng, -0.3, 0.3), core::uniform(rng, -0.3, 0.3)), 0.5, 13);
    }
    const auto s = pr.at(t);
    ASSERT_LE(s.v.norm(), 0.5 * (1 + 1e-9)) << "t " << t;
    ASSERT_LE((s.v - prev.v).norm(), 13 * dt * (1 + 1e-6)) << "velocity step at t " << t;
    ASSERT_LE((s.p - prev.p).norm(), 0.5 * dt * (1 + 1e-6)) << "position jump at t " << t;
    prev = s;
  }
}

// A turn at full speed (the catch planner re-plans while the box already moves towards an earlier
// prediction): the velocity chord turns with the full acceleration, so it arrives sooner than
// stopping first and then taking the straight line, and stays within the norms.
TEST(MotionProfile, EuclideanTurnAtFullSpeedBeatsStoppingFirst) {
  const double V = 0.5, A = 13.0;
  const Eigen::Vector3d p0(4.0, 0.0, 1.1), v0(0.0, V, 0.0);
  for (const Eigen::Vector3d& d : {Eigen::Vector3d(0, 0, 0.3), Eigen::Vector3d(0, -0.1, 0.25), Eigen::Vector3d(0, 0.1, 0.1)}) {
    const Eigen::Vector3d pf = p0 + d;
    const SyncProfile pr = SyncProfile::planEuclidean(0.0, p0, v0, pf, V, A);
    const Eigen::Vector3d stop = p0 + v0 * (V / (2.0 * A));  // braking at A along -v0
    const double stop_then_go = V / A + AxisProfile::minimumTime(0, 0, (pf - stop).norm(), V, A);
    EXPECT_LT(pr.duration(), stop_then_go - 0.01) << d.transpose();
    EXPECT_LT((pr.at(pr.arrivalTime()).p - pf).norm(), 1e-9);
    EXPECT_LT((pr.at(0.0).v - v0).norm(), 1e-12);
    expectWithinNormLimits(pr, V, A);
  }
}

namespace {

// The Euclidean minimum time as the plain nested bisection computes it (every weight bisected to
// its end at every arrival time the outer bisection tries), kept here as the reference of the
// library's faster search, which must give the same double.
namespace reference {

double profileDistance(double v0, double vc, double a, double T) {
  const double t1 = std::abs(vc - v0) / a;
  const double t3 = std::abs(vc) / a;
  const double tc = std::max(0.0, T - t1 - t3);
  return 0.5 * (v0 + vc) * t1 + vc * tc + 0.5 * vc * t3;
}

bool axisFeasible(double v0, double D, double v_max, double a, double T) {
  if (T < std::abs(v0) / a - 1e-12) return false;
  const double lo = std::max(-v_max, 0.5 * (v0 - a * T));
  const double hi = std::min(v_max, 0.5 * (v0 + a * T));
  if (!(lo <= hi)) return false;
  const double tol = 1e-12 * (1.0 + std::abs(D));
  return D >= profileDistance(v0, lo, a, T) - tol && D <= profileDistance(v0, hi, a, T) + tol;
}

double euclideanMinimumTime(const Eigen::Vector3d& p0, const Eigen::Vector3d& v0_in, const Eigen::Vector3d& pf,
                            double V, double A) {
  Eigen::Vector3d v0 = v0_in;
  if (v0.norm() > V) v0 *= V / v0.norm();
  const Eigen::Vector3d D = pf - p0;
  const double dist = D.norm();
  Eigen::Vector3d e1 = Eigen::Vector3d::UnitX();
  if (dist > 0.0) e1 = D / dist;
  else if (v0.norm() > 0.0) e1 = v0.normalized();
  double d[2] = {dist, 0.0}, v[2] = {v0.dot(e1), 0.0}, lo[2];
  const Eigen::Vector3d across = v0 - v[0] * e1;
  if (across.norm() > 1e-12 * V) v[1] = across.norm();
  lo[0] = std::abs(v[0]) / V;
  lo[1] = v[1] / V;
  const double l = std::hypot(lo[0], lo[1]);
  if (l > 1.0) {
    lo[0] /= l;
    lo[1] /= l;
  }
  auto idle = [&](int k) { return d[k] == 0.0 && v[k] == 0.0; };
  auto weightFor = [&](int k, double T) {
    if (idle(k)) return 0.0;
    auto ok = [&](double w) { return w > 0.0 && axisFeasible(v[k], d[k], V * w, A * w, T); };
    if (!ok(1.0)) return std::numeric_limits<double>::infinity();
    if (ok(lo[k])) return lo[k];
    double a = lo[k], b = 1.0;
    for (int it = 0; it < 60 && b - a > 1e-14; ++it) {
      const double m = 0.5 * (a + b);
      if (ok(m)) b = m;
      else a = m;
    }
    return b;
  };
  auto feasible = [&](double T) {
    const double w0 = weightFor(0, T), w1 = weightFor(1, T);
    return std::isfinite(w0) && std::isfinite(w1) && w0 * w0 + w1 * w1 <= 1.0 + 1e-12;
  };
  if (idle(0) && idle(1)) return 0.0;
  double lo_t = 0.0, hi_t = 1e-3;
  while (!feasible(hi_t)) {
    lo_t = hi_t;
    hi_t *= 2.0;
  }
  for (int it = 0; it < 200 && hi_t - lo_t > 1e-13 * (1.0 + hi_t); ++it) {
    const double mid = 0.5 * (lo_t + hi_t);
    if (feasible(mid)) hi_t = mid;
    else lo_t = mid;
  }
  return hi_t;
}

}  // namespace reference

}  // namespace

// The search that decides each arrival time from the weights' bounds returns the same double as
// the nested bisection: planEuclidean's duration is the reference's, bit for bit, unless the
// velocity chord (not changed) is faster.
TEST(MotionProfile, EuclideanMinimumTimeEqualsTheNestedBisection) {
  core::Rng rng = core::makeRng(23);
  int compared = 0;
  for (int k = 0; k < 400; ++k) {
    Eigen::Vector3d p0, v0, pf;
    for (int i = 0; i < 3; ++i) {
      p0(i) = core::uniform(rng, -0.4, 0.4);
      pf(i) = core::uniform(rng, -0.4, 0.4);
      v0(i) = core::uniform(rng, -1, 1);
    }
    if (k % 7 == 0) pf = p0;
    if (k % 11 == 0) v0.setZero();
    else v0 *= (k % 3 == 0 ? 0.5 : core::uniform(rng, 0.0, 0.6)) / v0.norm();  // some above V (clamped)
    const double a_max = k % 2 == 0 ? 13.0 : 0.6;  // the chord needs a goal beyond V²/2A: rarer at 0.6
    const double ref = reference::euclideanMinimumTime(p0, v0, pf, 0.5, a_max);
    const double T = SyncProfile::minimumDurationEuclidean(p0, v0, pf, 0.5, a_max);
    const SyncProfile pr = SyncProfile::planEuclidean(0.0, p0, v0, pf, 0.5, a_max);
    if (T < ref) continue;  // the chord is faster: not the bisection's answer
    ++compared;
    EXPECT_EQ(T, ref) << "case " << k;
    EXPECT_EQ(pr.duration(), ref) << "case " << k;
  }
  EXPECT_GT(compared, 150);
}
