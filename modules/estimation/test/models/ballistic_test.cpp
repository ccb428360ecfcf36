// Ballistic models: without drag ([L] eqs 19-20) and with quadratic drag (EKF).
#include <gtest/gtest.h>

#include <cmath>
#include <cstdint>
#include <cstring>
#include <limits>

#include "monte_carlo.h"
#include "viewline/estimation/discretization.h"
#include "viewline/estimation/models/ballistic.h"
#include "viewline/estimation/models/ballistic_drag.h"
#include "viewline/estimation/models/constant_velocity.h"
#include "viewline/estimation/models/position_measurement.h"
#include "viewline/estimation/nonlinear.h"

using namespace viewline;
using namespace viewline::estimation;
using test::expectConsistent;
using test::expectInvalid;
using test::expectOverconfident;

namespace {
const double kNaN = std::numeric_limits<double>::quiet_NaN();
double maxAbs(const Eigen::MatrixXd& m) { return m.cwiseAbs().maxCoeff(); }
using Vec6 = Eigen::Matrix<double, 6, 1>;

// A tennis ball: ρ = 1.2 kg/m³, Cd = 0.55, r = 0.033 m, m = 0.057 kg (k ≈ 0.02 1/m).
double tennisK() { return DragBallisticModel::dragConstant(1.2, 0.55, M_PI * 0.033 * 0.033, 0.057); }
}  // namespace

// ---------------------------------------------------------------- no drag

TEST(BallisticModel, LinderothEquation20WithYUp) {
  BallisticModel model;
  model.up = Eigen::Vector3d::UnitY();
  model.g = 9.81;
  model.q = 0.3;
  const double h = 0.02;
  const LinearTransition tr = model.transition(h);
  Eigen::MatrixXd phi = Eigen::MatrixXd::Identity(6, 6);
  phi.topRightCorner(3, 3) = h * Eigen::Matrix3d::Identity();
  EXPECT_EQ(tr.Phi, phi);
  Vec6 gamma;
  gamma << 0.0, -9.81 * h * h / 2.0, 0.0, 0.0, -9.81 * h, 0.0;
  ASSERT_EQ(tr.Gamma.rows(), 6);
  ASSERT_EQ(tr.Gamma.cols(), 1);
  EXPECT_LT(maxAbs(tr.Gamma - gamma), 1e-15);
  ASSERT_EQ(tr.u.size(), 1);
  EXPECT_EQ(tr.u[0], 1.0);
  EXPECT_LT(maxAbs(tr.Q - ConstantVelocityModel{3, 0.3}.transition(h).Q), 1e-18);
  EXPECT_EQ(tr.dt, h);
}

TEST(BallisticModel, MatchesVanLoanForAnyUpAxisAndDt) {
  BallisticModel model;
  model.up = Eigen::Vector3d(0.3, -0.2, 0.9);  // normalised on use
  model.q = 2.0;
  ContinuousLinearModel c;
  c.A = Eigen::MatrixXd::Zero(6, 6);
  c.A.topRightCorner(3, 3).setIdentity();
  c.B = Eigen::MatrixXd::Zero(6, 1);
  c.B.bottomRows(3) = model.gravity();
  c.G = Eigen::MatrixXd::Zero(6, 3);
  c.G.bottomRows(3).setIdentity();
  c.Qc = 2.0 * Eigen::MatrixXd::Identity(3, 3);
  EXPECT_NEAR(model.gravity().norm(), 9.81, 1e-12);
  for (double dt : {0.004, 0.02, 0.7}) {
    const LinearTransition a = model.transition(dt), b = discretize(c, dt, Eigen::VectorXd::Ones(1));
    EXPECT_LT(maxAbs(a.Phi - b.Phi), 1e-12);
    EXPECT_LT(maxAbs(a.Gamma - b.Gamma), 1e-12);
    EXPECT_LT(maxAbs(a.Q - b.Q), 1e-10 * maxAbs(b.Q));
  }
}

