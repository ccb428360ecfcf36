#include <gtest/gtest.h>

#include "viewline/core/error.h"
#include "viewline/core/statistics.h"

using namespace viewline::core;

TEST(Statistics, KnownQuantiles) {
  // Table values: chi2(1) 95% = 3.841459, chi2(2) 99% = 9.210340, chi2(6) 0.5% = 0.675727.
  EXPECT_NEAR(chiSquareQuantile(1, 0.95), 3.841459, 1e-5);
  EXPECT_NEAR(chiSquareQuantile(2, 0.99), 9.210340, 1e-5);
  EXPECT_NEAR(chiSquareQuantile(6, 0.005), 0.675727, 1e-5);
  EXPECT_NEAR(chiSquareSurvival(2, 9.210340), 0.01, 1e-7);
}

TEST(Statistics, AveragedIntervalShrinksAroundDof) {
  const Interval one = averagedChiSquareInterval(3, 1, 0.99);
  const Interval many = averagedChiSquareInterval(3, 500, 0.99);
  EXPECT_LT(one.lo, many.lo);
  EXPECT_GT(one.hi, many.hi);
  EXPECT_TRUE(many.contains(3.0));
  // Wilson-Hilferty approximation for chi2(1500) at 0.5% / 99.5%, divided by 500.
  EXPECT_NEAR(many.lo, 2.7253, 0.001);
  EXPECT_NEAR(many.hi, 3.2897, 0.001);
  EXPECT_THROW(chiSquareQuantile(2, 1.5), InvalidInput);
}
