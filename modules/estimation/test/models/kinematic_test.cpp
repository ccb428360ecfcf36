// Constant velocity, constant acceleration (Wiener) and Singer models.
#include <gtest/gtest.h>

#include <cmath>
#include <limits>
#include <string>

#include "monte_carlo.h"
#include "viewline/core/error.h"
#include "viewline/estimation/discretization.h"
#include "viewline/estimation/models/constant_acceleration.h"
#include "viewline/estimation/models/constant_velocity.h"
#include "viewline/estimation/models/position_measurement.h"
#include "viewline/estimation/models/singer.h"

using namespace viewline;
using namespace viewline::estimation;
using test::expectConsistent;
using test::expectInvalid;
using test::expectOverconfident;

namespace {

const double kNaN = std::numeric_limits<double>::quiet_NaN();

double maxAbs(const Eigen::MatrixXd& m) { return m.cwiseAbs().maxCoeff(); }

// Continuous chain of `order` integrators per axis (block layout), white noise on the last.
ContinuousLinearModel integratorChain(int order, int dim, double q) {
  const int n = order * dim;
  ContinuousLinearModel m;
  m.A = Eigen::MatrixXd::Zero(n, n);
  for (int b = 0; b + 1 < order; ++b) m.A.block(b * dim, (b + 1) * dim, dim, dim).setIdentity();
  m.G = Eigen::MatrixXd::Zero(n, dim);
  m.G.bottomRows(dim).setIdentity();
  m.Qc = q * Eigen::MatrixXd::Identity(dim, dim);
  return m;
}

test::LinearMcSetup positionSetup(Eigen::Index n, int dim, double sigma, const std::function<LinearTransition(int)>& tr) {
  test::LinearMcSetup setup;
  setup.transition = tr;
  setup.measurement = [n, dim, sigma] { return positionMeasurement(n, Eigen::VectorXd::Zero(dim), sigma); };
  return setup;
}

}  // namespace

// ---------------------------------------------------------------- closed forms

TEST(ConstantVelocityModel, ClosedFormMatchesVanLoan) {
  for (int dim = 1; dim <= 3; ++dim) {
    const ConstantVelocityModel model{dim, 2.5};
    for (double dt : {0.001, 0.037, 0.5, 3.0}) {
      const LinearTransition a = model.transition(dt);
      const LinearTransition b = discretize(integratorChain(2, dim, 2.5), dt);
      ASSERT_EQ(a.Phi.rows(), 2 * dim);
      EXPECT_LT(maxAbs(a.Phi - b.Phi), 1e-12);
      EXPECT_LT(maxAbs(a.Q - b.Q), 1e-10 * std::max(1.0, maxAbs(b.Q)));
      EXPECT_EQ(a.dt, dt);
    }
  }
  // [T] eq 7 entries in 2-D: position variance q dt³/3, cross q dt²/2, velocity q dt.
  const LinearTransition t = ConstantVelocityModel{2, 4.0}.transition(0.1);
  EXPECT_NEAR(t.Q(0, 0), 4.0 * 1e-3 / 3.0, 1e-15);
  EXPECT_NEAR(t.Q(1, 3), 4.0 * 1e-2 / 2.0, 1e-15);
  EXPECT_NEAR(t.Q(2, 2), 0.4, 1e-15);
  EXPECT_EQ(t.Q(0, 1), 0.0);  // axes independent
  EXPECT_NEAR(t.Phi(1, 3), 0.1, 1e-15);
}

TEST(ConstantAccelerationModel, ClosedFormMatchesVanLoan) {
  for (int dim = 1; dim <= 3; ++dim) {
    const ConstantAccelerationModel model{dim, 0.7};
    for (double dt : {0.002, 0.05, 1.3}) {
      const LinearTransition a = model.transition(dt);
      const LinearTransition b = discretize(integratorChain(3, dim, 0.7), dt);
      EXPECT_LT(maxAbs(a.Phi - b.Phi), 1e-12);
      EXPECT_LT(maxAbs(a.Q - b.Q), 1e-10 * std::max(1.0, maxAbs(b.Q)));
    }
  }
}

