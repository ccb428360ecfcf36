#include <gtest/gtest.h>

#include <Eigen/Cholesky>
#include <Eigen/LU>
#include <limits>

#include "viewline/core/random.h"
#include "viewline/core/statistics.h"
#include "viewline/estimation/consistency.h"
#include "viewline/estimation/kalman_filter.h"

using namespace viewline;
using namespace viewline::estimation;

namespace {

Eigen::MatrixXd randomSpd(core::Rng& rng, int n, double scale = 1.0) {
  Eigen::MatrixXd A(n, n);
  for (int i = 0; i < n; ++i)
    for (int j = 0; j < n; ++j) A(i, j) = core::gaussian(rng);
  return scale * (A * A.transpose() + 0.5 * Eigen::MatrixXd::Identity(n, n));
}

Eigen::MatrixXd randomMatrix(core::Rng& rng, int r, int c) {
  Eigen::MatrixXd A(r, c);
  for (int i = 0; i < r; ++i)
    for (int j = 0; j < c; ++j) A(i, j) = core::gaussian(rng);
  return A;
}

// Constant-velocity 3-D model (position, velocity), dt = 0.02.
LinearTransition cv3(double q, double dt = 0.02) {
  LinearTransition tr;
  tr.Phi = Eigen::MatrixXd::Identity(6, 6);
  tr.Phi.topRightCorner(3, 3) = dt * Eigen::Matrix3d::Identity();
  tr.Q = Eigen::MatrixXd::Zero(6, 6);
  tr.Q.topLeftCorner(3, 3) = q * dt * dt * dt / 3.0 * Eigen::Matrix3d::Identity();
  tr.Q.topRightCorner(3, 3) = q * dt * dt / 2.0 * Eigen::Matrix3d::Identity();
  tr.Q.bottomLeftCorner(3, 3) = q * dt * dt / 2.0 * Eigen::Matrix3d::Identity();
  tr.Q.bottomRightCorner(3, 3) = q * dt * Eigen::Matrix3d::Identity();
  tr.dt = dt;
  return tr;
}

}  // namespace

TEST(KalmanFilter, UpdateMatchesTextbookFilterForm) {
  core::Rng rng = core::makeRng(3);
  for (int trial = 0; trial < 20; ++trial) {
    const int n = 6, m = 1 + trial % 5;
    const Eigen::MatrixXd P = randomSpd(rng, n);
    const Eigen::VectorXd x = randomMatrix(rng, n, 1);
    LinearMeasurement meas{randomMatrix(rng, m, n), randomMatrix(rng, m, 1), randomSpd(rng, m, 0.1)};
    StateEstimate s(x, P, 1.0);
    const UpdateReport rep = update(s, meas);

    const Eigen::MatrixXd S = meas.R + meas.C * P * meas.C.transpose();
    const Eigen::MatrixXd K = P * meas.C.transpose() * S.inverse();  // reference only
    const Eigen::VectorXd d = meas.y - meas.C * x;
    EXPECT_LT((s.x() - (x + K * d)).norm(), 1e-10);
    EXPECT_LT((s.P() - (P - K * meas.C * P)).norm(), 1e-10);
    EXPECT_NEAR(rep.nis, d.dot(S.inverse() * d), 1e-9);
    EXPECT_EQ(rep.rows, m);
    EXPECT_EQ(s.t(), 1.0);
  }
}

TEST(KalmanFilter, PredictorFormWithCrossCovarianceMatchesTextbook) {
  core::Rng rng = core::makeRng(4);
  for (int trial = 0; trial < 20; ++trial) {
    const int n = 4, m = 2;
    const Eigen::MatrixXd P = randomSpd(rng, n);
    const Eigen::VectorXd x = randomMatrix(rng, n, 1);
    // A valid joint covariance [[R1, R12], [R12', R2]].
    const Eigen::MatrixXd J = randomSpd(rng, n + m, 0.2);
    LinearTransition tr;
    tr.Phi = randomMatrix(rng, n, n);
    tr.Gamma = randomMatrix(rng, n, 1);
    tr.u = Eigen::VectorXd::Constant(1, 0.7);
    tr.Q = J.topLeftCorner(n, n);
    tr.dt = 0.1;
    const Eigen::MatrixXd R12 = J.topRightCorner(n, m);
    LinearMeasurement meas{randomMatrix(rng, m, n), randomMatrix(rng, m, 1), J.bottomRightCorner(m, m)};
    StateEstimate s(x, P, 0.0);
    predictorStep(s, tr, meas, R12);

    const Eigen::MatrixXd S = meas.R + meas.C * P * meas.C.transpose();
    const Eigen::MatrixXd M = tr.Phi * P * meas.C.transpose() + R12;
    const Eigen::MatrixXd K = M * S.inverse();
    const Eigen::VectorXd xr = tr.Phi * x + tr.Gamma * tr.u + K * (meas.y - meas.C * x);
    const Eigen::MatrixXd Pr = tr.Phi * P * tr.Phi.transpose() + tr.Q - K * M.transpose();
    EXPECT_LT((s.x() - xr).norm(), 1e-9);
    EXPECT_LT((s.P() - Pr).norm(), 1e-9 * std::max(1.0, Pr.norm()));
    EXPECT_NEAR(s.t(), 0.1, 1e-15);
  }
}

