// Ball rolling on a tilting table with disturbance states ([M] §4.2).
#include <gtest/gtest.h>

#include <Eigen/Geometry>
#include <cmath>
#include <limits>

#include "monte_carlo.h"
#include "viewline/estimation/models/rolling_ball.h"

using namespace viewline;
using namespace viewline::estimation;
using test::expectConsistent;
using test::expectInvalid;
using test::expectOverconfident;

namespace {
const double kNaN = std::numeric_limits<double>::quiet_NaN();
const Eigen::Vector3d kGravity(0.0, 0.0, -9.81);  // world z up
double maxAbs(const Eigen::MatrixXd& m) { return m.cwiseAbs().maxCoeff(); }

// Table tilted by `angle` about a horizontal world axis: world_R_table = R(axis, angle).
Eigen::Matrix3d tableRWorld(const Eigen::Vector3d& axis, double angle) {
  return Eigen::AngleAxisd(angle, axis.normalized()).toRotationMatrix().transpose();
}
}  // namespace

TEST(RollingBall, AccelerationIsFiveSeventhsGSinTheta) {
  for (double theta : {0.0, 0.01, 0.1, 0.3, -0.2}) {
    for (const Eigen::Vector3d& axis : {Eigen::Vector3d(1, 0, 0), Eigen::Vector3d(0, 1, 0), Eigen::Vector3d(1, 1, 0),
                                        Eigen::Vector3d(-0.3, 0.8, 0)}) {
      const Eigen::Vector2d a = rollingBallAcceleration(tableRWorld(axis, theta), kGravity);
      EXPECT_NEAR(a.norm(), 5.0 / 7.0 * 9.81 * std::abs(std::sin(theta)), 1e-12);
      // Downhill: perpendicular to the tilt axis (expressed in table coordinates).
      const Eigen::Vector3d axis_t = tableRWorld(axis, theta) * axis.normalized();
      EXPECT_NEAR(a.dot(axis_t.head<2>()), 0.0, 1e-12);
    }
  }
  // Tilt about x by +θ lifts +y: the ball rolls towards −y.
  const Eigen::Vector2d a = rollingBallAcceleration(tableRWorld(Eigen::Vector3d::UnitX(), 0.1), kGravity);
  EXPECT_NEAR(a.x(), 0.0, 1e-15);
  EXPECT_LT(a.y(), 0.0);
}

TEST(RollingBall, TableRotationFromCameraPoses) {
  // Camera looking down at the ground, table tilted in the world: c_R_table = c_R_world · world_R_table.
  const Eigen::Matrix3d c_R_world =
      (Eigen::AngleAxisd(2.5, Eigen::Vector3d::UnitX()) * Eigen::AngleAxisd(0.4, Eigen::Vector3d::UnitZ())).toRotationMatrix();
  const Eigen::Matrix3d world_R_table = Eigen::AngleAxisd(0.2, Eigen::Vector3d(1, -2, 0).normalized()).toRotationMatrix();
  const Eigen::Matrix3d table_R_world = tableRotationInWorld(c_R_world * world_R_table, c_R_world);
  EXPECT_LT(maxAbs(table_R_world - world_R_table.transpose()), 1e-12);
  EXPECT_NEAR(rollingBallAcceleration(table_R_world, kGravity).norm(), 5.0 / 7.0 * 9.81 * std::sin(0.2), 1e-12);
  expectInvalid([&] { tableRotationInWorld(2.0 * c_R_world, c_R_world); }, "c_R_table");
  expectInvalid([&] { rollingBallAcceleration(Eigen::Matrix3d::Constant(kNaN), kGravity); }, "table_R_world");
}

