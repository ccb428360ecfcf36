// Interception planner: reaches a reachable crossing in time, decides early and goes home on an
// unreachable one, replans without position/velocity jumps, respects the limits.
#include <gtest/gtest.h>

#include <cmath>

#include "viewline/planning/catch_planner.h"

using namespace viewline;
using planning::CatchPhase;
using planning::CatchPlanner;
using planning::CatchPlannerConfig;
using Vector6 = Eigen::Matrix<double, 6, 1>;

namespace {

CatchPlannerConfig config() {
  CatchPlannerConfig c;
  c.model.kind = planning::FlightModel::Ballistic;
  c.home = Eigen::Vector3d(0, 0, 1.2);
  c.latency = 0.008;
  c.commit_sigma = 0.01;
  c.commit_min_updates = 2;
  return c;
}

// A ballistic flight that crosses x = 0 at time tc at (0, y, z).
Vector6 flightState(double t, double tc, double y, double z) {
  const Eigen::Vector3d g(0, 0, -9.81);
  const Eigen::Vector3d v_c(-8.0, 0.2, -1.0);  // velocity at the crossing
  const double tau = t - tc;                   // negative before the crossing
  Vector6 x;
  x.head<3>() = Eigen::Vector3d(0, y, z) + v_c * tau + 0.5 * g * tau * tau;
  x.tail<3>() = v_c + g * tau;
  return x;
}

estimation::StateEstimate estimate(double t, const Vector6& x, double sigma_p, double sigma_v) {
  Eigen::Matrix<double, 6, 6> P = Eigen::Matrix<double, 6, 6>::Zero();
  P.diagonal() << Eigen::Vector3d::Constant(sigma_p * sigma_p), Eigen::Vector3d::Constant(sigma_v * sigma_v);
  return estimation::StateEstimate(x, P, t);
}

struct PlannedRun {
  Eigen::Vector3d at_crossing;
  double max_v = 0, max_dv = 0, max_dp = 0;
  bool gave_up = false;
  std::optional<double> commit;
  Eigen::Vector3d final_p;
};

// 100 Hz updates from t = 0 until the crossing at tc, uncertainty shrinking; 1 kHz set points.
PlannedRun simulate(CatchPlanner& pl, double tc, double y, double z) {
  PlannedRun r;
  pl.reset(0.0, pl.config().home);
  robots::CartesianState prev = pl.setpoint(0.0);
  const double dt = 1e-3;
  for (int k = 1; k < 2500; ++k) {
    const double t = k * dt;
    if (k % 10 == 0 && t < tc - 0.02) {
      const double sp = 0.2 * std::exp(-t / 0.05) + 0.001;  // m
      pl.update(t, estimate(t, flightState(t, tc, y, z), sp, 10 * sp));
    }
    const auto s = pl.setpoint(t);
    r.max_v = std::max(r.max_v, s.v.cwiseAbs().maxCoeff());
    r.max_dv = std::max(r.max_dv, (s.v - prev.v).cwiseAbs().maxCoeff() / dt);
    r.max_dp = std::max(r.max_dp, (s.p - prev.p).cwiseAbs().maxCoeff() / dt);
    if (std::abs(t - (tc - pl.config().latency)) < 0.5 * dt) r.at_crossing = s.p;
    prev = s;
  }
  r.gave_up = pl.giveUpTime().has_value();
  r.commit = pl.commitTime();
  r.final_p = prev.p;
  return r;
}

}  // namespace

TEST(CatchPlanner, ReachesAReachableCrossingInTimeAndGoesHome) {
  CatchPlanner pl(config());
  const double tc = 0.6;
  const PlannedRun r = simulate(pl, tc, 0.15, 1.05);
  EXPECT_FALSE(r.gave_up);
  ASSERT_TRUE(r.commit);
  EXPECT_LT(*r.commit, 0.3);
  // The box (set point acting at tc) is at the crossing point.
  EXPECT_LT((r.at_crossing - Eigen::Vector3d(0, 0.15, 1.05)).norm(), 2e-3);
  // Limits (0.5 m/s, 13 m/s²) respected, no jumps.
  EXPECT_LE(r.max_v, 0.5 + 1e-9);
  EXPECT_LE(r.max_dv, 13.0 * (1 + 1e-6));
  EXPECT_LE(r.max_dp, 0.5 + 1e-6);
  // Home again afterwards.
  EXPECT_LT((r.final_p - pl.config().home).norm(), 1e-9);
  EXPECT_EQ(pl.phase(), CatchPhase::Homing);
}

