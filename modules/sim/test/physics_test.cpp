#include <gtest/gtest.h>

#include <cmath>
#include <vector>

#include "viewline/core/error.h"
#include "viewline/core/frames.h"
#include "viewline/sim/physics.h"

using namespace viewline;
using namespace viewline::sim;

TEST(DragFlight, NoDragEqualsClosedFormParabola) {
  const FlightState s0{{0.0, -3.0, 1.0}, {1.0, 6.0, 7.0}};
  const DragFlight f(s0, 2.0, 1.5, DragBody::vacuum());
  EXPECT_EQ(f.dragPerMass(), 0.0);
  for (double tau = 0.0; tau <= 1.5; tau += 0.0371) {
    const Eigen::Vector3d p = f.state(2.0 + tau).p;
    EXPECT_LT((p - parabola(s0, tau)).norm(), 1e-10) << "tau = " << tau;
    EXPECT_LT((f.state(2.0 + tau).v - (s0.v + tau * gravityWorld())).norm(), 1e-10);
  }
}

TEST(DragFlight, VerticalDropMatchesAnalyticQuadraticDrag) {
  // From rest: v(t) = -vt tanh(g t / vt), z(t) = z0 - vt²/g ln cosh(g t / vt), vt = sqrt(g/k).
  const DragBody body = DragBody::ball5cm();
  const double k = body.dragPerMass();
  EXPECT_NEAR(k, 1.2 * 0.5 * M_PI * 0.025 * 0.025 / (2 * 0.057), 1e-12);
  const double vt = std::sqrt(kGravity / k);
  const DragFlight f({{0, 0, 100.0}, {0, 0, 0}}, 0.0, 4.0, body);
  for (double t : {0.5, 1.0, 2.0, 3.9}) {
    const FlightState s = f.state(t);
    EXPECT_NEAR(s.v.z(), -vt * std::tanh(kGravity * t / vt), 1e-8);
    EXPECT_NEAR(s.p.z(), 100.0 - vt * vt / kGravity * std::log(std::cosh(kGravity * t / vt)), 1e-8);
  }
}

TEST(DragFlight, DragDissipatesEnergyAndShortensTheThrow) {
  const FlightState s0{{0, 0, 1.0}, {8.0, 0.0, 8.0}};
  const DragFlight drag(s0, 0.0, 1.6, DragBody::ball5cm());
  const DragFlight vac(s0, 0.0, 1.6, DragBody::vacuum());
  double e_prev = 1e9;
  for (double t = 0.0; t <= 1.6; t += 0.05) {
    const FlightState s = drag.state(t);
    const double e = 0.5 * s.v.squaredNorm() + kGravity * s.p.z();  // per unit mass
    EXPECT_LT(e, e_prev + 1e-12);
    e_prev = e;
    const double e_vac = 0.5 * vac.state(t).v.squaredNorm() + kGravity * vac.state(t).p.z();
    EXPECT_NEAR(e_vac, 0.5 * s0.v.squaredNorm() + kGravity * s0.p.z(), 1e-9);
  }
  EXPECT_LT(drag.state(1.6).p.x(), vac.state(1.6).p.x() - 0.05);  // 8 m/s over 1.6 s: drag costs > 5 cm
  EXPECT_GT(drag.state(1.6).p.x(), 0.9 * vac.state(1.6).p.x());
}

TEST(DragFlight, BadInputNamesTheField) {
  DragBody b;
  b.mass = -1.0;
  try {
    b.dragPerMass();
    FAIL();
  } catch (const core::InvalidInput& e) {
    EXPECT_NE(std::string(e.what()).find("mass"), std::string::npos);
  }
  EXPECT_THROW(DragFlight({{0, 0, std::nan("")}, {0, 0, 0}}, 0.0, 1.0, DragBody{}), core::InvalidInput);
  EXPECT_THROW(DragFlight({}, 0.0, 0.0, DragBody{}), core::InvalidInput);
  const DragFlight f({}, 0.0, 1.0, DragBody{});
  EXPECT_THROW(f.state(1.5), core::InvalidInput);
  EXPECT_THROW(dartPose({0, 0, 0}, {0, 0, 0}), core::InvalidInput);
}