TEST(KalmanFilter, ZeroRowsIsPurePrediction) {
  StateEstimate s(Eigen::VectorXd::Ones(6), Eigen::MatrixXd::Identity(6, 6), 0.0);
  LinearMeasurement none{Eigen::MatrixXd(0, 6), Eigen::VectorXd(0), Eigen::MatrixXd(0, 0)};
  const UpdateReport rep = update(s, none);
  EXPECT_EQ(rep.rows, 0);
  EXPECT_EQ(s.x(), Eigen::VectorXd::Ones(6));
  EXPECT_LT((s.P() - Eigen::MatrixXd::Identity(6, 6)).norm(), 1e-15);
  // Predictor form with no rows equals predict().
  StateEstimate a = s, b = s;
  const LinearTransition tr = cv3(0.5);
  predict(a, tr);
  predictorStep(b, tr, none, Eigen::MatrixXd(6, 0));
  EXPECT_LT((a.x() - b.x()).norm(), 1e-14);
  EXPECT_LT((a.P() - b.P()).norm(), 1e-14);
}

TEST(KalmanFilter, HugeInitialCovarianceDoesNotBreak) {
  // SPEC §1.1: P(0) = 1e12 I must not break the filter. A moving point observed through
  // scalar "plane" measurements (unit normals, 1 mm noise) for 5 steps: the estimate must
  // equal the weighted least-squares solution that ignores the prior, and P must stay SPD.
  core::Rng rng = core::makeRng(5);
  const LinearTransition tr = cv3(0.0);
  Eigen::VectorXd truth(6);
  truth << 1.0, -2.0, 3.0, 4.0, 0.5, -8.0;
  const double sigma = 1e-3;
  StateEstimate huge(Eigen::VectorXd::Zero(6), 1e12 * Eigen::MatrixXd::Identity(6, 6), 0.0);
  Eigen::MatrixXd info = Eigen::MatrixXd::Zero(6, 6);
  Eigen::VectorXd rhs = Eigen::VectorXd::Zero(6);
  Eigen::MatrixXd Phi_k = Eigen::MatrixXd::Identity(6, 6);  // maps x(0) to x(k)
  Eigen::VectorXd x = truth;
  for (int k = 0; k < 5; ++k) {
    LinearMeasurement m;
    m.C = Eigen::MatrixXd::Zero(2, 6);
    for (int r = 0; r < 2; ++r) m.C.block(r, 0, 1, 3) = randomMatrix(rng, 1, 3).normalized();
    m.R = sigma * sigma * Eigen::MatrixXd::Identity(2, 2);
    m.y = m.C * x + sigma * randomMatrix(rng, 2, 1);
    update(huge, m);
    // While P mixes 1e12 and 1e-6 (condition ~1e18) only the factor is representable: it must
    // stay finite and triangular with a non-negative diagonal (P = L Lᵀ is PSD by construction).
    ASSERT_TRUE(huge.sqrtP().allFinite()) << "step " << k;
    ASSERT_TRUE((huge.sqrtP().diagonal().array() >= 0.0).all()) << "step " << k;
    ASSERT_LT(huge.sqrtP().triangularView<Eigen::StrictlyUpper>().toDenseMatrix().norm(), 1e-300);
    const Eigen::MatrixXd H = m.C * Phi_k;
    info += H.transpose() * H / (sigma * sigma);
    rhs += H.transpose() * m.y / (sigma * sigma);
    predict(huge, tr);
    x = tr.Phi * x;
    Phi_k = tr.Phi * Phi_k;
  }
  // Ten rows for six states: P is now well conditioned and must be positive definite.
  Eigen::LLT<Eigen::MatrixXd> llt(huge.P());
  ASSERT_EQ(llt.info(), Eigen::Success);
  const Eigen::VectorXd x0_wls = info.ldlt().solve(rhs);
  const Eigen::VectorXd x5_wls = Phi_k * x0_wls;
  EXPECT_LT((huge.x() - x5_wls).norm(), 1e-6);
  EXPECT_LT((huge.x() - x).head(3).norm(), 0.05);
  // And the covariance equals the WLS covariance.
  const Eigen::MatrixXd P5 = Phi_k * info.inverse() * Phi_k.transpose();
  EXPECT_LT((huge.P() - P5).norm() / P5.norm(), 1e-5);
}