TEST(BallisticModel, NoiseFreeStepsFollowTheParabolaWithIrregularDt) {
  const BallisticModel model;  // z up
  Vec6 x0;
  x0 << 1.0, -2.0, 1.5, 3.0, 0.5, 7.0;
  Eigen::VectorXd x = x0;
  double t = 0.0;
  for (double dt : {0.013, 0.02, 0.031, 0.007, 0.25}) {
    const LinearTransition tr = model.transition(dt);
    x = tr.Phi * x + tr.Gamma * tr.u;
    t += dt;
  }
  const Eigen::Vector3d g(0, 0, -9.81);
  const Eigen::Vector3d p = x0.head<3>() + x0.tail<3>() * t + 0.5 * g * t * t;
  const Eigen::Vector3d v = x0.tail<3>() + g * t;
  EXPECT_LT((x.head(3) - p).norm(), 1e-12);
  EXPECT_LT((x.tail(3) - v).norm(), 1e-12);
}

TEST(BallisticModel, BadInputNamesTheField) {
  expectInvalid([] { BallisticModel().transition(0.0); }, "dt");
  expectInvalid([] { BallisticModel().transition(-0.02); }, "dt");
  expectInvalid([] { BallisticModel().transition(kNaN); }, "dt");
  expectInvalid([] { BallisticModel m; m.g = kNaN; m.transition(0.02); }, "BallisticModel.g");
  expectInvalid([] { BallisticModel m; m.q = -1.0; m.transition(0.02); }, "BallisticModel.q");
  expectInvalid([] { BallisticModel m; m.up = Eigen::Vector3d::Zero(); m.transition(0.02); }, "BallisticModel.up");
  expectInvalid([] { BallisticModel m; m.up[1] = kNaN; m.transition(0.02); }, "BallisticModel.up");
}

namespace {
test::LinearMcSetup ballisticSetup() {
  BallisticModel model;
  model.q = 0.5;
  test::LinearMcSetup s;
  s.transition = [model](int) { return model.transition(0.02); };
  s.measurement = [] { return positionMeasurement(6, Eigen::Vector3d::Zero(), 0.01); };
  s.m0 = (Eigen::VectorXd(6) << 0, 0, 1, 5, 1, 6).finished();
  s.P0 = Eigen::VectorXd((Eigen::VectorXd(6) << 0.01, 0.01, 0.01, 1, 1, 1).finished()).asDiagonal();
  s.steps = 50;
  s.runs = 400;
  s.seed = 11;
  return s;
}
}  // namespace

TEST(BallisticModel, MonteCarloNeesConsistent) { expectConsistent(test::runLinearMc(ballisticSetup(), 1.0)); }
TEST(BallisticModel, TooSmallProcessNoiseDetected) { expectOverconfident(test::runLinearMc(ballisticSetup(), 0.1)); }

// ---------------------------------------------------------------- quadratic drag

TEST(DragBallisticModel, DragConstant) {
  EXPECT_NEAR(DragBallisticModel::dragConstant(1.2, 0.5, 0.01, 0.1), 1.2 * 0.5 * 0.01 / 0.2, 1e-15);
  EXPECT_NEAR(tennisK(), 0.0197, 5e-4);
  expectInvalid([] { DragBallisticModel::dragConstant(1.2, 0.5, 0.01, 0.0); }, "mass m");
  expectInvalid([] { DragBallisticModel::dragConstant(kNaN, 0.5, 0.01, 0.1); }, "air density rho");
  expectInvalid([] { DragBallisticModel::dragConstant(1.2, -0.5, 0.01, 0.1); }, "drag coefficient Cd");
}

