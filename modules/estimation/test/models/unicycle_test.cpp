// Curvilinear ground target (unicycle), [K] eqs 16-20, and the least-squares
// trajectory prediction, [K] eqs 27-29.
#include <gtest/gtest.h>

#include <cmath>
#include <limits>

#include "monte_carlo.h"
#include "viewline/estimation/models/unicycle.h"
#include "viewline/estimation/models/unicycle_predictor.h"

using namespace viewline;
using namespace viewline::estimation;
using test::expectConsistent;
using test::expectInvalid;
using test::expectOverconfident;

namespace {
const double kNaN = std::numeric_limits<double>::quiet_NaN();
using Vec5 = Eigen::Matrix<double, 5, 1>;
double maxAbs(const Eigen::MatrixXd& m) { return m.cwiseAbs().maxCoeff(); }
}  // namespace

TEST(UnicycleModel, StepEquations) {
  const UnicycleModel model;
  Vec5 x;
  x << 1.0, 2.0, 0.3, 2.0, 0.5;
  const double dt = 0.1, phi = 0.3 + 0.5 * 0.5 * dt;
  const Eigen::VectorXd y = model.propagate(x, dt);
  EXPECT_NEAR(y[0], 1.0 + 2.0 * dt * std::cos(phi), 1e-15);
  EXPECT_NEAR(y[1], 2.0 + 2.0 * dt * std::sin(phi), 1e-15);
  EXPECT_NEAR(y[2], 0.3 + 0.5 * dt, 1e-15);
  EXPECT_EQ(y[3], 2.0);
  EXPECT_EQ(y[4], 0.5);
  // Constant v, ω: one full turn closes the circle of radius v/ω (midpoint rule, O((ω dt)²) per step).
  Eigen::VectorXd z = x;
  const int n = 200;
  const double T = 2.0 * M_PI / 0.5;
  for (int i = 0; i < n; ++i) z = model.propagate(z, T / n);
  EXPECT_LT((z.head(2) - x.head(2)).norm(), 1e-3 * 2.0 / 0.5);
  EXPECT_NEAR(z[2], x[2] + 2.0 * M_PI, 1e-12);
}

TEST(UnicycleModel, AnalyticJacobianMatchesNumerical) {
  const UnicycleModel model;
  for (const Vec5& x : {(Vec5() << 1, 2, 0.3, 2, 0.5).finished(), (Vec5() << -4, 0, 3.1, -0.5, -1.2).finished(),
                        (Vec5() << 0, 0, -1.7, 0, 0).finished()}) {
    for (double dt : {0.02, 0.1, 0.7}) {
      const Eigen::MatrixXd Fn =
          numericalJacobian([&](const Eigen::VectorXd& z) { return model.propagate(z, dt); }, x, 1e-6);
      EXPECT_LT(maxAbs(model.jacobian(x, dt) - Fn), 1e-8) << x.transpose() << " dt " << dt;
    }
  }
  const NonlinearMeasurement m = UnicycleModel::positionMeasurement(Eigen::Vector2d(1, 2), 0.1);
  const Vec5 x = (Vec5() << 1, 2, 0.3, 2, 0.5).finished();
  EXPECT_LT(maxAbs(m.H(x) - numericalJacobian(m.h, x)), 1e-9);
}

TEST(UnicycleModel, ProcessNoiseIsRandomWalkOnSpeedAndTurnRate) {
  UnicycleModel model;
  model.q_v = 0.2;
  model.q_w = 0.03;
  const Eigen::MatrixXd Q = model.processNoise(0.5);
  Eigen::MatrixXd expected = Eigen::MatrixXd::Zero(5, 5);
  expected(3, 3) = 0.1;
  expected(4, 4) = 0.015;
  EXPECT_LT(maxAbs(Q - expected), 1e-16);
}