TEST(KalmanFilter, TooTightPriorShowsInNees) {
  // The true initial spread is 1 m; the filter is told 1 cm. The NEES after the first few
  // updates, averaged over 200 runs, must lie above the 99% band (and a correct prior inside).
  const int runs = 200;
  const LinearTransition tr = cv3(1.0);
  const Eigen::MatrixXd P0_true = Eigen::MatrixXd::Identity(6, 6);
  ConsistencyStats tight, right;
  core::Rng rng = core::makeRng(6);
  for (int r = 0; r < runs; ++r) {
    Eigen::VectorXd x = core::sampleGaussian(rng, Eigen::VectorXd::Zero(6), P0_true);
    StateEstimate good(Eigen::VectorXd::Zero(6), P0_true), bad(Eigen::VectorXd::Zero(6), 1e-4 * P0_true);
    for (int k = 0; k < 3; ++k) {
      LinearMeasurement m;
      m.C = Eigen::MatrixXd::Zero(2, 6);
      m.C(0, 0) = 1.0;
      m.C(1, 1) = 1.0;
      m.R = 0.01 * Eigen::MatrixXd::Identity(2, 2);
      m.y = m.C * x + core::sampleGaussian(rng, Eigen::VectorXd::Zero(2), m.R);
      update(good, m);
      update(bad, m);
      predict(good, tr);
      predict(bad, tr);
      x = tr.Phi * x + core::sampleGaussian(rng, Eigen::VectorXd::Zero(6), tr.Q);
    }
    right.add(nees(good, x), 6);
    tight.add(nees(bad, x), 6);
  }
  EXPECT_TRUE(right.consistent(0.99)) << right.mean();
  EXPECT_GT(tight.mean(), tight.bounds(0.99).hi) << tight.mean();
}

TEST(KalmanFilter, BadInputThrowsAndLeavesStateUnchanged) {
  const double nan = std::numeric_limits<double>::quiet_NaN();
  const double inf = std::numeric_limits<double>::infinity();
  StateEstimate s(Eigen::VectorXd::Ones(6), 2.0 * Eigen::MatrixXd::Identity(6, 6), 5.0);
  const StateEstimate before = s;
  auto unchanged = [&] {
    EXPECT_EQ(s.x(), before.x());
    EXPECT_EQ(s.sqrtP(), before.sqrtP());
    EXPECT_EQ(s.t(), before.t());
  };
  LinearMeasurement good;
  good.C = Eigen::MatrixXd::Zero(2, 6);
  good.C(0, 0) = good.C(1, 1) = 1.0;
  good.y = Eigen::Vector2d(1.0, 2.0);
  good.R = Eigen::Matrix2d::Identity();

  LinearMeasurement m = good;
  m.y[1] = nan;
  EXPECT_THROW(update(s, m), core::InvalidInput);
  unchanged();
  m = good;
  m.y[0] = inf;
  EXPECT_THROW(update(s, m), core::InvalidInput);
  unchanged();
  m = good;
  m.R(0, 0) = nan;
  EXPECT_THROW(update(s, m), core::InvalidInput);
  unchanged();
  m = good;
  m.R(0, 1) = 0.5;  // not symmetric
  EXPECT_THROW(update(s, m), core::InvalidInput);
  unchanged();
  m = good;
  m.R << 1.0, 2.0, 2.0, 1.0;  // symmetric, indefinite
  EXPECT_THROW(update(s, m), core::InvalidInput);
  unchanged();
  m = good;
  m.C = Eigen::MatrixXd::Zero(2, 5);  // wrong size
  EXPECT_THROW(update(s, m), core::InvalidInput);
  unchanged();

  LinearTransition tr = cv3(1.0);
  tr.dt = -0.01;
  EXPECT_THROW(predict(s, tr), core::InvalidInput);
  unchanged();
  tr = cv3(1.0);
  tr.dt = nan;
  EXPECT_THROW(predict(s, tr), core::InvalidInput);
  unchanged();
  tr = cv3(1.0);
  tr.Q(0, 0) = -1.0;  // not PSD
  EXPECT_THROW(predict(s, tr), core::InvalidInput);
  unchanged();
  tr = cv3(1.0);
  tr.Q(0, 3) += 0.1;  // not symmetric
  EXPECT_THROW(predict(s, tr), core::InvalidInput);
  unchanged();
  EXPECT_THROW(StateEstimate(Eigen::VectorXd::Ones(2), Eigen::Matrix2d::Zero()), core::InvalidInput);

  try {
    m = good;
    m.y[1] = nan;
    update(s, m);
  } catch (const core::InvalidInput& e) {
    EXPECT_NE(std::string(e.what()).find("measurement y"), std::string::npos) << e.what();
  }
}
