#include <gtest/gtest.h>

#include <Eigen/LU>

#include "viewline/estimation/kalman_filter.h"
#include "viewline/estimation/riccati.h"

using namespace viewline;
using namespace viewline::estimation;

TEST(Riccati, DareMatchesConvergedTimeVaryingFilter) {
  // Constant-acceleration model observed in position ([T]-like), 50 Hz.
  const double dt = 0.02, q = 3.0;
  Eigen::MatrixXd A(3, 3);
  A << 1, dt, dt * dt / 2, 0, 1, dt, 0, 0, 1;
  const Eigen::Vector3d g(dt * dt * dt / 6, dt * dt / 2, dt);
  const Eigen::MatrixXd Q = q * g * g.transpose() + 1e-9 * Eigen::MatrixXd::Identity(3, 3);
  Eigen::MatrixXd C = Eigen::MatrixXd::Zero(1, 3);
  C(0, 0) = 1.0;
  const Eigen::MatrixXd R = Eigen::MatrixXd::Constant(1, 1, 1e-4);

  const StationaryFilter sf = solveDare(A, C, Q, R);
  EXPECT_LT(sf.residual, 1e-10);

  StateEstimate s(Eigen::VectorXd::Zero(3), 100.0 * Eigen::MatrixXd::Identity(3, 3));
  LinearTransition tr{A, Eigen::MatrixXd(), Eigen::VectorXd(), Q, dt};
  LinearMeasurement m{C, Eigen::VectorXd::Zero(1), R};
  for (int k = 0; k < 3000; ++k) {
    predict(s, tr);
    if (k < 2999) update(s, m);
  }
  // s now holds the a-priori covariance of the converged filter.
  EXPECT_LT((s.P() - sf.P).norm() / sf.P.norm(), 1e-6);
  const Eigen::MatrixXd S = C * s.P() * C.transpose() + R;
  const Eigen::MatrixXd K = s.P() * C.transpose() * S.inverse();
  EXPECT_LT((K - sf.Kf).norm() / sf.Kf.norm(), 1e-6);
}

TEST(Riccati, UndetectableUnstableModeIsReported) {
  Eigen::MatrixXd A = Eigen::MatrixXd::Identity(2, 2) * 1.1;  // both modes unstable
  Eigen::MatrixXd C(1, 2);
  C << 1.0, 0.0;  // second mode never observed
  EXPECT_THROW(solveDare(A, C, Eigen::MatrixXd::Identity(2, 2), Eigen::MatrixXd::Identity(1, 1)),
               core::NumericalError);
  EXPECT_THROW(solveDare(A, C, Eigen::MatrixXd::Identity(2, 2), -Eigen::MatrixXd::Identity(1, 1)),
               core::InvalidInput);
}