TEST(UnicycleModel, HeldInputNoiseIsTheInputsEffectOverTheStep) {
  UnicycleModel model;
  model.q_v = 0.2;
  model.q_w = 0.03;
  model.input_sigma_v = 0.05;
  model.input_sigma_w = 0.4;
  model.input_period = 0.1;
  const Vec5 x = (Vec5() << 1, 2, 0.3, 2, 0.5).finished();
  // One period: the held ε moves (x, y, θ) through the v and ω columns of F.
  const Eigen::MatrixXd F = model.jacobian(x, 0.1);
  const Eigen::MatrixXd G = F.block(0, 3, 3, 2);
  const Eigen::Matrix2d S = Eigen::Vector2d(0.05 * 0.05, 0.4 * 0.4).asDiagonal();
  Eigen::MatrixXd expected = Eigen::MatrixXd::Zero(5, 5);
  expected.topLeftCorner(3, 3) = G * S * G.transpose();
  expected(3, 3) = 0.02;
  expected(4, 4) = 0.003;
  EXPECT_LT(maxAbs(model.processNoise(x, 0.1) - expected), 1e-15);
  // Three periods: the three independent ε average to Σ / 3 (θ's variance is (σ_εω T)² · 3).
  EXPECT_NEAR(model.processNoise(x, 0.3)(2, 2), 3.0 * std::pow(0.4 * 0.1, 2), 1e-15);
  // Without held noise the state-free Q is the same as the linearised one; with it, refused.
  model.input_sigma_v = model.input_sigma_w = 0.0;
  EXPECT_EQ(model.processNoise(0.1), model.processNoise(x, 0.1));
  model.input_sigma_w = 0.4;
  expectInvalid([&] { model.processNoise(0.1); }, "input_sigma");
  expectInvalid([&] { model.transition(0.1); }, "input_sigma");
  model.input_period = 0.0;
  expectInvalid([&] { model.processNoise(x, 0.1); }, "UnicycleModel.input_period");
}

TEST(UnicycleModel, AnglesWrap) {
  EXPECT_NEAR(wrapAngle(3.0 * M_PI / 2.0), -M_PI / 2.0, 1e-15);
  EXPECT_NEAR(wrapAngle(-3.0 * M_PI / 2.0), M_PI / 2.0, 1e-15);
  EXPECT_EQ(wrapAngle(M_PI), M_PI);
  EXPECT_EQ(wrapAngle(-M_PI), M_PI);  // range (−π, π]
  EXPECT_NEAR(wrapAngle(7.0), 7.0 - 2.0 * M_PI, 1e-15);
  // The filter's heading stays wrapped when the target turns through ±π.
  const UnicycleModel model;
  StateEstimate s((Vec5() << 0, 0, 3.0, 1.0, 1.0).finished(), 0.01 * Eigen::MatrixXd::Identity(5, 5));
  for (int k = 0; k < 5; ++k) ekfPredict(s, model.transition(0.1));
  EXPECT_NEAR(s.x()[2], 3.5 - 2.0 * M_PI, 1e-12);
  StateEstimate u((Vec5() << 0, 0, 3.0, 1.0, 1.0).finished(), 0.01 * Eigen::MatrixXd::Identity(5, 5));
  for (int k = 0; k < 5; ++k) ukfPredict(u, model.transition(0.1));
  EXPECT_NEAR(u.x()[2], 3.5 - 2.0 * M_PI, 1e-9);
  const Eigen::VectorXd d = UnicycleModel::difference((Vec5() << 0, 0, -3.1, 0, 0).finished(),
                                                      (Vec5() << 0, 0, 3.1, 0, 0).finished());
  EXPECT_NEAR(d[2], 2.0 * M_PI - 6.2, 1e-12);
}

