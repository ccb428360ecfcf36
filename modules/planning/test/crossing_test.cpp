// Crossing prediction: exact on a no-drag parabola, drag model against a fine integration,
// linearised covariance against Monte Carlo.
#include <gtest/gtest.h>

#include <cmath>

#include "viewline/core/random.h"
#include "viewline/estimation/models/ballistic_drag.h"
#include "viewline/planning/crossing.h"

using namespace viewline;
using planning::CrossingModel;
using planning::CrossingPlane;
using planning::FlightModel;
using Vector6 = Eigen::Matrix<double, 6, 1>;

TEST(Crossing, ExactOnANoDragParabola) {
  const Eigen::Vector3d g(0, 0, -9.81);
  const Eigen::Vector3d p0(4.0, 0.3, 1.5), v0(-8.0, -0.5, 2.0);
  CrossingPlane plane{Eigen::Vector3d(0.0, 0.0, 1.2), Eigen::Vector3d::UnitX()};
  CrossingModel m;
  m.kind = FlightModel::Ballistic;
  Vector6 x;
  x << p0, v0;
  auto c = planning::predictCrossing(x, 2.0, plane, m);
  ASSERT_TRUE(c);
  const double tau = 0.5;  // 4 m at 8 m/s
  EXPECT_NEAR(c->t, 2.0 + tau, 1e-12);
  const Eigen::Vector3d expected = p0 + v0 * tau + 0.5 * g * tau * tau;
  EXPECT_LT((c->p - expected).norm(), 1e-12);
  // The drag model with k = 0 takes the same exact path.
  m.kind = FlightModel::Drag;
  m.drag_k = 0.0;
  auto c2 = planning::predictCrossing(x, 2.0, plane, m);
  ASSERT_TRUE(c2);
  EXPECT_LT((c2->p - expected).norm(), 1e-12);
  // A tilted plane and vertical crossing: root of the quadratic.
  CrossingPlane floor{Eigen::Vector3d(0, 0, 0.5), Eigen::Vector3d::UnitZ()};
  m.kind = FlightModel::Ballistic;
  auto c3 = planning::predictCrossing(x, 0.0, floor, m);
  ASSERT_TRUE(c3);
  const double t3 = (2.0 + std::sqrt(4.0 + 2 * 9.81 * 1.0)) / 9.81;
  EXPECT_NEAR(c3->t, t3, 1e-12);
  EXPECT_NEAR(c3->p.z(), 0.5, 1e-12);
}

TEST(Crossing, NoCrossingWhenMovingAwayOrBehind) {
  CrossingPlane plane{Eigen::Vector3d(0.0, 0.0, 1.2), Eigen::Vector3d::UnitX()};
  CrossingModel m;
  Vector6 away;
  away << 4, 0, 1.5, 5, 0, 2;
  EXPECT_FALSE(planning::predictCrossing(away, 0.0, plane, m));
  Vector6 behind;
  behind << -0.1, 0, 1.5, -5, 0, 2;
  EXPECT_FALSE(planning::predictCrossing(behind, 0.0, plane, m));
}

TEST(Crossing, DragAgainstFineIntegration) {
  const double k = estimation::DragBallisticModel::dragConstant(1.2, 0.5, M_PI * 0.025 * 0.025, 0.057);
  CrossingModel m;
  m.kind = FlightModel::Drag;
  m.drag_k = k;
  CrossingPlane plane{Eigen::Vector3d(0.0, 0.0, 1.2), Eigen::Vector3d::UnitX()};
  Vector6 x;
  x << 4.0, 0.3, 1.4, -8.0, -0.5, 2.5;
  auto c = planning::predictCrossing(x, 0.0, plane, m);
  ASSERT_TRUE(c);
  // Reference: RK4 with 0.1 ms steps and linear interpolation at the sign change.
  estimation::DragBallisticModel d;
  d.k = k;
  d.substeps = 1;
  Vector6 s = x;
  double t = 0;
  const double h = 1e-4;
  while (true) {
    const Vector6 n = d.propagate(s, h);
    if (n(0) <= 0.0) {
      const double f = s(0) / (s(0) - n(0));
      EXPECT_NEAR(c->t, t + f * h, 1e-6);
      EXPECT_LT((c->p - (s.head<3>() + f * (n.head<3>() - s.head<3>()))).norm(), 1e-6);
      break;
    }
    s = n;
    t += h;
  }
  // Drag matters: the no-drag prediction is several centimetres off.
  m.kind = FlightModel::Ballistic;
  auto c0 = planning::predictCrossing(x, 0.0, plane, m);
  ASSERT_TRUE(c0);
  EXPECT_GT((c0->p - c->p).norm(), 0.02);
}

TEST(Crossing, LinearisedCovarianceMatchesMonteCarlo) {
  for (FlightModel kind : {FlightModel::Ballistic, FlightModel::Drag}) {
    CrossingModel m;
    m.kind = kind;
    m.drag_k = kind == FlightModel::Drag ? 0.0103 : 0.0;
    CrossingPlane plane{Eigen::Vector3d(0.0, 0.0, 1.2), Eigen::Vector3d::UnitX()};
    Vector6 x;
    x << 2.5, 0.1, 1.6, -7.5, -0.3, 0.5;
    Eigen::Matrix<double, 6, 6> P = Eigen::Matrix<double, 6, 6>::Zero();
    P.diagonal() << 0.01 * 0.01, 0.005 * 0.005, 0.008 * 0.008, 0.05 * 0.05, 0.03 * 0.03, 0.04 * 0.04;
    P(0, 3) = P(3, 0) = 0.5 * 0.01 * 0.05;
    const estimation::StateEstimate est(x, P, 1.0);
    auto c = planning::predictCrossing(est, plane, m);
    ASSERT_TRUE(c);
    EXPECT_NEAR(c->cov_p.row(0).norm(), 0.0, 1e-12);  // no spread along the normal
    core::Rng rng = core::makeRng(5);
    const int N = 4000;
    Eigen::Vector3d mean = Eigen::Vector3d::Zero();
    Eigen::Matrix3d S = Eigen::Matrix3d::Zero();
    double mt = 0, st = 0;
    std::vector<Eigen::Vector3d> pts;
    std::vector<double> ts;
    for (int i = 0; i < N; ++i) {
      const Vector6 xi = core::sampleGaussian(rng, x, P);
      auto ci = planning::predictCrossing(xi, 1.0, plane, m);
      ASSERT_TRUE(ci);
      pts.push_back(ci->p);
      ts.push_back(ci->t);
      mean += ci->p;
      mt += ci->t;
    }
    mean /= N;
    mt /= N;
    for (int i = 0; i < N; ++i) {
      S += (pts[i] - mean) * (pts[i] - mean).transpose();
      st += (ts[i] - mt) * (ts[i] - mt);
    }
    S /= (N - 1);
    st /= (N - 1);
    // Sampling error of a variance with N = 4000: ~2.2 % (1 sigma); allow 10 %.
    for (int i = 1; i < 3; ++i) EXPECT_NEAR(std::sqrt(S(i, i)) / std::sqrt(c->cov_p(i, i)), 1.0, 0.05) << i;
    EXPECT_NEAR(std::sqrt(st / c->var_t), 1.0, 0.05);
    EXPECT_LT((mean - c->p).norm(), 3e-3);
  }
}
