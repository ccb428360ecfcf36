#include <gtest/gtest.h>

#include "viewline/core/random.h"

using namespace viewline::core;

TEST(Random, SameSeedSameStream) {
  Rng a = makeRng(7), b = makeRng(7), c = makeRng(8);
  const double x = gaussian(a), y = gaussian(b), z = gaussian(c);
  EXPECT_EQ(x, y);
  EXPECT_NE(x, z);
}

TEST(Random, SampleGaussianHasTheRequestedCovariance) {
  Rng rng = makeRng(1);
  Eigen::MatrixXd cov(2, 2);
  cov << 4.0, 1.0, 1.0, 1.0;
  const Eigen::VectorXd mean = Eigen::Vector2d(1.0, -2.0);
  const int n = 40000;
  Eigen::MatrixXd s(2, n);
  for (int i = 0; i < n; ++i) s.col(i) = sampleGaussian(rng, mean, cov);
  const Eigen::VectorXd m = s.rowwise().mean();
  const Eigen::MatrixXd d = s.colwise() - m;
  const Eigen::MatrixXd c = d * d.transpose() / (n - 1);
  EXPECT_NEAR(m[0], 1.0, 0.05);
  EXPECT_NEAR(m[1], -2.0, 0.03);
  EXPECT_NEAR(c(0, 0), 4.0, 0.15);
  EXPECT_NEAR(c(0, 1), 1.0, 0.06);
  EXPECT_NEAR(c(1, 1), 1.0, 0.04);
}