TEST(RollingBall, TransitionClosedForm) {
  RollingBallModel model;
  model.beta = 2.0;
  model.sigma_w = 1.0;
  const double dt = 0.02, b = model.beta, e = std::exp(-b * dt);
  const Eigen::Vector2d a(0.3, -0.7);
  const LinearTransition tr = model.transition(dt, a);
  for (int i = 0; i < 2; ++i) {
    const int p = 2 * i, v = 2 * i + 1, w = 4 + i;
    EXPECT_NEAR(tr.Phi(p, v), dt, 1e-15);
    EXPECT_NEAR(tr.Phi(p, w), (b * dt - 1.0 + e) / (b * b), 1e-14);
    EXPECT_NEAR(tr.Phi(v, w), (1.0 - e) / b, 1e-14);
    EXPECT_NEAR(tr.Phi(w, w), e, 1e-15);
    EXPECT_NEAR(tr.Gamma(p, i), dt * dt / 2.0, 1e-15);
    EXPECT_NEAR(tr.Gamma(v, i), dt, 1e-15);
    EXPECT_NEAR(tr.Gamma(w, i), 0.0, 1e-15);
    // The white part alone gives velocity variance σw² dt; w2's variance 2βσw² ∫e^{−2βs} = σw²(1 − e^{−2β dt}).
    EXPECT_NEAR(tr.Q(w, w), model.sigma_w * model.sigma_w * (1.0 - e * e), 1e-13);
    EXPECT_GT(tr.Q(v, v), model.sigma_w * model.sigma_w * dt);
  }
  EXPECT_EQ(tr.u, a);
  // Axes decoupled.
  EXPECT_EQ(tr.Phi(0, 2), 0.0);
  EXPECT_EQ(tr.Q(0, 2), 0.0);
  // Long interval: w2 forgets its initial value and reaches its stationary variance σw².
  EXPECT_NEAR(model.transition(20.0, a).Q(4, 4), 1.0, 1e-12);
}

TEST(RollingBall, MeasurementSelectsPositions) {
  const RollingBallModel model;
  const LinearMeasurement m = model.measurement(Eigen::Vector2d(0.01, -0.02));
  Eigen::MatrixXd C = Eigen::MatrixXd::Zero(2, 6);
  C(0, 0) = C(1, 2) = 1.0;
  EXPECT_EQ(m.C, C);
  EXPECT_NEAR(m.R(0, 0), 0.005 * 0.005, 1e-18);
  EXPECT_EQ(m.R(0, 1), 0.0);
}

TEST(RollingBall, ClampAtTheBorderIsInelastic) {
  const RollingBallModel model;  // L = 0.3, r = 0.025: limit 0.125
  EXPECT_NEAR(model.positionLimit(), 0.125, 1e-15);
  Eigen::VectorXd x(6);
  x << 0.13, 0.4, -0.05, -0.2, 0.1, 0.2;
  EXPECT_TRUE(model.clamp(x));
  EXPECT_EQ(x[0], 0.125);
  EXPECT_EQ(x[1], 0.0);     // that velocity component stops
  EXPECT_EQ(x[2], -0.05);   // the other axis untouched
  EXPECT_EQ(x[3], -0.2);
  EXPECT_EQ(x[4], 0.1);
  x << 0.0, 0.1, -0.2, -0.3, 0.0, 0.0;
  EXPECT_TRUE(model.clamp(x));
  EXPECT_EQ(x[2], -0.125);
  EXPECT_EQ(x[3], 0.0);
  EXPECT_EQ(x[1], 0.1);
  Eigen::VectorXd inside(6);
  inside << 0.1, 1.0, -0.125, -1.0, 0.0, 0.0;
  const Eigen::VectorXd before = inside;
  EXPECT_FALSE(model.clamp(inside));
  EXPECT_EQ(inside, before);
}

TEST(RollingBall, NStepPredictionStopsAtTheBorder) {
  const RollingBallModel model;
  const double dt = 0.02;
  // Ball at the centre rolling towards +x at 1 m/s on a table tilted so that it accelerates towards +x.
  Eigen::VectorXd x(6);
  x << 0.0, 1.0, 0.0, 0.0, 0.0, 0.0;
  const Eigen::Vector2d a(2.0, 0.0);
  const std::vector<Eigen::Vector2d> pred = model.predictPositions(x, dt, a);
  ASSERT_EQ(pred.size(), 10u);  // N = 10 by default
  // Free motion until the border, then stuck at the limit.
  const LinearTransition tr = model.transition(dt, a);
  Eigen::VectorXd free = x;
  bool reached = false;
  for (std::size_t k = 0; k < pred.size(); ++k) {
    free = tr.Phi * free + tr.Gamma * tr.u;
    if (free[0] >= 0.125) reached = true;
    EXPECT_LE(pred[k].x(), 0.125);
    if (!reached) EXPECT_NEAR(pred[k].x(), free[0], 1e-12) << k;
    else EXPECT_EQ(pred[k].x(), 0.125) << k;
    EXPECT_EQ(pred[k].y(), 0.0);
  }
  EXPECT_TRUE(reached);
  EXPECT_EQ(model.predictPositions(x, dt, a, 25).size(), 25u);
}