TEST(SingerModel, MatchesVanLoanAndClosedFormPhi) {
  const double tau = 1.7, sm = 2.0, dt = 0.3, alpha = 1.0 / tau;
  const SingerModel model{2, tau, sm};
  const LinearTransition a = model.transition(dt);
  ContinuousLinearModel c = integratorChain(3, 2, 2.0 * alpha * sm * sm);
  c.A.bottomRightCorner(2, 2) = -alpha * Eigen::MatrixXd::Identity(2, 2);
  const LinearTransition b = discretize(c, dt);
  EXPECT_LT(maxAbs(a.Phi - b.Phi), 1e-12);
  EXPECT_LT(maxAbs(a.Q - b.Q), 1e-11);
  // Singer's closed-form Φ entries (x axis: indices 0, 2, 4).
  const double e = std::exp(-alpha * dt);
  EXPECT_NEAR(a.Phi(0, 4), (alpha * dt - 1.0 + e) / (alpha * alpha), 1e-13);
  EXPECT_NEAR(a.Phi(2, 4), (1.0 - e) / alpha, 1e-13);
  EXPECT_NEAR(a.Phi(4, 4), e, 1e-15);
  // Singer's closed-form q33 and q23 (× 2 α σm²).
  const double qc = 2.0 * alpha * sm * sm;
  EXPECT_NEAR(a.Q(4, 4), qc / (2.0 * alpha) * (1.0 - e * e), 1e-12);
  EXPECT_NEAR(a.Q(2, 4), qc / (2.0 * alpha * alpha) * (e * e + 1.0 - 2.0 * e), 1e-12);
  // Long steps: the acceleration variance reaches its stationary value σm².
  EXPECT_NEAR(model.transition(50.0 * tau).Q(4, 4), sm * sm, 1e-9);
}

TEST(SingerModel, LongTimeConstantApproachesConstantAcceleration) {
  const double q = 0.8, dt = 0.2;
  const ConstantAccelerationModel ca{3, q};
  for (double tau : {1e3, 1e5}) {
    const SingerModel singer{3, tau, std::sqrt(q * tau / 2.0)};  // 2 α σm² = q
    const LinearTransition a = singer.transition(dt), b = ca.transition(dt);
    const double err_phi = maxAbs(a.Phi - b.Phi), err_q = maxAbs(a.Q - b.Q) / maxAbs(b.Q);
    EXPECT_LT(err_phi, 1.01 * dt / tau);  // Φ_aa = e^{−dt/τ} = 1 − dt/τ + ...
    EXPECT_LT(err_q, 2.0 * dt / tau);
  }
}

TEST(SingerModel, ShortTimeConstantApproachesConstantVelocity) {
  const double q = 1.5, dt = 0.1;
  const LinearTransition cv = ConstantVelocityModel{2, q}.transition(dt);
  std::vector<Eigen::Index> pv = {0, 1, 2, 3};  // position and velocity blocks of (p, v, a) in 2-D
  double prev = std::numeric_limits<double>::infinity();
  for (double tau : {1e-2, 1e-3, 1e-5}) {
    const SingerModel singer{2, tau, std::sqrt(q / (2.0 * tau))};  // acceleration white, density q
    const LinearTransition a = singer.transition(dt);
    ASSERT_TRUE(a.Q.allFinite());
    const Eigen::MatrixXd Qpv = a.Q.topLeftCorner(4, 4);
    const double err = maxAbs(Qpv - cv.Q) / maxAbs(cv.Q);
    EXPECT_LT(err, 5.0 * tau / dt) << "tau " << tau;
    EXPECT_LT(err, prev);
    prev = err;
    EXPECT_LT(maxAbs(a.Phi.topLeftCorner(4, 4) - cv.Phi), 1e-12);
  }
}

TEST(PositionMeasurement, SelectsThePositionBlock) {
  const LinearMeasurement m = positionMeasurement(9, Eigen::Vector3d(1, 2, 3), 0.5);
  ASSERT_EQ(m.C.rows(), 3);
  ASSERT_EQ(m.C.cols(), 9);
  EXPECT_EQ(m.C.leftCols(3), Eigen::MatrixXd::Identity(3, 3));
  EXPECT_EQ(m.C.rightCols(6), Eigen::MatrixXd::Zero(3, 6));
  EXPECT_EQ(m.R, 0.25 * Eigen::MatrixXd::Identity(3, 3));
  expectInvalid([] { positionMeasurement(2, Eigen::Vector3d(1, 2, 3), 0.5); }, "y has 3 entries");
  expectInvalid([] { positionMeasurement(6, Eigen::Vector3d(1, kNaN, 3), 0.5); }, "y");
  expectInvalid([] { positionMeasurement(6, Eigen::Vector3d(1, 2, 3), 0.0); }, "sigma");
}