TEST(UnicycleModel, BadInputNamesTheField) {
  const Eigen::VectorXd x = (Vec5() << 1, 2, 0.3, 2, 0.5).finished();
  expectInvalid([&] { UnicycleModel().propagate(x, 0.0); }, "dt");
  expectInvalid([&] { UnicycleModel().jacobian(x, -0.1); }, "dt");
  expectInvalid([&] { UnicycleModel().transition(kNaN); }, "dt");
  expectInvalid([&] { UnicycleModel m; m.q_v = kNaN; m.transition(0.1); }, "UnicycleModel.q_v");
  expectInvalid([&] { UnicycleModel m; m.q_w = -1.0; m.transition(0.1); }, "UnicycleModel.q_w");
  expectInvalid([&] { UnicycleModel().propagate(Eigen::VectorXd::Constant(5, kNaN), 0.1); }, "state x");
  expectInvalid([&] { UnicycleModel::positionMeasurement(Eigen::Vector2d(kNaN, 0), 0.1); }, "measurement y");
  expectInvalid([&] { UnicycleModel::positionMeasurement(Eigen::Vector2d(0, 0), 0.0); }, "measurement sigma");
}

// ---------------------------------------------------------------- Monte Carlo

namespace {
enum class Filter { kEkf, kUkf };

// Truth: the model's own discrete process, x ← f(x) + (0, 0, 0, ξv, ξω) with ξ drawn from Q.
// NEES at the final step with the heading error wrapped; one value per run.
ConsistencyStats unicycleMc(Filter filter, double q_scale, std::uint64_t seed) {
  UnicycleModel model;
  model.q_v = 0.05;
  model.q_w = 0.01;
  UnicycleModel filter_model = model;
  filter_model.q_v *= q_scale;
  filter_model.q_w *= q_scale;
  const double dt = 0.1, sigma = 0.1;
  const int steps = 50, runs = 300;
  const NonlinearTransition truth_tr = model.transition(dt), filt_tr = filter_model.transition(dt);
  const test::NoiseSampler qn(truth_tr.Q), rn(sigma * sigma * Eigen::MatrixXd::Identity(2, 2));
  const Eigen::VectorXd m0 = (Vec5() << 0, 0, 0.5, 3.0, 0.2).finished();
  const Eigen::MatrixXd P0 = Eigen::VectorXd((Vec5() << 0.04, 0.04, 0.01, 0.09, 0.0025).finished()).asDiagonal();
  const test::NoiseSampler p0(P0);
  ConsistencyStats stats;
  for (int run = 0; run < runs; ++run) {
    core::Rng rng(core::deriveSeed(seed, static_cast<std::uint64_t>(run)));
    Eigen::VectorXd x = m0 + p0(rng);
    StateEstimate s(m0, P0);
    for (int k = 0; k < steps; ++k) {
      x = truth_tr.normalize(truth_tr.f(x) + qn(rng));
      const NonlinearMeasurement m = UnicycleModel::positionMeasurement(x.head<2>() + rn(rng), sigma);
      if (filter == Filter::kEkf) {
        ekfPredict(s, filt_tr);
        ekfUpdate(s, m);
      } else {
        ukfPredict(s, filt_tr);
        ukfUpdate(s, m);
      }
    }
    const Eigen::VectorXd e = UnicycleModel::difference(x, s.x());
    stats.add(s.sqrtP().triangularView<Eigen::Lower>().solve(e).squaredNorm(), 5.0);
  }
  return stats;
}
}  // namespace

TEST(UnicycleModel, MonteCarloNeesConsistentEkf) { expectConsistent(unicycleMc(Filter::kEkf, 1.0, 41)); }
TEST(UnicycleModel, MonteCarloNeesConsistentUkf) { expectConsistent(unicycleMc(Filter::kUkf, 1.0, 42)); }
TEST(UnicycleModel, TooSmallProcessNoiseDetectedEkf) { expectOverconfident(unicycleMc(Filter::kEkf, 0.1, 43)); }
TEST(UnicycleModel, TooSmallProcessNoiseDetectedUkf) { expectOverconfident(unicycleMc(Filter::kUkf, 0.1, 44)); }

