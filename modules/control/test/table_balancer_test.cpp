#include "viewline/control/table_balancer.h"

#include <gtest/gtest.h>

#include <cmath>

#include "viewline/core/error.h"
#include "viewline/robots/table_tilt.h"

using viewline::control::TableBalancer;
using viewline::control::TableBalancerConfig;
using viewline::control::TiltRamp;

namespace {

struct StepResult {
  double overshoot_pct = 0.0;
  double settling_s = 0.0;
  double final_error = 0.0;
  double max_angle = 0.0;
  double max_command_rate = 0.0;
};

// The true plant: ball rolling on the table tilted by the wrist (1 ms steps, exact trigonometry),
// state feedback every T from the true state, ramps sent as 1 kHz position commands.
StepResult simulateStep(const TableBalancerConfig& cfg, double step, double duration,
                        const Eigen::Vector2d& push = Eigen::Vector2d::Zero()) {
  TableBalancer ctl(cfg);
  viewline::robots::TableTiltLimits lim;
  lim.max_angle = cfg.max_angle;
  lim.max_rate = cfg.max_rate;
  lim.delay = cfg.delay;
  viewline::robots::SimulatedTableTilt wrist(lim);
  const double c = 5.0 / 7.0 * cfg.gravity;
  Eigen::Vector2d p(-0.5 * step, 0.0), v(0.0, 0.0);
  const Eigen::Vector2d ref(0.5 * step, 0.0);
  const double dt = 1e-3;
  const int ticks_per_period = static_cast<int>(std::lround(cfg.period / dt));
  TiltRamp ramp;
  ramp.period = cfg.period;
  StepResult r;
  double last_outside = 0.0;
  Eigen::Vector2d last_cmd = Eigen::Vector2d::Zero();
  const int n = static_cast<int>(std::lround(duration / dt));
  for (int i = 0; i < n; ++i) {
    const double t = i * dt;
    if (i % ticks_per_period == 0) ramp = ctl.update(t, p, v, ref);
    if (i == n / 2 && push.norm() > 0.0) v += push;
    const Eigen::Vector2d cmd = ramp.commandAt(t);
    r.max_angle = std::max(r.max_angle, cmd.cwiseAbs().maxCoeff());
    if (i > 0) r.max_command_rate = std::max(r.max_command_rate, (cmd - last_cmd).cwiseAbs().maxCoeff() / dt);
    last_cmd = cmd;
    wrist.command(t, cmd);
    const Eigen::Vector2d th = wrist.actual(t + dt);
    const Eigen::Vector2d a(c * std::cos(th.x()) * std::sin(th.y()), -c * std::sin(th.x()));
    p += v * dt + 0.5 * a * dt * dt;
    v += a * dt;
    const double e = p.x() - ref.x();
    r.overshoot_pct = std::max(r.overshoot_pct, 100.0 * e / step);
    if (std::abs(e) > 0.02 * step || std::abs(p.y()) > 0.02 * step) last_outside = t + dt;
  }
  r.settling_s = last_outside;
  r.final_error = (p - ref).norm();
  return r;
}

}  // namespace

TEST(TableBalancer, GainStabilisesTheDelayedModel) {
  for (double delay : {0.0, 0.02, 0.03, 0.055}) {
    TableBalancerConfig cfg;
    cfg.delay = delay;
    TableBalancer ctl(cfg);
    EXPECT_LT(ctl.closedLoopSpectralRadius(), 1.0) << "delay " << delay;
    EXPECT_EQ(ctl.gain().size(), 4 + static_cast<int>(std::floor(delay / cfg.period + 1e-9)) + 1);
  }
}

TEST(TableBalancer, TenCentimetreStepMeetsOvershootAndSettlingOnTheTruePlant) {
  TableBalancerConfig cfg;
  cfg.delay = 0.03;  // 10 ms latency + 20 ms wrist delay: a fractional delay
  const StepResult r = simulateStep(cfg, 0.10, 6.0);
  EXPECT_LE(r.overshoot_pct, 10.0);
  EXPECT_LE(r.settling_s, 2.0);
  EXPECT_LT(r.final_error, 1e-4);
}

