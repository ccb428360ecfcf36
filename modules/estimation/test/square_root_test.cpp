// The hot path of the filter: in-place triangularisation and the cached,
// validated covariance factors (a covariance equal to the previous one reuses
// its factor; anything else is validated again).
#include <gtest/gtest.h>

#include <limits>

#include "viewline/core/error.h"
#include "viewline/core/random.h"
#include "viewline/estimation/kalman_filter.h"
#include "viewline/estimation/square_root.h"

using namespace viewline;
using namespace viewline::estimation;

namespace {
Eigen::MatrixXd randomMatrix(core::Rng& rng, Eigen::Index r, Eigen::Index c) {
  Eigen::MatrixXd A(r, c);
  for (Eigen::Index i = 0; i < r; ++i)
    for (Eigen::Index j = 0; j < c; ++j) A(i, j) = core::gaussian(rng);
  return A;
}
}  // namespace

TEST(SquareRoot, InPlaceTriangularisationPreservesAAt) {
  core::Rng rng = core::makeRng(5);
  for (const auto& [r, c] : std::vector<std::pair<int, int>>{{1, 1}, {3, 7}, {6, 12}, {14, 14}, {8, 3}, {5, 0}, {0, 4}}) {
    const Eigen::MatrixXd A = randomMatrix(rng, r, c);
    RowMatrixXd W = A;
    lowerTriangularizeInPlace(W);
    const Eigen::MatrixXd Wd = W;
    EXPECT_LT((Wd * Wd.transpose() - A * A.transpose()).norm(), 1e-12 * (1.0 + A.squaredNorm()));
    for (Eigen::Index i = 0; i < r; ++i) {
      for (Eigen::Index j = i + 1; j < c; ++j) EXPECT_EQ(W(i, j), 0.0) << r << "x" << c;
      if (i < c) {
        EXPECT_GE(W(i, i), 0.0);
      }
    }
    const Eigen::MatrixXd T = lowerTriangularize(A);
    ASSERT_EQ(T.rows(), r);
    ASSERT_EQ(T.cols(), r);
    EXPECT_LT((T * T.transpose() - A * A.transpose()).norm(), 1e-12 * (1.0 + A.squaredNorm()));
  }
}

TEST(SquareRoot, CachedFactorsStillRejectBadCovariances) {
  const double nan = std::numeric_limits<double>::quiet_NaN();
  StateEstimate s(Eigen::VectorXd::Zero(2), Eigen::MatrixXd::Identity(2, 2));
  LinearTransition tr{Eigen::MatrixXd::Identity(2, 2), Eigen::MatrixXd(), Eigen::VectorXd(),
                      0.1 * Eigen::MatrixXd::Identity(2, 2), 0.1};
  LinearMeasurement m{Eigen::MatrixXd::Identity(2, 2), Eigen::VectorXd::Ones(2), 0.5 * Eigen::MatrixXd::Identity(2, 2)};
  predict(s, tr);  // Q and R factors now cached
  update(s, m);
  const StateEstimate before = s;
  auto expectRejected = [&](auto&& fn) {
    EXPECT_THROW(fn(), core::InvalidInput);
    EXPECT_EQ(s.x(), before.x());
    EXPECT_EQ(s.sqrtP(), before.sqrtP());
  };
  LinearTransition bad = tr;
  bad.Q(0, 1) = 0.01;  // asymmetric
  expectRejected([&] { predict(s, bad); });
  bad = tr;
  bad.Q(1, 1) = nan;
  expectRejected([&] { predict(s, bad); });
  bad = tr;
  bad.Q(1, 1) = -0.1;  // indefinite
  expectRejected([&] { predict(s, bad); });
  LinearMeasurement badm = m;
  badm.R(1, 1) = 0.0;  // semi-definite R is not allowed
  expectRejected([&] { update(s, badm); });
  badm = m;
  badm.R(0, 1) = 0.3;
  expectRejected([&] { update(s, badm); });
  badm = m;
  badm.R(0, 0) = std::numeric_limits<double>::infinity();
  expectRejected([&] { update(s, badm); });
  // Semi-definite Q is accepted (LDLT factor), and the cached good ones still work afterwards.
  bad = tr;
  bad.Q(1, 1) = 0.0;
  bad.Q(0, 0) = 0.0;
  EXPECT_NO_THROW(predict(s, bad));
  EXPECT_NO_THROW(predict(s, tr));
  EXPECT_NO_THROW(update(s, m));
}