namespace {
// Truth as [K] drives its object: the smooth (v̄, ω̄) random walks of the model plus ε drawn once
// per step (one input period) and held over it. The filter is told the held noise or not.
ConsistencyStats heldInputMc(bool told, std::uint64_t seed) {
  UnicycleModel model;
  model.q_v = 0.0005;  // the smooth speed stays away from 0 (where the heading is not observable)
  model.q_w = 0.02;
  model.input_sigma_v = 0.0141;  // [K]: var ξv 2 (cm/s)²
  model.input_sigma_w = 0.316;   // [K]: var ξω 0.1 (rad/s)²
  model.input_period = 0.1;
  UnicycleModel filter_model = model;
  if (!told) filter_model.input_sigma_v = filter_model.input_sigma_w = 0.0;
  const double dt = 0.1, sigma = 0.01;
  const int steps = 60, runs = 300;
  UnicycleModel walks_only = model;
  walks_only.input_sigma_v = walks_only.input_sigma_w = 0.0;
  const test::NoiseSampler walk(walks_only.processNoise(dt)), rn(sigma * sigma * Eigen::MatrixXd::Identity(2, 2));
  const Eigen::VectorXd m0 = (Vec5() << 0, 0, 0.5, 0.3, 0.2).finished();
  const Eigen::MatrixXd P0 = Eigen::VectorXd((Vec5() << 1e-4, 1e-4, 0.01, 0.01, 0.04).finished()).asDiagonal();
  const test::NoiseSampler p0(P0);
  ConsistencyStats stats;
  for (int run = 0; run < runs; ++run) {
    core::Rng rng(core::deriveSeed(seed, static_cast<std::uint64_t>(run)));
    Eigen::VectorXd x = m0 + p0(rng);
    StateEstimate s(m0, P0);
    for (int k = 0; k < steps; ++k) {
      Eigen::VectorXd driven = x;
      driven[3] += core::gaussian(rng, model.input_sigma_v);
      driven[4] += core::gaussian(rng, model.input_sigma_w);
      Eigen::VectorXd next = model.propagate(driven, dt);
      next.tail<2>() = x.tail<2>();  // the held ε does not persist in (v̄, ω̄)
      x = next + walk(rng);
      x[2] = wrapAngle(x[2]);
      ekfPredict(s, filter_model.transition(dt, s.x()));
      ekfUpdate(s, UnicycleModel::positionMeasurement(x.head<2>() + rn(rng), sigma));
    }
    const Eigen::VectorXd e = UnicycleModel::difference(x, s.x());
    stats.add(s.sqrtP().triangularView<Eigen::Lower>().solve(e).squaredNorm(), 5.0);
  }
  return stats;
}
}  // namespace

TEST(UnicycleModel, HeldInputNoiseToldIsConsistent) { expectConsistent(heldInputMc(true, 45)); }
TEST(UnicycleModel, HeldInputNoiseLeftOutIsOverconfident) { expectOverconfident(heldInputMc(false, 46)); }

// ---------------------------------------------------------------- LS trajectory prediction

namespace {
// A noise-free path generated by [K]'s recursion with constant accelerations: samples every T.
struct Path {
  std::vector<double> t, v, w;
  std::vector<Eigen::Vector2d> p;
  std::vector<double> theta;
};
Path recursionPath(double v0, double w0, double th0, double av, double aw, double T, int n) {
  Path path;
  Eigen::Vector2d p(1.0, -2.0);
  for (int h = 0; h < n; ++h) {
    const double ht = h * T;
    path.t.push_back(ht);
    path.v.push_back(v0 + av * ht);
    path.w.push_back(w0 + aw * ht);
    path.theta.push_back(th0 + w0 * ht + 0.5 * aw * ht * ht);
    path.p.push_back(p);
    p += path.v.back() * T * Eigen::Vector2d(std::cos(path.theta.back()), std::sin(path.theta.back()));
  }
  return path;
}
}  // namespace