TEST(DragFlight, DartPointsAlongVelocity) {
  const Eigen::Isometry3d m = dartPose({1, 2, 3}, {3.0, 0.0, -1.0});
  EXPECT_LT((m.linear().col(2) - Eigen::Vector3d(3, 0, -1).normalized()).norm(), 1e-12);
  EXPECT_NEAR(m.linear().col(0).z(), 0.0, 1e-12);
  EXPECT_NEAR(m.linear().determinant(), 1.0, 1e-12);
}

TEST(TiltTable, RollingAccelerationIsFiveSeventhsGSinTheta) {
  TiltTableParams p;
  p.delay = 0.0;
  p.max_rate = 100.0;
  for (double theta : {0.05, 0.1, -0.2}) {
    TiltTableState s0;
    s0.tilt = Eigen::Vector2d(theta, 0.0);
    TiltTable table(p, s0);
    table.command(0.0, s0.tilt);
    const double a = 5.0 / 7.0 * kGravity * std::sin(theta);
    EXPECT_NEAR(table.rollingAcceleration(s0.tilt).norm(), std::abs(a), 1e-12);
    const double t = 0.1;
    table.advanceTo(t);
    EXPECT_NEAR(std::abs(table.state().p.y()), 0.5 * std::abs(a) * t * t, 1e-9);
    EXPECT_NEAR(table.state().p.x(), 0.0, 1e-12);
    EXPECT_NEAR(std::abs(table.state().v.y()), std::abs(a) * t, 1e-9);
    // Tilting about x lowers the table's +y side for positive angles: the ball rolls to -y.
    EXPECT_LT(table.state().p.y() * theta, 0.0);
  }
}

TEST(TiltTable, InelasticBordersClampPositionAndVelocity) {
  TiltTableParams p;
  p.delay = 0.0;
  TiltTableState s0;
  s0.tilt = Eigen::Vector2d(0.0, 0.2);
  s0.v = Eigen::Vector2d(0.0, 0.3);
  TiltTable table(p, s0);
  table.command(0.0, s0.tilt);
  table.advanceTo(3.0);
  const double lim = 0.5 * p.side - p.ball_radius;
  EXPECT_NEAR(table.limit(), lim, 1e-15);
  EXPECT_NEAR(std::abs(table.state().p.x()), lim, 1e-12);
  EXPECT_NEAR(table.state().v.x(), 0.0, 1e-12);
  // The initial y velocity carried the ball to the y border, where it stopped: a corner.
  EXPECT_NEAR(std::abs(table.state().p.y()), lim, 1e-12);
  EXPECT_EQ(table.state().v.y(), 0.0);
  table.command(3.0, Eigen::Vector2d(0.0, -0.2));
  table.advanceTo(6.0);
  EXPECT_NEAR(table.state().p.x(), -std::copysign(lim, table.rollingAcceleration({0.0, 0.2}).x()), 1e-12);
}

TEST(TiltTable, ActuatorDelayRateAndAngleLimits) {
  TiltTableParams p;
  p.delay = 0.05;
  p.max_rate = 1.0;
  p.max_angle = 0.15;
  TiltTable table(p);
  table.command(0.0, Eigen::Vector2d(0.3, -0.05));
  table.advanceTo(0.049);
  EXPECT_NEAR(table.state().tilt.x(), 0.0, 1e-12);
  table.advanceTo(0.15);
  EXPECT_NEAR(table.state().tilt.x(), 0.1, 1e-9);
  EXPECT_NEAR(table.state().tilt.y(), -0.05, 1e-9);
  table.advanceTo(1.0);
  EXPECT_NEAR(table.state().tilt.x(), 0.15, 1e-12);  // clamped to the angle limit
  // History interpolation.
  EXPECT_NEAR(table.stateAt(0.1).tilt.x(), 0.05, 1e-9);
  table.command(1.2, Eigen::Vector2d(0, 0));
  EXPECT_THROW(table.command(1.1, Eigen::Vector2d(0, 0)), core::InvalidInput);  // backwards
  EXPECT_THROW(table.advanceTo(0.5), core::InvalidInput);
  TiltTableParams bad;
  bad.ball_radius = -0.01;
  EXPECT_THROW(TiltTable{bad}, core::InvalidInput);
}

TEST(TiltTable, PushAddsVelocity) {
  TiltTableParams p;
  TiltTable table(p);
  table.push({0.1, 0.0});
  table.advanceTo(0.5);
  EXPECT_NEAR(table.state().p.x(), 0.05, 1e-12);
}