TEST(DragBallisticModel, AnalyticJacobianMatchesNumerical) {
  DragBallisticModel model;
  model.k = 0.05;
  model.up = Eigen::Vector3d(0.1, 0.2, 1.0);
  for (const Vec6& x : {(Vec6() << 0, 0, 1, 12, -3, 9).finished(), (Vec6() << 1, 2, 3, -0.4, 0.1, -20).finished(),
                        (Vec6() << 0, 0, 0, 0.02, 0.0, -0.01).finished()}) {
    for (double dt : {0.01, 0.05, 0.2}) {
      const Eigen::MatrixXd F = model.jacobian(x, dt);
      const Eigen::MatrixXd Fn = numericalJacobian([&](const Eigen::VectorXd& z) { return model.propagate(z, dt); }, x, 1e-6);
      EXPECT_LT(maxAbs(F - Fn), 1e-7) << "x " << x.transpose() << " dt " << dt;
    }
    const Eigen::MatrixXd J = model.derivativeJacobian(x);
    const Eigen::MatrixXd Jn = numericalJacobian([&](const Eigen::VectorXd& z) { return Eigen::VectorXd(model.derivative(z)); }, x, 1e-7);
    EXPECT_LT(maxAbs(J - Jn), 1e-6);
  }
}

TEST(DragBallisticModel, ReducesToBallisticWithoutDragAndConvergesWithSubsteps) {
  DragBallisticModel nodrag;  // k = 0: RK4 is exact on the parabola
  Vec6 x;
  x << 0, 0, 1, 12, -3, 9;
  const LinearTransition lin = BallisticModel{Eigen::Vector3d::UnitZ(), 9.81, 1.0}.transition(0.3);
  EXPECT_LT((nodrag.propagate(x, 0.3) - (lin.Phi * x + lin.Gamma * lin.u)).norm(), 1e-12);
  EXPECT_LT(maxAbs(nodrag.jacobian(x, 0.3) - lin.Phi), 1e-14);
  EXPECT_LT(maxAbs(nodrag.processNoise(x, 0.3) - lin.Q), 1e-12);

  DragBallisticModel drag;
  drag.k = tennisK();
  DragBallisticModel fine = drag;
  fine.substeps = 2000;
  const double err = (drag.propagate(x, 0.02) - fine.propagate(x, 0.02)).norm();
  EXPECT_LT(err, 1e-10);  // RK4, 4 sub-steps of 5 ms
  // Drag slows the ball down with respect to the vacuum parabola.
  EXPECT_LT(drag.propagate(x, 0.5).tail(3).norm(), nodrag.propagate(x, 0.5).tail(3).norm());
}

TEST(DragBallisticModel, FallingBallReachesTerminalVelocity) {
  DragBallisticModel model;
  model.k = 0.1;  // terminal speed sqrt(g/k)
  Eigen::VectorXd x = Eigen::VectorXd::Zero(6);
  for (int i = 0; i < 100; ++i) x = model.propagate(x, 0.1);
  EXPECT_NEAR(x[5], -std::sqrt(9.81 / 0.1), 1e-6);
  EXPECT_NEAR(x[3], 0.0, 1e-15);
}

TEST(DragBallisticModel, BadInputNamesTheField) {
  const Eigen::VectorXd x = (Eigen::VectorXd(6) << 0, 0, 1, 12, -3, 9).finished();
  expectInvalid([&] { DragBallisticModel().propagate(x, 0.0); }, "dt");
  expectInvalid([&] { DragBallisticModel().transition(-1.0, x); }, "dt");
  expectInvalid([&] { DragBallisticModel m; m.k = kNaN; m.propagate(x, 0.02); }, "DragBallisticModel.k");
  expectInvalid([&] { DragBallisticModel m; m.q = kNaN; m.transition(0.02, x); }, "DragBallisticModel.q");
  expectInvalid([&] { DragBallisticModel m; m.substeps = 0; m.jacobian(x, 0.02); }, "DragBallisticModel.substeps");
  expectInvalid([&] { DragBallisticModel().transition(0.02, Eigen::VectorXd::Constant(6, kNaN)); }, "linearisation point");
  expectInvalid([&] { DragBallisticModel().propagate(Eigen::VectorXd::Zero(5), 0.02); }, "state x");
}

