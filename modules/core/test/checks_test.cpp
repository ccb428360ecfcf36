#include <gtest/gtest.h>

#include <limits>

#include "viewline/core/checks.h"

using namespace viewline::core;

TEST(Checks, FiniteRejectsNanAndInf) {
  Eigen::MatrixXd m = Eigen::MatrixXd::Identity(2, 2);
  EXPECT_NO_THROW(requireFinite(m, "m"));
  m(1, 0) = std::numeric_limits<double>::quiet_NaN();
  EXPECT_THROW(requireFinite(m, "m"), InvalidInput);
  EXPECT_THROW(requireFinite(std::numeric_limits<double>::infinity(), "x"), InvalidInput);
}

TEST(Checks, MessageNamesTheQuantity) {
  try {
    requirePositive(-1.0, "dt");
    FAIL() << "no throw";
  } catch (const InvalidInput& e) {
    EXPECT_NE(std::string(e.what()).find("dt"), std::string::npos);
    EXPECT_NE(std::string(e.what()).find("> 0"), std::string::npos);
  }
}

TEST(Checks, SymmetricPositiveDefinite) {
  Eigen::MatrixXd a(2, 2);
  a << 2, 1, 1, 2;
  EXPECT_NO_THROW(requireSymmetricPositiveDefinite(a, "a"));
  Eigen::MatrixXd ns = a;
  ns(0, 1) = 1.5;
  EXPECT_THROW(requireSymmetricPositiveDefinite(ns, "a"), InvalidInput);
  Eigen::MatrixXd indef(2, 2);
  indef << 1, 2, 2, 1;
  EXPECT_THROW(requireSymmetricPositiveDefinite(indef, "a"), InvalidInput);
  EXPECT_THROW(requireSymmetricPositiveSemiDefinite(indef, "a"), InvalidInput);
  Eigen::MatrixXd psd = Eigen::MatrixXd::Zero(2, 2);
  psd(0, 0) = 1.0;
  EXPECT_NO_THROW(requireSymmetricPositiveSemiDefinite(psd, "a"));
  EXPECT_THROW(requireSymmetricPositiveDefinite(psd, "a"), InvalidInput);
  EXPECT_THROW(requireSize(a, 3, 3, "a"), InvalidInput);
}

TEST(Checks, RankDeficientPsdWhoseLdltHitsAZeroPivotFirstIsAccepted) {
  // A unicycle process noise: the rank-2 held-input block G Σ Gᵀ beside the random walks. Eigen's
  // LDLT meets its exactly zero pivot before the small q_v dt pivot and reports NumericalIssue.
  Eigen::MatrixXd q = Eigen::MatrixXd::Zero(5, 5);
  const double s = 0.0141 * 0.0141, w = 0.316 * 0.316, dt = 0.1, v = 0.0133763, phi = -3.84383;
  Eigen::Matrix<double, 3, 2> g;
  g << dt * std::cos(phi), -0.5 * v * dt * dt * std::sin(phi), dt * std::sin(phi), 0.5 * v * dt * dt * std::cos(phi), 0.0,
      dt;
  q.topLeftCorner(3, 3) = g * Eigen::Vector2d(s, w).asDiagonal() * g.transpose();
  q(3, 3) = 3.72091e-7;
  q(4, 4) = 0.00132712;
  EXPECT_NO_THROW(requireSymmetricPositiveSemiDefinite(q, "q"));
  q(3, 3) = -1e-6;  // an eigenvalue below zero by far more than the rounding is still refused
  EXPECT_THROW(requireSymmetricPositiveSemiDefinite(q, "q"), InvalidInput);
}