TEST(RollingBall, KeepsPredictingWithTheClampWhileNotDetected) {
  const RollingBallModel model;
  Eigen::VectorXd x0(6);
  x0 << 0.1, 0.5, -0.1, -0.5, 0.0, 0.0;
  StateEstimate s(x0, 1e-4 * Eigen::MatrixXd::Identity(6, 6));
  const Eigen::Vector2d a = rollingBallAcceleration(tableRWorld(Eigen::Vector3d(1, 1, 0), 0.05), kGravity);
  for (int k = 0; k < 100; ++k) {  // 2 s without a detection
    model.predictClamped(s, 0.02, a);
    EXPECT_LE(std::abs(s.x()[0]), model.positionLimit());
    EXPECT_LE(std::abs(s.x()[2]), model.positionLimit());
  }
  EXPECT_NEAR(s.t(), 2.0, 1e-12);
  EXPECT_GT(s.P()(0, 0), 1e-4);  // uncertainty grows while undetected
}

TEST(RollingBall, StationaryGainMatchesConvergedTimeVaryingFilter) {
  const RollingBallModel model;  // [M]'s best tuning σw = 1, σv = 0.005
  const double dt = 0.02;
  const StationaryFilter sf = model.stationaryFilter(dt);
  StateEstimate s(Eigen::VectorXd::Zero(6), 0.01 * Eigen::MatrixXd::Identity(6, 6));
  const LinearMeasurement m = model.measurement(Eigen::Vector2d::Zero());
  const Eigen::Vector2d a(0.2, -0.1);  // the tilt does not change the gain
  for (int k = 0; k < 3000; ++k) {
    predict(s, model.transition(dt, a));
    if (k < 2999) update(s, m);
  }
  const Eigen::MatrixXd S = innovationCovariance(s, m.C, m.R);
  const Eigen::MatrixXd K = s.P() * m.C.transpose() * S.inverse();  // reference only
  EXPECT_LT(maxAbs(K - sf.Kf), 1e-6 * maxAbs(sf.Kf));
  EXPECT_LT(maxAbs(s.P() - sf.P), 1e-6 * maxAbs(sf.P));

  // The stationary filter tracks a simulated run as well as the time-varying one (after start-up).
  // The simulated ball is not clamped, so neither is the filter (a table larger than the run).
  RollingBallModel big = model;
  big.table_side = 1e3;
  core::Rng rng(core::deriveSeed(7, 0));
  const LinearTransition tr = model.transition(dt, a);
  const test::NoiseSampler qn(tr.Q), rn(m.R);
  Eigen::VectorXd x = Eigen::VectorXd::Zero(6), xs = x;
  StateEstimate tv(x, 0.01 * Eigen::MatrixXd::Identity(6, 6));
  double e_st = 0.0, e_tv = 0.0;
  for (int k = 0; k < 400; ++k) {
    x = tr.Phi * x + tr.Gamma * tr.u + qn(rng);
    const Eigen::Vector2d y = Eigen::Vector2d(x[0], x[2]) + rn(rng);
    xs = big.stationaryStep(sf, tr, xs, y);
    predict(tv, tr);
    LinearMeasurement mk = m;
    mk.y = y;
    update(tv, mk);
    if (k >= 100) {
      e_st += std::hypot(xs[0] - x[0], xs[2] - x[2]);
      e_tv += std::hypot(tv.x()[0] - x[0], tv.x()[2] - x[2]);
    }
  }
  EXPECT_NEAR(e_st / e_tv, 1.0, 0.02);
}

