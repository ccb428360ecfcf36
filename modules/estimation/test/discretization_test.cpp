#include <gtest/gtest.h>

#include <cmath>

#include "viewline/estimation/discretization.h"

using namespace viewline;
using namespace viewline::estimation;

TEST(Discretization, WhiteNoiseAccelerationClosedForm) {
  // ẋ = v, v̇ = w, E w w = q: Φ = [1 dt; 0 1], Q = q [dt³/3 dt²/2; dt²/2 dt].
  ContinuousLinearModel m;
  m.A = Eigen::Matrix2d::Zero();
  m.A(0, 1) = 1.0;
  m.G = Eigen::Vector2d(0.0, 1.0);
  m.Qc = Eigen::MatrixXd::Constant(1, 1, 2.5);
  for (double dt : {1e-4, 0.02, 0.37, 3.0}) {
    const LinearTransition tr = discretize(m, dt);
    Eigen::Matrix2d Phi, Q;
    Phi << 1.0, dt, 0.0, 1.0;
    Q << dt * dt * dt / 3.0, dt * dt / 2.0, dt * dt / 2.0, dt;
    Q *= 2.5;
    EXPECT_LT((tr.Phi - Phi).norm(), 1e-12);
    EXPECT_LT((tr.Q - Q).norm(), 1e-12 * std::max(1.0, Q.norm())) << dt;
    EXPECT_EQ(tr.dt, dt);
  }
}

TEST(Discretization, OrnsteinUhlenbeckAndInputClosedForm) {
  // ẋ = −a x + b u + w: Φ = e^{−a dt}, Γ = b (1 − e^{−a dt}) / a, Q = q (1 − e^{−2 a dt}) / (2a).
  const double a = 1.7, b = 0.3, q = 0.9, dt = 0.25;
  ContinuousLinearModel m;
  m.A = Eigen::MatrixXd::Constant(1, 1, -a);
  m.B = Eigen::MatrixXd::Constant(1, 1, b);
  m.G = Eigen::MatrixXd::Identity(1, 1);
  m.Qc = Eigen::MatrixXd::Constant(1, 1, q);
  const LinearTransition tr = discretize(m, dt, Eigen::VectorXd::Constant(1, 2.0));
  EXPECT_NEAR(tr.Phi(0, 0), std::exp(-a * dt), 1e-14);
  EXPECT_NEAR(tr.Gamma(0, 0), b * (1.0 - std::exp(-a * dt)) / a, 1e-14);
  EXPECT_NEAR(tr.Q(0, 0), q * (1.0 - std::exp(-2.0 * a * dt)) / (2.0 * a), 1e-14);
  EXPECT_EQ(tr.u[0], 2.0);
}

TEST(Discretization, GravityInputMatchesBallistic) {
  // [L] eq 20 (y up): Γ u = (0, −g h²/2, 0, 0, −g h, 0) for u = 1 and B = (0,0,0, 0,−g,0).
  const double g = 9.81, h = 0.02;
  ContinuousLinearModel m;
  m.A = Eigen::MatrixXd::Zero(6, 6);
  m.A.topRightCorner(3, 3) = Eigen::Matrix3d::Identity();
  m.B = Eigen::MatrixXd::Zero(6, 1);
  m.B(4, 0) = -g;
  m.G = Eigen::MatrixXd::Zero(6, 3);
  m.G.bottomRows(3) = Eigen::Matrix3d::Identity();
  m.Qc = Eigen::Matrix3d::Identity();
  const LinearTransition tr = discretize(m, h, Eigen::VectorXd::Ones(1));
  Eigen::VectorXd expected = Eigen::VectorXd::Zero(6);
  expected[1] = -g * h * h / 2.0;
  expected[4] = -g * h;
  EXPECT_LT((tr.Gamma * tr.u - expected).norm(), 1e-14);
}

TEST(Discretization, RejectsBadDt) {
  ContinuousLinearModel m;
  m.A = Eigen::MatrixXd::Zero(1, 1);
  m.G = Eigen::MatrixXd::Identity(1, 1);
  m.Qc = Eigen::MatrixXd::Identity(1, 1);
  EXPECT_THROW(discretize(m, 0.0), core::InvalidInput);
  EXPECT_THROW(discretize(m, -1.0), core::InvalidInput);
  EXPECT_THROW(discretize(m, std::nan("")), core::InvalidInput);
}