TEST(ScreenPath, AllShapesMoveAtConstantSpeed) {
  core::Rng rng = core::makeRng(7);
  for (PathShape shape : {PathShape::Rectangle, PathShape::Circle, PathShape::Random}) {
    ScreenPathParams p;
    p.shape = shape;
    p.speed = 0.25;
    p.duration = 60.0;
    const ScreenPath path(p, rng);
    const double dt = 1e-3;
    int at_speed = 0, n = 0;
    for (double t = 0.0; t < 30.0; t += 0.0173) {
      const double v = (path.position(t + dt) - path.position(t)).norm() / dt;
      EXPECT_LE(v, p.speed * (1 + 1e-6));  // chords across a corner are shorter, never longer
      if (std::abs(v - p.speed) < 1e-6 * p.speed + 1e-9) ++at_speed;
      EXPECT_NEAR(path.velocity(t).norm(), p.speed, 1e-6);
      ++n;
    }
    EXPECT_GT(at_speed, n * 9 / 10) << "shape " << static_cast<int>(shape);
  }
  ScreenPathParams rect;
  rect.width = 1.0;
  rect.height = 0.5;
  rect.speed = 1.0;
  const ScreenPath r(rect, rng);
  EXPECT_LT((r.position(0.0) - Eigen::Vector2d(-0.5, -0.25)).norm(), 1e-12);
  EXPECT_LT((r.position(1.0) - Eigen::Vector2d(0.5, -0.25)).norm(), 1e-12);
  EXPECT_LT((r.position(3.0) - r.position(0.0)).norm(), 1e-12);  // perimeter 3 m: closed loop
  // Corners at the vertices: 1, 1.5, 2.5, 3 (back at the start), 4, ... s.
  const std::vector<double> corners = r.cornerTimes(4.2);
  ASSERT_EQ(corners.size(), 5u);
  const double expected[] = {1.0, 1.5, 2.5, 3.0, 4.0};
  for (std::size_t i = 0; i < 5; ++i) EXPECT_NEAR(corners[i], expected[i], 1e-12);
  for (double c : corners) {  // the direction changes there
    const Eigen::Vector2d before = r.velocity(c - 1e-3), after = r.velocity(c + 1e-3);
    EXPECT_GT((before - after).norm(), 0.5);
  }
  ScreenPathParams random;
  random.shape = PathShape::Random;
  random.speed = 0.15;
  random.duration = 30.0;
  const ScreenPath rp(random, rng);
  const std::vector<double> rc = rp.cornerTimes(30.0);
  ASSERT_GE(rc.size(), 3u);
  for (std::size_t i = 0; i < rc.size(); ++i) {
    EXPECT_GT(rc[i], i ? rc[i - 1] : 0.0);
    EXPECT_GT((rp.velocity(rc[i] - 1e-3) - rp.velocity(rc[i] + 1e-3)).norm(), 1e-4);
  }
  ScreenPathParams circle;
  circle.shape = PathShape::Circle;
  EXPECT_TRUE(ScreenPath(circle, rng).cornerTimes(100.0).empty());
  ScreenPathParams bad;
  bad.speed = 0.0;
  EXPECT_THROW(ScreenPath(bad, rng), core::InvalidInput);
}