TEST(RollingBall, BestTuningFollowsMeasurementsTheOtherLags) {
  // [M]: σw = 1, σv = 0.005 stays close to the measurements; σw = σv = 1 lags behind.
  RollingBallModel best, laggy;
  laggy.sigma_v = 1.0;
  const double dt = 0.02;
  core::Rng rng(core::deriveSeed(8, 0));
  const test::NoiseSampler rn(0.005 * 0.005 * Eigen::MatrixXd::Identity(2, 2));
  StateEstimate sb(Eigen::VectorXd::Zero(6), 1e-4 * Eigen::MatrixXd::Identity(6, 6)), sl = sb;
  double lag_best = 0.0, lag_laggy = 0.0;
  for (int k = 0; k < 150; ++k) {
    // Table tilting back and forth: the true ball oscillates along x (a known input is not given to
    // the filters, as when the control action is unknown).
    const double t = (k + 1) * dt;
    const Eigen::Vector2d p(0.08 * std::sin(2.0 * t), 0.0);
    const Eigen::Vector2d y = p + rn(rng);
    for (auto [s, m] : {std::pair<StateEstimate*, const RollingBallModel*>{&sb, &best}, {&sl, &laggy}}) {
      m->predictClamped(*s, dt, Eigen::Vector2d::Zero());
      update(*s, m->measurement(y));
    }
    if (k >= 50) {
      lag_best += std::abs(sb.x()[0] - p.x());
      lag_laggy += std::abs(sl.x()[0] - p.x());
    }
  }
  EXPECT_LT(lag_best / 100.0, 0.005);   // within the measurement noise
  EXPECT_GT(lag_laggy / 100.0, 0.01);   // visibly behind
}

TEST(RollingBall, BadInputNamesTheField) {
  const Eigen::Vector2d a(0.1, 0.0);
  expectInvalid([&] { RollingBallModel().transition(0.0, a); }, "dt");
  expectInvalid([&] { RollingBallModel().transition(kNaN, a); }, "dt");
  expectInvalid([&] { RollingBallModel().transition(0.02, Eigen::Vector2d(kNaN, 0.0)); }, "a_xy");
  expectInvalid([&] { RollingBallModel m; m.sigma_w = kNaN; m.transition(0.02, a); }, "RollingBallModel.sigma_w");
  expectInvalid([&] { RollingBallModel m; m.beta = 0.0; m.transition(0.02, a); }, "RollingBallModel.beta");
  expectInvalid([&] { RollingBallModel m; m.sigma_v = -1.0; m.measurement(a); }, "RollingBallModel.sigma_v");
  expectInvalid([&] { RollingBallModel m; m.table_side = 0.04; m.positionLimit(); }, "RollingBallModel.table_side");
  expectInvalid([&] { RollingBallModel m; m.prediction_steps = 0; m.transition(0.02, a); }, "RollingBallModel.prediction_steps");
  expectInvalid([&] { RollingBallModel().measurement(Eigen::Vector2d(kNaN, 0.0)); }, "measurement y");
  expectInvalid([&] { RollingBallModel().predictPositions(Eigen::VectorXd::Zero(4), 0.02, a); }, "state");
}

namespace {
// Monte Carlo over the linear time-varying model: the table tilts sinusoidally, so the input
// (and the transition) changes every frame. Table large enough that the clamp never acts (the
// clamp is a nonlinearity outside the Gaussian model; it is tested above).
test::LinearMcSetup rollingSetup() {
  RollingBallModel model;  // σw = 1, σv = 0.005, β = 1
  model.table_side = 100.0;
  const double dt = 0.02;
  test::LinearMcSetup s;
  s.transition = [model, dt](int k) {
    const double theta = 0.05 * std::sin(0.8 * k * dt);
    const Eigen::Vector3d axis(std::cos(0.3 * k * dt), std::sin(0.3 * k * dt), 0.0);
    return model.transition(dt, rollingBallAcceleration(tableRWorld(axis, theta), kGravity));
  };
  s.measurement = [model] { return model.measurement(Eigen::Vector2d::Zero()); };
  s.m0 = Eigen::VectorXd::Zero(6);
  // Prior: 1 cm, 0.1 m/s, and w2 at its stationary variance σw².
  s.P0 = Eigen::VectorXd((Eigen::VectorXd(6) << 1e-4, 0.01, 1e-4, 0.01, 1.0, 1.0).finished()).asDiagonal();
  s.steps = 50;
  s.runs = 400;
  s.seed = 31;
  return s;
}
}  // namespace

TEST(RollingBall, MonteCarloNeesConsistent) { expectConsistent(test::runLinearMc(rollingSetup(), 1.0)); }
TEST(RollingBall, TooSmallProcessNoiseDetected) { expectOverconfident(test::runLinearMc(rollingSetup(), 0.1)); }
