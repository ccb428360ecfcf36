#include <gtest/gtest.h>

#include <cmath>
#include <vector>

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

TEST(Statistics, PercentileInterpolatesBetweenOrderStatistics) {
  using viewline::core::percentile;
  const std::vector<double> v{4.0, 1.0, 3.0, 2.0};
  EXPECT_DOUBLE_EQ(percentile(v, 0.0), 1.0);
  EXPECT_DOUBLE_EQ(percentile(v, 1.0), 4.0);
  EXPECT_DOUBLE_EQ(percentile(v, 0.5), 2.5);
  EXPECT_DOUBLE_EQ(percentile(v, 0.95), 3.85);  // h = 2.85
  EXPECT_TRUE(std::isnan(percentile({}, 0.5)));
}

TEST(Statistics, NearestRankPercentileIsASampleValue) {
  using viewline::core::percentileNearestRank;
  std::vector<double> v;
  for (int i = 1; i <= 20; ++i) v.push_back(i);
  EXPECT_DOUBLE_EQ(percentileNearestRank(v, 0.95), 19.0);  // ceil(0.95 * 20) = 19th
  EXPECT_DOUBLE_EQ(percentileNearestRank(v, 0.96), 20.0);
  EXPECT_DOUBLE_EQ(percentileNearestRank(v, 0.0), 1.0);
  EXPECT_TRUE(std::isnan(percentileNearestRank({}, 0.5)));
}

TEST(Statistics, RmsOfASampleAndFromASum) {
  EXPECT_DOUBLE_EQ(viewline::core::rms({3.0, -4.0}), std::sqrt(12.5));
  EXPECT_DOUBLE_EQ(viewline::core::rmsFromSum(8.0, 2), 2.0);
  EXPECT_TRUE(std::isnan(viewline::core::rmsFromSum(0.0, 0)));
}