TEST(ScreenPath, RoundedRandomPathKeepsItsSpeedAndBoundsItsCurvature) {
  ScreenPathParams p;
  p.shape = PathShape::Random;
  p.speed = 0.15;
  p.width = 0.8;
  p.height = 0.43;
  p.duration = 60.0;
  p.corner_radius = 0.1;
  core::Rng rng_a = core::makeRng(3), rng_b = core::makeRng(3);
  const ScreenPath rounded(p, rng_a);
  ScreenPathParams sharp_p = p;
  sharp_p.corner_radius = 0.0;
  const ScreenPath sharp(sharp_p, rng_b);  // other waypoints (the rounded path redraws turns that do not fit)
  const double dt = 1e-3;
  double max_step_turn = 0.0, max_step_turn_sharp = 0.0;
  int on_full_radius = 0;
  const auto stepTurn = [dt](const ScreenPath& path, double t) {
    const Eigen::Vector2d v0 = path.velocity(t), v1 = path.velocity(t + dt);
    return std::abs(std::atan2(v0.x() * v1.y() - v0.y() * v1.x(), v0.dot(v1)));
  };
  for (double t = 0.0; t < 55.0; t += 0.0173) {
    const Eigen::Vector2d x = rounded.position(t);
    EXPECT_NEAR((rounded.position(t + dt) - x).norm() / dt, p.speed, 1e-5 * p.speed) << t;  // constant speed
    EXPECT_LE(std::abs(x.x()), 0.4 + 1e-9);  // inside the box (an arc stays inside its corner's triangle)
    EXPECT_LE(std::abs(x.y()), 0.215 + 1e-9);
    const double turn = stepTurn(rounded, t);
    max_step_turn = std::max(max_step_turn, turn);
    if (std::abs(turn / dt - p.speed / p.corner_radius) < 1e-3 * p.speed / p.corner_radius) ++on_full_radius;
  }
  for (double c : sharp.cornerTimes(55.0)) max_step_turn_sharp = std::max(max_step_turn_sharp, stepTurn(sharp, c - 0.5 * dt));
  // The heading is continuous: within dt = 1 ms it turns by at most speed dt / r (every arc has radius r),
  // never by the whole turn as at a sharp vertex.
  EXPECT_LT(max_step_turn, 1.001 * p.speed * dt / p.corner_radius);
  EXPECT_GT(max_step_turn_sharp, 0.3);
  EXPECT_GT(on_full_radius, 20);  // on the arcs: turn rate speed / r
  const std::vector<double> mid = rounded.cornerTimes(55.0);
  ASSERT_GE(mid.size(), 5u);
  for (double t : mid) {  // the middle of each arc: turning there
    const Eigen::Vector2d v0 = rounded.velocity(t - 0.05), v1 = rounded.velocity(t + 0.05);
    EXPECT_GT((v1 - v0).norm(), 1e-3) << t;
  }
  ScreenPathParams bad = p;
  bad.corner_radius = -0.1;
  EXPECT_THROW(ScreenPath(bad, rng_a), core::InvalidInput);
  bad.corner_radius = 0.1;
  bad.shape = PathShape::Rectangle;
  EXPECT_THROW(ScreenPath(bad, rng_a), core::InvalidInput);  // only the random path is rounded
}

TEST(GroundTarget, FollowsKimProfilesInSiUnits) {
  EXPECT_NEAR(GroundTarget::nominal(GroundProfile::Capture, 0.0).x(), 0.60, 1e-12);
  EXPECT_NEAR(GroundTarget::nominal(GroundProfile::Capture, 0.0).y(), 0.7 * std::sin(M_PI / 1.5), 1e-12);
  EXPECT_NEAR(GroundTarget::nominal(GroundProfile::FilterTest, 50.0).x(), 0.15 * (std::sin(1.0) + 1), 1e-12);
  EXPECT_NEAR(GroundTarget::nominal(GroundProfile::FilterTest, 50.0).y(), 0.7 * std::cos(0.5), 1e-12);
  GroundTargetParams p;
  p.noise = false;
  p.duration = 20.0;
  core::Rng rng = core::makeRng(1);
  const GroundTarget g(p, rng);
  EXPECT_LT((Eigen::Vector2d(g.state(0).x, g.state(0).y) - p.start).norm(), 1e-12);
  for (double t = 0.05; t < 19.0; t += 0.5) {
    const double k = std::floor(t / p.profile_period + 1e-9);
    const Eigen::Vector2d u = GroundTarget::nominal(p.profile, k);
    const GroundState a = g.state(t), b = g.state(t + 0.01);
    const double v = std::hypot(b.x - a.x, b.y - a.y) / 0.01;
    if (std::floor((t + 0.01) / p.profile_period + 1e-9) == k) {
      EXPECT_NEAR(v, u.x(), 1e-5) << t;  // chord of the arc: v (1 - (ω dt)²/24)
      EXPECT_NEAR((b.theta - a.theta) / 0.01, u.y(), 1e-6) << t;
    }
  }
  // Noise: reproducible per seed, different across seeds.
  p.noise = true;
  core::Rng r1 = core::makeRng(5), r2 = core::makeRng(5), r3 = core::makeRng(6);
  const GroundTarget n1(p, r1), n2(p, r2), n3(p, r3);
  EXPECT_EQ(n1.state(15.0).x, n2.state(15.0).x);
  EXPECT_NE(n1.state(15.0).x, n3.state(15.0).x);
  EXPECT_THROW(g.state(25.0), core::InvalidInput);
}
