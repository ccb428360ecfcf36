#include "viewline/planning/catch_planner.h"

#include <algorithm>
#include <cmath>

#include "viewline/core/error.h"

namespace viewline::planning {

using core::InvalidInput;

SyncProfile planProfile(const robots::CartesianLimits& limits, double t0, const Eigen::Vector3d& p0,
                        const Eigen::Vector3d& v0, const Eigen::Vector3d& pf) {
  if (limits.norm == robots::LimitNorm::Euclidean)
    return SyncProfile::planEuclidean(t0, p0, v0, pf, limits.v_max(0), limits.a_max(0));
  return SyncProfile::plan(t0, p0, v0, pf, limits.v_max, limits.a_max);
}

double minimumDuration(const robots::CartesianLimits& limits, const Eigen::Vector3d& p0, const Eigen::Vector3d& v0,
                       const Eigen::Vector3d& pf) {
  if (limits.norm == robots::LimitNorm::Euclidean)
    return SyncProfile::minimumDurationEuclidean(p0, v0, pf, limits.v_max(0), limits.a_max(0));
  return SyncProfile::minimumDuration(p0, v0, pf, limits.v_max, limits.a_max);
}

const char* toString(CatchPhase p) {
  switch (p) {
    case CatchPhase::Idle: return "idle";
    case CatchPhase::Tracking: return "tracking";
    case CatchPhase::Committed: return "committed";
    case CatchPhase::GaveUp: return "gave_up";
    case CatchPhase::Homing: return "homing";
  }
  return "?";
}

void CatchPlannerConfig::validate() const {
  model.validate();
  limits.validate();
  if (!home.allFinite()) throw InvalidInput("planner.home: expected finite values");
  if (!normal.allFinite() || std::abs(normal.norm() - 1.0) > 1e-9)
    throw InvalidInput("planner.normal: expected a unit vector");
  auto nonneg = [](double v, const char* key) {
    if (!(std::isfinite(v) && v >= 0.0)) throw InvalidInput(std::string(key) + ": expected a finite value >= 0");
  };
  nonneg(latency, "robot.latency_s");
  nonneg(give_up_late, "planner.give_up_late_s");
  nonneg(give_up_sigmas, "planner.give_up_sigmas");
  nonneg(home_delay, "planner.home_delay_s");
  nonneg(min_lead, "planner.min_lead_s");
  nonneg(target_prior_std, "planner.target_prior_std_m");
  nonneg(move_sigmas, "planner.move_sigmas");
  if (!(std::isfinite(start_sigma) && start_sigma > 0.0)) throw InvalidInput("planner.start_sigma_m: expected > 0");
  if (!(std::isfinite(commit_sigma) && commit_sigma > 0.0)) throw InvalidInput("planner.commit_sigma_m: expected > 0");
  if (commit_min_updates < 1) throw InvalidInput("planner.commit_min_updates: expected >= 1");
}

CatchPlanner::CatchPlanner(CatchPlannerConfig cfg, std::function<bool(const Eigen::Vector3d&)> workspace)
    : cfg_(std::move(cfg)), workspace_(std::move(workspace)) {
  cfg_.validate();
  reset(0.0, cfg_.home);
}

namespace {
CatchPlannerConfig withRobot(CatchPlannerConfig cfg, const robots::CartesianRobot& robot) {
  cfg.limits = robot.limits();
  cfg.latency = robot.commandLatency();
  return cfg;
}
}  // namespace

CatchPlanner::CatchPlanner(CatchPlannerConfig cfg, const robots::CartesianRobot& robot)
    : CatchPlanner(withRobot(std::move(cfg), robot), [&robot](const Eigen::Vector3d& p) { return robot.reachable(p); }) {}

void CatchPlanner::reset(double t, const Eigen::Vector3d& p, const Eigen::Vector3d& v) {
  phase_ = CatchPhase::Idle;
  profile_ = planProfile(cfg_.limits, t, p, v, p);  // stop, return to p
  last_t_ = t;
  target_.reset();
  first_update_.reset();
  commit_time_.reset();
  give_up_time_.reset();
  first_move_.reset();
  updates_ = 0;
  replans_ = 0;
}

void CatchPlanner::planTo(double now, const Eigen::Vector3d& goal) {
  const CartesianSample s = profile_.at(now);
  profile_ = planProfile(cfg_.limits, now, s.p, s.v, goal);
  ++replans_;
}

PlannerUpdate CatchPlanner::update(double now, const estimation::StateEstimate& est) {
  PlannerUpdate out;
  if (!std::isfinite(now)) throw InvalidInput("CatchPlanner::update: non-finite time");
  if (phase_ == CatchPhase::GaveUp || phase_ == CatchPhase::Homing) return out;
  if (!first_update_) first_update_ = now;
  ++updates_;
  out.crossing = predictCrossing(est, plane(), cfg_.model);
  if (!out.crossing) return out;
  const Crossing& c = *out.crossing;
  if (c.t < now + cfg_.latency + cfg_.min_lead) return out;  // too late to act on
  const double sigma = c.sigmaMax();
  const bool in_workspace = !workspace_ || workspace_(c.p);
  const CartesianSample s = profile_.at(now);
  const double duration = minimumDuration(cfg_.limits, s.p, s.v, c.p);
  out.arrival = now + duration + cfg_.latency;
  out.feasible = in_workspace && out.arrival <= c.t;
  if (!commit_time_ && sigma <= cfg_.commit_sigma && updates_ >= cfg_.commit_min_updates) {
    commit_time_ = now;
    phase_ = CatchPhase::Committed;
  }
  // Give up only when even a lower bound of the arrival is late: under Euclidean limits the
  // per-axis profile with the same numbers relaxes |v| <= V to |v_i| <= V (so it is never slower
  // than any norm-limited motion), while the planner's own Euclidean family from a moving start is
  // conservative; going home cannot catch anything, chasing might.
  // With give_up_sigmas k: the crossing k std nearer the box (along the line to it) and k std later.
  Eigen::Vector3d p_near = c.p;
  double t_late = c.t;
  if (cfg_.give_up_sigmas > 0.0) {
    const Eigen::Vector3d d = s.p - c.p;
    if (d.norm() > 1e-12) {
      const Eigen::Vector3d u = d.normalized();
      const double sigma_u = std::sqrt(std::max(0.0, u.dot(c.cov_p * u)));
      p_near = c.p + u * std::min(d.norm(), cfg_.give_up_sigmas * sigma_u);
    }
    t_late = c.t + cfg_.give_up_sigmas * std::sqrt(std::max(0.0, c.var_t));
  }
  const double arrival_bound =
      cfg_.limits.norm == robots::LimitNorm::Euclidean
          ? now + cfg_.latency + SyncProfile::minimumDuration(s.p, s.v, p_near, cfg_.limits.v_max, cfg_.limits.a_max)
          : now + cfg_.latency + minimumDuration(cfg_.limits, s.p, s.v, p_near);
  if (commit_time_ && cfg_.give_up && (!in_workspace || arrival_bound > t_late + cfg_.give_up_late)) {
    give_up_time_ = now;
    phase_ = CatchPhase::GaveUp;
    planTo(now, cfg_.home);
    out.replanned = true;
    return out;
  }
  if (sigma > cfg_.start_sigma || !in_workspace) return out;
  if (phase_ == CatchPhase::Idle) phase_ = CatchPhase::Tracking;
  target_ = c;
  Eigen::Vector3d goal = c.p;
  if (cfg_.target_prior_std > 0.0) {
    const double s0 = cfg_.target_prior_std * cfg_.target_prior_std;
    const Eigen::Matrix3d S = s0 * Eigen::Matrix3d::Identity() + c.cov_p;
    goal = cfg_.home + s0 * S.ldlt().solve(c.p - cfg_.home);
    goal -= cfg_.normal * cfg_.normal.dot(goal - cfg_.home);  // stay in the plane
    if (workspace_ && !workspace_(goal)) goal = c.p;
  }
  if (cfg_.move_sigmas > 0.0) {
    // Soft threshold per in-plane axis (an orthonormal basis of the plane).
    const Eigen::Vector3d a = std::abs(cfg_.normal.z()) < 0.9 ? Eigen::Vector3d::UnitZ() : Eigen::Vector3d::UnitX();
    const Eigen::Vector3d e1 = (a - cfg_.normal * cfg_.normal.dot(a)).normalized();
    const Eigen::Vector3d e2 = cfg_.normal.cross(e1);
    Eigen::Vector3d shrunk = cfg_.home;
    for (const Eigen::Vector3d& e : {e1, e2}) {
      const double mu = e.dot(goal - cfg_.home);
      const double sd = std::sqrt(std::max(0.0, e.dot(c.cov_p * e)));
      shrunk += e * std::copysign(std::max(0.0, std::abs(mu) - cfg_.move_sigmas * sd), mu);
    }
    if (!workspace_ || workspace_(shrunk)) goal = shrunk;
  }
  if (!first_move_) first_move_ = now;
  planTo(now, goal);
  out.replanned = true;
  return out;
}

robots::CartesianState CatchPlanner::setpoint(double t) {
  if (t < last_t_) throw InvalidInput("CatchPlanner::setpoint: time goes backwards");
  last_t_ = t;
  if ((phase_ == CatchPhase::Tracking || phase_ == CatchPhase::Committed) && target_ &&
      t >= target_->t + cfg_.home_delay) {
    phase_ = CatchPhase::Homing;
    planTo(t, cfg_.home);
  }
  const CartesianSample s = profile_.at(t);
  return {t, s.p, s.v};
}

}  // namespace viewline::planning
