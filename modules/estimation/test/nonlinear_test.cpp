#include <gtest/gtest.h>

#include <cmath>

#include "viewline/core/random.h"
#include "viewline/estimation/consistency.h"
#include "viewline/estimation/nonlinear.h"

using namespace viewline;
using namespace viewline::estimation;

namespace {
// Range and bearing of a 2-D position state (x, y, vx, vy) from the origin.
Eigen::VectorXd rangeBearing(const Eigen::VectorXd& x) {
  return Eigen::Vector2d(std::hypot(x[0], x[1]), std::atan2(x[1], x[0]));
}
Eigen::MatrixXd rangeBearingJacobian(const Eigen::VectorXd& x) {
  const double r2 = x[0] * x[0] + x[1] * x[1], r = std::sqrt(r2);
  Eigen::MatrixXd H = Eigen::MatrixXd::Zero(2, 4);
  H << x[0] / r, x[1] / r, 0, 0, -x[1] / r2, x[0] / r2, 0, 0;
  return H;
}
Eigen::VectorXd wrapResidual(const Eigen::VectorXd& a, const Eigen::VectorXd& b) {
  Eigen::VectorXd d = a - b;
  d[1] = std::remainder(d[1], 2.0 * M_PI);
  return d;
}
}  // namespace

TEST(Nonlinear, AnalyticJacobianMatchesNumerical) {
  const Eigen::Vector4d x(3.0, -1.0, 0.5, 0.2);
  const Eigen::MatrixXd num = numericalJacobian(rangeBearing, x);
  EXPECT_LT((num - rangeBearingJacobian(x)).norm(), 1e-8);
}

TEST(Nonlinear, UkfEqualsKalmanOnLinearModels) {
  core::Rng rng = core::makeRng(9);
  Eigen::MatrixXd F = Eigen::MatrixXd::Identity(4, 4);
  F(0, 2) = F(1, 3) = 0.1;
  const Eigen::MatrixXd Q = 0.01 * Eigen::MatrixXd::Identity(4, 4);
  Eigen::MatrixXd H = Eigen::MatrixXd::Zero(2, 4);
  H(0, 0) = 1.0;
  H(1, 1) = 1.0;
  StateEstimate a(Eigen::Vector4d(1, 2, 3, 4), Eigen::MatrixXd::Identity(4, 4)), b = a, c = a;
  NonlinearTransition tr{[&](const Eigen::VectorXd& x) { return Eigen::VectorXd(F * x); },
                         [&](const Eigen::VectorXd&) { return F; }, Q, 0.1, nullptr};
  for (int k = 0; k < 5; ++k) {
    NonlinearMeasurement m{[&](const Eigen::VectorXd& x) { return Eigen::VectorXd(H * x); },
                           [&](const Eigen::VectorXd&) { return H; },
                           Eigen::Vector2d(core::gaussian(rng), core::gaussian(rng)),
                           0.2 * Eigen::MatrixXd::Identity(2, 2), nullptr};
    predict(a, LinearTransition{F, Eigen::MatrixXd(), Eigen::VectorXd(), Q, 0.1});
    update(a, LinearMeasurement{H, m.y, m.R});
    ekfPredict(b, tr);
    ekfUpdate(b, m);
    ukfPredict(c, tr);
    ukfUpdate(c, m);
  }
  EXPECT_LT((a.x() - b.x()).norm(), 1e-10);
  EXPECT_LT((a.x() - c.x()).norm(), 1e-10);
  EXPECT_LT((a.P() - c.P()).norm(), 1e-10);
  EXPECT_NEAR(a.t(), 0.5, 1e-12);
}

namespace {
struct RangeBearingResult {
  ConsistencyStats ekf, ukf;
};
// Static target seen by a range-bearing sensor; Monte-Carlo runs, position NEES after 10 updates.
RangeBearingResult rangeBearingMonteCarlo(double prior_var, int runs, std::uint64_t seed) {
  RangeBearingResult out;
  core::Rng rng = core::makeRng(seed);
  const Eigen::MatrixXd R = Eigen::Vector2d(0.05 * 0.05, 0.01 * 0.01).asDiagonal();
  const Eigen::MatrixXd P0 = Eigen::Vector4d(prior_var, prior_var, 0.01, 0.01).asDiagonal();
  NonlinearTransition tr{[](const Eigen::VectorXd& x) { return x; },
                         [](const Eigen::VectorXd&) { return Eigen::MatrixXd(Eigen::MatrixXd::Identity(4, 4)); },
                         1e-8 * Eigen::MatrixXd::Identity(4, 4), 0.1, nullptr};
  for (int r = 0; r < runs; ++r) {
    const Eigen::VectorXd truth = core::sampleGaussian(rng, Eigen::Vector4d(5, 3, 0, 0), P0);
    StateEstimate e(Eigen::Vector4d(5, 3, 0, 0), P0), u = e;
    for (int k = 0; k < 10; ++k) {
      NonlinearMeasurement m{rangeBearing, rangeBearingJacobian,
                             rangeBearing(truth) + core::sampleGaussian(rng, Eigen::Vector2d::Zero(), R), R,
                             wrapResidual};
      ekfPredict(e, tr);
      ekfUpdate(e, m);
      ukfPredict(u, tr);
      ukfUpdate(u, m);
    }
    out.ekf.add(nees(e, truth, {0, 1}), 2);
    out.ukf.add(nees(u, truth, {0, 1}), 2);
  }
  return out;
}
}  // namespace

TEST(Nonlinear, RangeBearingEkfAndUkfAreConsistent) {
  // Mild nonlinearity (prior std 0.1 m at 6 m range): both filters consistent.
  const RangeBearingResult r = rangeBearingMonteCarlo(0.01, 300, 10);
  EXPECT_TRUE(r.ekf.consistent()) << r.ekf.mean() << " band " << r.ekf.bounds().lo << ".." << r.ekf.bounds().hi;
  EXPECT_TRUE(r.ukf.consistent()) << r.ukf.mean() << " band " << r.ukf.bounds().lo << ".." << r.ukf.bounds().hi;
}

TEST(Nonlinear, UkfStaysConsistentWithBroadPrior) {
  // Prior std 0.55 m: the EKF's first linearisation makes it slightly overconfident (a known
  // EKF property); the UKF's second-order accuracy keeps it inside the band.
  const RangeBearingResult r = rangeBearingMonteCarlo(0.3, 300, 10);
  EXPECT_TRUE(r.ukf.consistent()) << r.ukf.mean() << " band " << r.ukf.bounds().lo << ".." << r.ukf.bounds().hi;
  EXPECT_GE(r.ekf.mean(), r.ukf.mean());
}

TEST(Nonlinear, MissingFunctionsAreReported) {
  StateEstimate s(Eigen::Vector2d::Zero(), Eigen::Matrix2d::Identity());
  NonlinearTransition tr;
  tr.Q = Eigen::Matrix2d::Identity();
  EXPECT_THROW(ekfPredict(s, tr), core::InvalidInput);
  tr.f = [](const Eigen::VectorXd& x) { return x; };
  EXPECT_THROW(ekfPredict(s, tr), core::InvalidInput);  // no Jacobian
  EXPECT_NO_THROW(ukfPredict(s, tr));
}