TEST(TableBalancer, NeverCommandsPastTheLimits) {
  TableBalancerConfig cfg;
  cfg.max_angle = 0.05;  // tight limits so that both saturate during a large step and a push
  cfg.max_rate = 0.3;
  cfg.q_integral = 50.0;
  const StepResult r = simulateStep(cfg, 0.2, 20.0, Eigen::Vector2d(0.3, -0.3));
  EXPECT_LE(r.max_angle, cfg.max_angle + 1e-12);
  EXPECT_LE(r.max_command_rate, cfg.max_rate * (1.0 + 1e-9));
  EXPECT_GT(r.max_angle, 0.99 * cfg.max_angle);  // the limit was actually reached
  EXPECT_LT(r.final_error, 2e-3);                // and the loop still recovered
}

TEST(TableBalancer, IntegralActionKeepsStabilityAndAnglesMapToAxes) {
  TableBalancerConfig cfg;
  cfg.q_integral = 200.0;
  TableBalancer ctl(cfg);
  EXPECT_LT(ctl.closedLoopSpectralRadius(), 1.0);
  // Ball at +x of the set point: the table must tilt so that the ball accelerates towards -x,
  // i.e. θy decreases (a_x = c sin θy); ball at +y: θx increases (a_y = -c sin θx).
  TiltRamp r = ctl.update(0.0, Eigen::Vector2d(0.05, 0.0), Eigen::Vector2d::Zero(), Eigen::Vector2d::Zero());
  EXPECT_LT(r.rate.y(), 0.0);
  EXPECT_NEAR(r.rate.x(), 0.0, 1e-12);
  ctl.reset();
  r = ctl.update(0.0, Eigen::Vector2d(0.0, 0.05), Eigen::Vector2d::Zero(), Eigen::Vector2d::Zero());
  EXPECT_GT(r.rate.x(), 0.0);
}

TEST(TableBalancer, RejectsBadConfig) {
  TableBalancerConfig cfg;
  cfg.r_rate = 0.0;
  EXPECT_THROW(TableBalancer{cfg}, viewline::core::InvalidInput);
  cfg = TableBalancerConfig{};
  cfg.delay = -0.01;
  EXPECT_THROW(TableBalancer{cfg}, viewline::core::InvalidInput);
  TableBalancer ok{TableBalancerConfig{}};
  EXPECT_THROW(ok.update(0.0, Eigen::Vector2d(NAN, 0.0), Eigen::Vector2d::Zero(), Eigen::Vector2d::Zero()),
               viewline::core::InvalidInput);
}

// A wrist that did not take the last ramps holds its tilt: after hold() the model's tilt and the
// next ramp's start are that tilt (no step for the wrist), the next ramp stays within the limits,
// and the integral is kept (frozen), not reset.
TEST(TableBalancer, HoldPutsTheHeldTiltIntoTheModelAndKeepsTheIntegral) {
  TableBalancerConfig cfg;
  cfg.q_integral = 200.0;
  cfg.delay = 0.03;
  TableBalancer ctl(cfg);
  // 0.01 m off the set point, inside integral_band: the integral grows over these updates.
  for (int k = 0; k < 20; ++k) ctl.update(0.02 * k, Eigen::Vector2d(0.01, -0.01), Eigen::Vector2d::Zero(), Eigen::Vector2d::Zero());
  const Eigen::Vector2d held(0.03, -0.02);
  ASSERT_GT((ctl.commandedTilt() - held).norm(), 1e-3);  // the refused ramps went elsewhere
  TableBalancer fresh(cfg);
  fresh.reset(held);
  ctl.hold(held);
  EXPECT_EQ(ctl.modelTilt(), held);
  EXPECT_EQ(ctl.commandedTilt(), held);
  const Eigen::Vector2d p(0.01, -0.01), v = Eigen::Vector2d::Zero(), sp = Eigen::Vector2d::Zero();
  const TiltRamp r = ctl.update(0.4, p, v, sp);
  EXPECT_EQ(r.start, held);
  EXPECT_LE(r.rate.cwiseAbs().maxCoeff(), cfg.max_rate);
  EXPECT_LE(r.end().cwiseAbs().maxCoeff(), cfg.max_angle + 1e-12);
  // Same state, same tilt, nothing in flight: only the kept integral tells them apart.
  const TiltRamp rf = fresh.update(0.4, p, v, sp);
  EXPECT_GT((r.rate - rf.rate).norm(), 1e-6);
  EXPECT_THROW(ctl.hold(Eigen::Vector2d(NAN, 0.0)), viewline::core::InvalidInput);
}