TEST(UnicycleTrajectoryPredictor, ExactOnNoiseFreeConstantAccelerationPath) {
  const double T = 0.05, av = 0.4, aw = -0.3;
  const Path path = recursionPath(1.5, 0.6, 0.2, av, aw, T, 60);
  UnicycleTrajectoryPredictor pred(10);
  const int k = 30, m = 25;
  for (int i = k - 12; i <= k; ++i) pred.add(path.t[i], path.v[i], path.w[i]);
  EXPECT_EQ(pred.size(), 10u);  // window
  const UnicycleTrajectoryPredictor::Accelerations acc = pred.fitAccelerations();
  EXPECT_NEAR(acc.a_v, av, 1e-12);
  EXPECT_NEAR(acc.a_omega, aw, 1e-12);
  const Eigen::VectorXd xk = (Vec5() << path.p[k].x(), path.p[k].y(), path.theta[k], path.v[k], path.w[k]).finished();
  const std::vector<Eigen::Vector2d> out = pred.predict(xk, T, m);
  ASSERT_EQ(out.size(), static_cast<std::size_t>(m));
  for (int j = 1; j <= m; ++j) EXPECT_LT((out[j - 1] - path.p[k + j]).norm(), 1e-12) << j;
}

TEST(UnicycleTrajectoryPredictor, FirstOrderAccurateOnTheContinuousPath) {
  // Continuous path with constant accelerations, integrated finely; prediction error shrinks ~T.
  const double v0 = 1.5, w0 = 0.6, th0 = 0.2, av = 0.4, aw = -0.3, horizon = 1.0;
  auto truth = [&](double t) {
    Eigen::Vector2d p(0, 0);
    const int n = 20000;
    const double h = t / n;
    for (int i = 0; i < n; ++i) {
      const double s = (i + 0.5) * h;
      const double th = th0 + w0 * s + 0.5 * aw * s * s;
      p += (v0 + av * s) * h * Eigen::Vector2d(std::cos(th), std::sin(th));
    }
    return p;
  };
  const Eigen::Vector2d end = truth(horizon);
  double prev = std::numeric_limits<double>::infinity();
  for (double T : {0.1, 0.05, 0.025}) {
    UnicycleTrajectoryPredictor pred(5);
    for (int i = -4; i <= 0; ++i) pred.add(i * T, v0 + av * i * T, w0 + aw * i * T);
    const int m = static_cast<int>(std::lround(horizon / T));
    const Eigen::Vector2d p = pred.predict((Vec5() << 0, 0, th0, v0, w0).finished(), T, m).back();
    const double err = (p - end).norm();
    EXPECT_LT(err, 0.6 * prev);
    EXPECT_LT(err, 2.0 * T);
    prev = err;
  }
}

TEST(UnicycleTrajectoryPredictor, WindowAndBadInput) {
  expectInvalid([] { UnicycleTrajectoryPredictor p(1); }, "window");
  UnicycleTrajectoryPredictor p(3);
  EXPECT_EQ(p.fitAccelerations().a_v, 0.0);  // fewer than two samples
  p.add(0.0, 1.0, 0.0);
  expectInvalid([&] { p.add(0.0, 1.0, 0.0); }, "t = 0");
  expectInvalid([&] { p.add(0.1, kNaN, 0.0); }, "v");
  expectInvalid([&] { p.add(kNaN, 1.0, 0.0); }, "t");
  EXPECT_EQ(p.size(), 1u);  // unchanged by the rejected samples
  const Eigen::VectorXd x = (Vec5() << 0, 0, 0, 1, 0).finished();
  expectInvalid([&] { p.predict(x, 0.0, 3); }, "period T");
  expectInvalid([&] { p.predict(x, 0.1, 0); }, "steps m");
  expectInvalid([&] { p.predict(Eigen::VectorXd::Zero(4), 0.1, 3); }, "state estimate");
  for (int i = 1; i < 6; ++i) p.add(0.1 * i, 1.0 + 0.2 * i, 0.0);
  EXPECT_EQ(p.size(), 3u);
}
