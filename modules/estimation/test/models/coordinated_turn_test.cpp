#include <gtest/gtest.h>

#include <cmath>

#include "viewline/core/frames.h"
#include "viewline/core/random.h"
#include "viewline/core/statistics.h"
#include "viewline/estimation/kalman_filter.h"
#include "viewline/estimation/models/coordinated_turn.h"
#include "viewline/estimation/nonlinear.h"

namespace viewline::estimation {
namespace {

using models::CoordinatedTurnParams;

Eigen::VectorXd stdNormal(core::Rng& rng, int n) {
  Eigen::VectorXd v(n);
  for (int i = 0; i < n; ++i) v(i) = core::gaussian(rng, 1.0);
  return v;
}

TEST(CoordinatedTurn, AnalyticJacobianMatchesCentralDifference) {
  for (const double w : {0.7, -1.3, 1e-7, 0.0, 3.0}) {
    Eigen::VectorXd x(5);
    x << 0.2, -0.1, 0.15, -0.08, w;
    for (const double dt : {1.0 / 30.0, 0.5}) {
      const Eigen::MatrixXd F = models::coordinatedTurnJacobian(x, dt);
      const Eigen::MatrixXd Fn = numericalJacobian([dt](const Eigen::VectorXd& v) { return models::coordinatedTurnStep(v, dt); }, x);
      EXPECT_LT((F - Fn).cwiseAbs().maxCoeff(), 1e-6) << "w = " << w << " dt = " << dt << "\n" << F << "\n" << Fn;
    }
  }
}

TEST(CoordinatedTurn, StaysOnTheCircleAndReducesToConstantVelocity) {
  // A circle of radius r at speed v: omega = v / r; after a full period the state returns.
  const double r = 0.3, v = 0.15, w = v / r, period = 2.0 * core::kPi / w;
  Eigen::VectorXd x(5);
  x << r, 0.0, 0.0, v, w;  // centre at the origin, moving counter-clockwise
  Eigen::VectorXd y = x;
  const int n = 377;
  for (int i = 0; i < n; ++i) {
    y = models::coordinatedTurnStep(y, period / n);
    EXPECT_NEAR(y.head<2>().norm(), r, 1e-9);
    EXPECT_NEAR(y.segment<2>(2).norm(), v, 1e-12);
  }
  EXPECT_LT((y - x).norm(), 1e-9);
  Eigen::VectorXd s(5);
  s << 1.0, 2.0, 0.3, -0.4, 0.0;
  const Eigen::VectorXd c = models::coordinatedTurnStep(s, 2.0);
  EXPECT_NEAR(c(0), 1.6, 1e-12);
  EXPECT_NEAR(c(1), 1.2, 1e-12);
}

TEST(CoordinatedTurn, EkfIsConsistentOnSimulatedTurns) {
  // Monte Carlo NEES: truth simulated with the same model and noise (discrete Q), EKF from the
  // true prior; the time-averaged NEES over the runs must sit in the two-sided 99 % band.
  CoordinatedTurnParams p;
  p.q_accel = 1e-3;
  p.q_omega = 1e-3;
  const double dt = 1.0 / 30.0, sigma = 0.01;
  const int runs = 50, steps = 150;
  core::Rng rng = core::makeRng(42);
  double nees_sum = 0.0;
  int count = 0;
  for (int r = 0; r < runs; ++r) {
    Eigen::VectorXd truth(5);
    truth << 0.0, 0.0, 0.15, 0.0, 0.5;
    Eigen::MatrixXd P0 = Eigen::VectorXd((Eigen::VectorXd(5) << 1e-4, 1e-4, 1e-3, 1e-3, 1e-2).finished()).asDiagonal();
    Eigen::VectorXd x0 = truth;
    const Eigen::LLT<Eigen::MatrixXd> l0(P0);
    x0 += l0.matrixL() * stdNormal(rng, 5);
    StateEstimate s(x0, P0, 0.0);
    const Eigen::MatrixXd Q = models::coordinatedTurnNoise(p, dt);
    const Eigen::LLT<Eigen::MatrixXd> lq(Q);
    for (int k = 0; k < steps; ++k) {
      truth = models::coordinatedTurnStep(truth, dt) + Eigen::MatrixXd(lq.matrixL()) * stdNormal(rng, 5);
      ekfPredict(s, models::coordinatedTurnTransition(p, dt));
      LinearMeasurement m;
      m.C = Eigen::MatrixXd::Zero(2, 5);
      m.C(0, 0) = m.C(1, 1) = 1.0;
      m.R = sigma * sigma * Eigen::MatrixXd::Identity(2, 2);
      m.y = truth.head<2>() + sigma * stdNormal(rng, 2);
      update(s, m);
      const Eigen::VectorXd e = s.x() - truth;
      nees_sum += e.dot(s.P().ldlt().solve(e));
      ++count;
    }
  }
  const double dof = 5.0 * count;
  const double lo = core::chiSquareQuantile(dof, 0.005) / count, hi = core::chiSquareQuantile(dof, 0.995) / count;
  const double mean_nees = nees_sum / count;
  // Samples within a run are correlated, so the band is only indicative; allow 15 % around it.
  EXPECT_GT(mean_nees, 0.85 * lo);
  EXPECT_LT(mean_nees, 1.15 * hi);
}

}  // namespace
}  // namespace viewline::estimation