namespace {
// Truth: the continuous process integrated finely (RK4 on 10 sub-steps of each frame, each
// sub-step adding the exact white-acceleration noise increment of its length); the EKF uses
// RK4 over the frame and Q from the linearisation at its estimate.
ConsistencyStats dragMc(double q_scale) {
  DragBallisticModel model;
  model.k = tennisK();
  model.q = 0.5;
  DragBallisticModel fine = model;
  fine.substeps = 1;
  DragBallisticModel filter_model = model;
  filter_model.q = model.q * q_scale;
  const double dt = 0.02, sigma = 0.01;
  const int sub = 10, steps = 40, runs = 300;
  const double h = dt / sub;
  const test::NoiseSampler noise(ConstantVelocityModel{3, model.q}.transition(h).Q);
  const test::NoiseSampler meas(sigma * sigma * Eigen::MatrixXd::Identity(3, 3));
  const Eigen::VectorXd m0 = (Eigen::VectorXd(6) << 0, 0, 1, 15, 2, 8).finished();
  const Eigen::MatrixXd P0 = Eigen::VectorXd((Eigen::VectorXd(6) << 0.01, 0.01, 0.01, 1, 1, 1).finished()).asDiagonal();
  const test::NoiseSampler prior(P0);
  ConsistencyStats stats;
  for (int run = 0; run < runs; ++run) {
    core::Rng rng(core::deriveSeed(21, static_cast<std::uint64_t>(run)));
    Eigen::VectorXd x = m0 + prior(rng);
    StateEstimate s(m0, P0);
    for (int k = 0; k < steps; ++k) {
      for (int i = 0; i < sub; ++i) x = fine.propagate(x, h) + noise(rng);
      ekfPredict(s, filter_model.transition(dt, s.x()));
      NonlinearMeasurement m;
      m.h = [](const Eigen::VectorXd& z) { return Eigen::VectorXd(z.head(3)); };
      m.H = [](const Eigen::VectorXd&) {
        Eigen::MatrixXd H = Eigen::MatrixXd::Zero(3, 6);
        H.leftCols(3).setIdentity();
        return H;
      };
      m.y = x.head(3) + meas(rng);
      m.R = sigma * sigma * Eigen::MatrixXd::Identity(3, 3);
      ekfUpdate(s, m);
    }
    stats.add(nees(s, x), 6.0);
  }
  return stats;
}
}  // namespace

TEST(DragBallisticModel, MonteCarloNeesConsistent) { expectConsistent(dragMc(1.0)); }
TEST(DragBallisticModel, TooSmallProcessNoiseDetected) { expectOverconfident(dragMc(0.1)); }

// The planner's fixed-size Van Loan gives the dynamic path's bits (the scenario outputs depend on
// them), over the durations and speeds of crossing predictions (tau 0-1.5 s, |v| 0-15 m/s: the
// Padé degrees 3 to 13 and the scaling and squaring of the matrix exponential).
TEST(DragBallisticModel, FixedSizeProcessNoiseIsTheDynamicOne) {
  DragBallisticModel m;
  m.k = 0.02;
  m.q = 0.02;
  m.substeps = 2;
  std::uint64_t state = 7;
  auto uniform = [&](double lo, double hi) {  // a small LCG: the test needs no distribution
    state = state * 6364136223846793005ULL + 1442695040888963407ULL;
    return lo + (hi - lo) * static_cast<double>(state >> 11) / 9007199254740992.0;
  };
  for (int k = 0; k < 200; ++k) {
    Vec6 x;
    for (int i = 0; i < 3; ++i) x(i) = uniform(-2.0, 2.0);
    for (int i = 3; i < 6; ++i) x(i) = uniform(-9.0, 9.0);
    const double dt = k < 10 ? 0.001 * (k + 1) : uniform(0.01, 1.5);
    const Eigen::MatrixXd dyn = m.processNoise(Eigen::VectorXd(x), dt);
    const Eigen::Matrix<double, 6, 6> fix = m.processNoiseFixed(x, dt);
    ASSERT_TRUE(dyn.allFinite());
    for (int r = 0; r < 6; ++r)
      for (int c = 0; c < 6; ++c) ASSERT_EQ(fix(r, c), dyn(r, c)) << "case " << k << " (" << r << "," << c << ")";
  }
  EXPECT_THROW(m.processNoiseFixed(Vec6::Zero(), 0.0), core::InvalidInput);
  EXPECT_THROW(m.processNoiseFixed(Vec6::Constant(kNaN), 0.1), core::InvalidInput);
}