TEST(CatchPlanner, DecidesEarlyThatAFarCrossingIsUnreachable) {
  CatchPlanner pl(config());
  // 0.6 m sideways in 0.4 s at 0.5 m/s: impossible.
  const double tc = 0.4;
  const PlannedRun r = simulate(pl, tc, 0.6, 1.2);
  EXPECT_TRUE(r.gave_up);
  ASSERT_TRUE(pl.giveUpTime());
  // Decided at the commitment, long before the crossing.
  ASSERT_TRUE(r.commit);
  EXPECT_DOUBLE_EQ(*pl.giveUpTime(), *r.commit);
  EXPECT_LT(*pl.giveUpTime(), tc - 0.15);
  EXPECT_LT((r.final_p - pl.config().home).norm(), 1e-9);
  EXPECT_LE(r.max_dv, 13.0 * (1 + 1e-6));
}

TEST(CatchPlanner, ReachabilityBoundaryMatchesTheProfileTime) {
  // The same crossing point, crossing time just after / just before the minimum arrival.
  const Eigen::Vector3d goal(0, 0.25, 1.2);
  const double T = planning::SyncProfile::minimumDuration(Eigen::Vector3d(0, 0, 1.2), Eigen::Vector3d::Zero(), goal,
                                                          Eigen::Vector3d::Constant(0.5),
                                                          Eigen::Vector3d::Constant(13));
  for (double margin : {+0.03, -0.05}) {
    CatchPlannerConfig c = config();
    c.give_up_late = 0.0;
    c.commit_min_updates = 1;
    c.latency = 0.0;
    CatchPlanner pl(c);
    const double tc = T + margin + 0.0;
    // A precise estimate already at t = 0 (so the robot starts at once).
    const auto u = pl.update(0.0, estimate(0.0, flightState(0.0, tc, goal.y(), goal.z()), 1e-4, 1e-4));
    ASSERT_TRUE(u.crossing);
    EXPECT_EQ(u.feasible, margin > 0) << margin;
    EXPECT_EQ(pl.giveUpTime().has_value(), margin < 0) << margin;
  }
}

TEST(CatchPlanner, RejectsBadConfig) {
  CatchPlannerConfig c = config();
  c.normal = Eigen::Vector3d(1, 1, 0);
  EXPECT_THROW(CatchPlanner{c}, core::InvalidInput);
  c = config();
  c.commit_sigma = 0;
  EXPECT_THROW(CatchPlanner{c}, core::InvalidInput);
}

TEST(CatchPlanner, TargetPriorShrinksUncertainPredictionsTowardsHome) {
  CatchPlannerConfig c = config();
  c.target_prior_std = 0.15;
  c.start_sigma = 10.0;
  c.latency = 0.0;
  const double tc = 0.6;
  for (double sigma : {1.0, 1e-4}) {
    CatchPlanner pl(c);
    pl.update(0.0, estimate(0.0, flightState(0.0, tc, 0.2, 1.2), sigma, sigma));
    ASSERT_TRUE(pl.target());
    const Eigen::Vector3d goal = pl.profile().goal();
    const double expected_y = 0.2 * 0.0225 / (0.0225 + pl.target()->cov_p(1, 1));  // posterior mean (cov is diagonal here)
    EXPECT_NEAR(goal.y(), expected_y, 1e-3) << sigma;
    EXPECT_NEAR(goal.x(), 0.0, 1e-12);  // stays in the plane
    if (sigma < 1e-3) {
      EXPECT_NEAR(goal.y(), 0.2, 1e-4);
    } else {
      EXPECT_LT(goal.y(), 0.05);
    }
  }
}