TEST(KinematicModels, BadInputNamesTheField) {
  expectInvalid([] { ConstantVelocityModel{2, 1.0}.transition(0.0); }, "dt");
  expectInvalid([] { ConstantVelocityModel{2, 1.0}.transition(-0.1); }, "dt");
  expectInvalid([] { ConstantVelocityModel{2, 1.0}.transition(kNaN); }, "dt");
  expectInvalid([] { ConstantVelocityModel{2, kNaN}.transition(0.1); }, "ConstantVelocityModel.q");
  expectInvalid([] { ConstantVelocityModel{2, -1.0}.transition(0.1); }, "ConstantVelocityModel.q");
  expectInvalid([] { ConstantVelocityModel{4, 1.0}.transition(0.1); }, "ConstantVelocityModel.dim");
  expectInvalid([] { ConstantAccelerationModel{3, kNaN}.transition(0.1); }, "ConstantAccelerationModel.q");
  expectInvalid([] { ConstantAccelerationModel{3, 1.0}.transition(0.0); }, "dt");
  expectInvalid([] { ConstantAccelerationModel{0, 1.0}.transition(0.1); }, "ConstantAccelerationModel.dim");
  expectInvalid([] { SingerModel{3, 0.0, 1.0}.transition(0.1); }, "SingerModel.tau");
  expectInvalid([] { SingerModel{3, kNaN, 1.0}.transition(0.1); }, "SingerModel.tau");
  expectInvalid([] { SingerModel{3, 1.0, kNaN}.transition(0.1); }, "SingerModel.sigma_m");
  expectInvalid([] { SingerModel{3, 1.0, 1.0}.transition(-1.0); }, "dt");
}

// ---------------------------------------------------------------- Monte Carlo

namespace {

test::LinearMcSetup cvSetup(int dim) {
  const ConstantVelocityModel model{dim, 1.0};
  const Eigen::Index n = model.stateDim();
  test::LinearMcSetup s = positionSetup(n, dim, 0.1, [model](int) { return model.transition(0.1); });
  s.m0 = Eigen::VectorXd::Zero(n);
  s.m0.tail(dim).setConstant(2.0);
  s.P0 = Eigen::MatrixXd::Identity(n, n);
  s.P0.topLeftCorner(dim, dim) *= 0.3 * 0.3;
  s.steps = 40;
  s.runs = 400;
  s.seed = 100 + static_cast<std::uint64_t>(dim);
  return s;
}

test::LinearMcSetup caSetup() {
  const ConstantAccelerationModel model{3, 2.0};
  test::LinearMcSetup s = positionSetup(9, 3, 0.05, [model](int) { return model.transition(0.1); });
  s.m0 = Eigen::VectorXd::Zero(9);
  s.P0 = Eigen::VectorXd((Eigen::VectorXd(9) << 0.01, 0.01, 0.01, 1, 1, 1, 4, 4, 4).finished()).asDiagonal();
  s.steps = 40;
  s.runs = 400;
  s.seed = 200;
  return s;
}

test::LinearMcSetup singerSetup() {
  const SingerModel model{2, 2.0, 3.0};
  test::LinearMcSetup s = positionSetup(6, 2, 0.1, [model](int) { return model.transition(0.1); });
  s.m0 = Eigen::VectorXd::Zero(6);
  // Acceleration prior at its stationary variance σm².
  s.P0 = Eigen::VectorXd((Eigen::VectorXd(6) << 0.04, 0.04, 1, 1, 9, 9).finished()).asDiagonal();
  s.steps = 50;
  s.runs = 400;
  s.seed = 300;
  return s;
}

}  // namespace

TEST(ConstantVelocityModel, MonteCarloNeesConsistent2D) { expectConsistent(test::runLinearMc(cvSetup(2), 1.0)); }
TEST(ConstantVelocityModel, MonteCarloNeesConsistent3D) { expectConsistent(test::runLinearMc(cvSetup(3), 1.0)); }
TEST(ConstantVelocityModel, TooSmallProcessNoiseDetected2D) { expectOverconfident(test::runLinearMc(cvSetup(2), 0.1)); }
TEST(ConstantVelocityModel, TooSmallProcessNoiseDetected3D) { expectOverconfident(test::runLinearMc(cvSetup(3), 0.1)); }
TEST(ConstantAccelerationModel, MonteCarloNeesConsistent) { expectConsistent(test::runLinearMc(caSetup(), 1.0)); }
TEST(ConstantAccelerationModel, TooSmallProcessNoiseDetected) { expectOverconfident(test::runLinearMc(caSetup(), 0.1)); }
TEST(SingerModel, MonteCarloNeesConsistent) { expectConsistent(test::runLinearMc(singerSetup(), 1.0)); }
TEST(SingerModel, TooSmallProcessNoiseDetected) { expectOverconfident(test::runLinearMc(singerSetup(), 0.1)); }