namespace {
// The variational RK4 step with the full products J(x) S (derivativeJacobian), as the one-pass
// propagation's reference.
Vec6 referenceStepWithJacobian(const DragBallisticModel& m, const Vec6& x0, double dt, Eigen::Matrix<double, 6, 6>& S) {
  using Mat6 = Eigen::Matrix<double, 6, 6>;
  Vec6 x = x0;
  S = Mat6::Identity();
  const double h = dt / m.substeps;
  for (int i = 0; i < m.substeps; ++i) {
    const Vec6 x1 = x;
    const Vec6 k1 = m.derivative(x1);
    const Mat6 d1 = m.derivativeJacobian(x1) * S;
    const Vec6 x2 = x + 0.5 * h * k1;
    const Mat6 S2 = S + 0.5 * h * d1;
    const Vec6 k2 = m.derivative(x2);
    const Mat6 d2 = m.derivativeJacobian(x2) * S2;
    const Vec6 x3 = x + 0.5 * h * k2;
    const Mat6 S3 = S + 0.5 * h * d2;
    const Vec6 k3 = m.derivative(x3);
    const Mat6 d3 = m.derivativeJacobian(x3) * S3;
    const Vec6 x4 = x + h * k3;
    const Mat6 S4 = S + h * d3;
    const Vec6 k4 = m.derivative(x4);
    const Mat6 d4 = m.derivativeJacobian(x4) * S4;
    x += h / 6.0 * (k1 + 2.0 * k2 + 2.0 * k3 + k4);
    S += h / 6.0 * (d1 + 2.0 * d2 + 2.0 * d3 + d4);
  }
  return x;
}

std::uint64_t bitsOf(double v) {
  std::uint64_t b = 0;
  std::memcpy(&b, &v, sizeof b);
  return b;
}
}  // namespace

// propagateWithJacobianFixed skips J's zero and unit products: the same bits as the full products
// (signed zeros included) and as propagateFixed / jacobianFixed, at rest and in flight.
TEST(DragBallisticModel, OnePassJacobianIsTheFullProducts) {
  DragBallisticModel m;
  m.k = 0.02;
  m.up = Eigen::Vector3d(0.1, 0.2, 1.0);
  std::uint64_t state = 11;
  auto uniform = [&](double lo, double hi) {
    state = state * 6364136223846793005ULL + 1442695040888963407ULL;
    return lo + (hi - lo) * static_cast<double>(state >> 11) / 9007199254740992.0;
  };
  for (int k = 0; k < 300; ++k) {
    m.substeps = 1 + k % 5;
    Vec6 x;
    for (int i = 0; i < 6; ++i) x(i) = k % 10 == 0 && i >= 3 ? 0.0 : uniform(-9.0, 9.0);  // some at rest
    const double dt = uniform(0.001, 1.0);
    Eigen::Matrix<double, 6, 6> S, S_ref;
    const Vec6 xe = m.propagateWithJacobianFixed(x, dt, S);
    const Vec6 x_ref = referenceStepWithJacobian(m, x, dt, S_ref);
    const Vec6 x_prop = m.propagateFixed(x, dt);
    const Eigen::Matrix<double, 6, 6> J = m.jacobianFixed(x, dt);
    for (int r = 0; r < 6; ++r) {
      ASSERT_EQ(bitsOf(xe(r)), bitsOf(x_ref(r))) << "case " << k;
      ASSERT_EQ(bitsOf(xe(r)), bitsOf(x_prop(r))) << "case " << k;
      for (int c = 0; c < 6; ++c) {
        ASSERT_EQ(bitsOf(S(r, c)), bitsOf(S_ref(r, c))) << "case " << k << " (" << r << "," << c << ")";
        ASSERT_EQ(bitsOf(J(r, c)), bitsOf(S_ref(r, c))) << "case " << k;
      }
    }
  }
}