TEST(Discretization, FirstOrderHoldOfADoubleIntegratorClosedForm) {
  // ẋ = v, v̇ = u with u ramping from u0 to u1 over dt: x gains u0 dt²/3 + u1 dt²/6 and v gains
  // (u0 + u1) dt / 2 (the trapezoid); with u0 = u1 it is the zero-order hold.
  ContinuousLinearModel m;
  m.A = Eigen::Matrix2d::Zero();
  m.A(0, 1) = 1.0;
  m.B = Eigen::Vector2d(0.0, 1.0);
  m.G = Eigen::Vector2d(0.0, 1.0);
  m.Qc = Eigen::MatrixXd::Constant(1, 1, 0.4);
  for (double dt : {1e-3, 0.02, 0.5}) {
    const LinearTransition foh = discretizeFirstOrderHold(m, dt, Eigen::VectorXd::Constant(1, 1.5),
                                                          Eigen::VectorXd::Constant(1, -0.7));
    ASSERT_EQ(foh.Gamma.rows(), 2);
    ASSERT_EQ(foh.Gamma.cols(), 2);
    Eigen::Matrix2d expected;
    expected << dt * dt / 3.0, dt * dt / 6.0, dt / 2.0, dt / 2.0;
    EXPECT_LT((foh.Gamma - expected).norm(), 1e-13) << dt;
    const LinearTransition zoh = discretize(m, dt, Eigen::VectorXd::Constant(1, 0.3));
    EXPECT_LT((foh.Phi - zoh.Phi).norm(), 1e-15);
    EXPECT_LT((foh.Q - zoh.Q).norm(), 1e-15);
    EXPECT_LT((foh.Gamma.col(0) + foh.Gamma.col(1) - zoh.Gamma).norm(), 1e-13);
  }
}

TEST(Discretization, FirstOrderHoldMatchesAFineIntegrationOfARampedInput) {
  // A damped oscillator driven by a ramp: the exact step against 20,000 midpoint (RK2) substeps.
  ContinuousLinearModel m;
  m.A.resize(2, 2);
  m.A << 0.0, 1.0, -4.0, -0.6;
  m.B = Eigen::MatrixXd(2, 1);
  m.B << 0.2, 1.0;
  m.G = Eigen::MatrixXd::Identity(2, 2);
  m.Qc = Eigen::MatrixXd::Identity(2, 2);
  const double dt = 0.3, u0 = 2.0, u1 = -1.0;
  const Eigen::Vector2d x0(0.1, -0.4);
  const LinearTransition tr = discretizeFirstOrderHold(m, dt, Eigen::VectorXd::Constant(1, u0), Eigen::VectorXd::Constant(1, u1));
  const Eigen::Vector2d exact = tr.Phi * x0 + tr.Gamma * tr.u;
  const int n = 20000;
  const double h = dt / n;
  auto f = [&](const Eigen::Vector2d& x, double s) -> Eigen::Vector2d {
    return m.A * x + m.B.col(0) * (u0 + (u1 - u0) * s / dt);
  };
  Eigen::Vector2d x = x0;
  for (int k = 0; k < n; ++k) {
    const double s = k * h;
    x += h * f(x + 0.5 * h * f(x, s), s + 0.5 * h);
  }
  EXPECT_LT((exact - x).norm(), 1e-9);
  // The zero-order hold of either end is visibly off (the test would catch a swapped column).
  EXPECT_GT((discretize(m, dt, Eigen::VectorXd::Constant(1, u1)).Gamma * u1 + tr.Phi * x0 - x).norm(), 1e-2);
}

TEST(Discretization, FirstOrderHoldNeedsAnInputOfTheRightSize) {
  ContinuousLinearModel m;
  m.A = Eigen::MatrixXd::Zero(1, 1);
  m.G = Eigen::MatrixXd::Identity(1, 1);
  m.Qc = Eigen::MatrixXd::Identity(1, 1);
  EXPECT_THROW(discretizeFirstOrderHold(m, 0.1, Eigen::VectorXd(), Eigen::VectorXd()), core::InvalidInput);
  m.B = Eigen::MatrixXd::Ones(1, 1);
  EXPECT_THROW(discretizeFirstOrderHold(m, 0.1, Eigen::VectorXd::Ones(1), Eigen::VectorXd::Ones(2)), core::InvalidInput);
  EXPECT_THROW(discretizeFirstOrderHold(m, 0.1, Eigen::VectorXd::Ones(1), Eigen::VectorXd::Constant(1, std::nan(""))),
               core::InvalidInput);
  EXPECT_THROW(discretizeFirstOrderHold(m, 0.0, Eigen::VectorXd::Ones(1), Eigen::VectorXd::Ones(1)), core::InvalidInput);
}
