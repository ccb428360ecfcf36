#include "viewline/control/mobile_capture_control.h"

#include <algorithm>
#include <cmath>

#include "viewline/core/checks.h"
#include "viewline/core/error.h"

namespace viewline::control {

namespace {
double wrap(double a) { return std::remainder(a, 2.0 * M_PI); }
}  // namespace

void GoToPointParams::validate() const {
  core::requirePositive(max_speed, "GoToPointParams.max_speed");
  core::requirePositive(max_turn_rate, "GoToPointParams.max_turn_rate");
  core::requirePositive(k_heading, "GoToPointParams.k_heading");
  core::requireFinite(stop_distance, "GoToPointParams.stop_distance");
  if (stop_distance < 0.0) throw core::InvalidInput("GoToPointParams.stop_distance: expected >= 0");
  core::requirePositive(slow_distance, "GoToPointParams.slow_distance");
}

BaseCommand goToPoint(const robots::BasePose& pose, const Eigen::Vector2d& goal, const GoToPointParams& params) {
  core::requireFinite(goal, "goToPoint: goal");
  const Eigen::Vector2d d = goal - Eigen::Vector2d(pose.x, pose.y);
  const double dist = d.norm();
  const double e = dist > 1e-9 ? wrap(std::atan2(d.y(), d.x()) - pose.theta) : 0.0;
  BaseCommand c;
  c.omega = std::clamp(params.k_heading * e, -params.max_turn_rate, params.max_turn_rate);
  const double align = std::max(0.0, std::cos(e));
  const double ramp = std::clamp((dist - params.stop_distance) / params.slow_distance, 0.0, 1.0);
  c.v = params.max_speed * align * align * ramp;
  return c;
}

robots::PanTiltJoints headSetPoint(const robots::MobilePanTilt& head, const robots::BasePose& pose,
                                   const Eigen::Vector3d& target_w, double* angle_error) {
  const Eigen::Isometry3d w_M_r = robots::baseOnFloor(pose.x, pose.y, pose.theta);
  return head.pointAtBest(w_M_r.inverse() * target_w, angle_error);
}

void SearchParams::validate() const {
  core::requirePositive(lost_after, "SearchParams.lost_after");
  core::requirePositive(search_after, "SearchParams.search_after");
  core::requirePositive(sweep_amplitude, "SearchParams.sweep_amplitude");
  core::requirePositive(sweep_period, "SearchParams.sweep_period");
  core::requirePositive(search_range, "SearchParams.search_range");
  core::requirePositive(base_turn_rate, "SearchParams.base_turn_rate");
}

SearchPattern::SearchPattern(const SearchParams& params) : params_(params) { params_.validate(); }

SearchMode SearchPattern::mode(double t, double last_seen) const {
  if (last_seen < 0.0) return SearchMode::Sweeping;
  const double gap = t - last_seen;
  if (gap < params_.lost_after) return SearchMode::Tracking;
  if (gap < params_.search_after) return SearchMode::Lost;
  return SearchMode::Sweeping;
}

robots::PanTiltJoints SearchPattern::sweep(const robots::MobilePanTilt& head, double t, double sweep_start,
                                           double centre_bearing) const {
  const double phase = 2.0 * M_PI * (t - sweep_start) / params_.sweep_period;
  const double bearing = centre_bearing + params_.sweep_amplitude * std::sin(phase);
  const Eigen::Vector3d p(params_.search_range * std::cos(bearing), params_.search_range * std::sin(bearing), 0.0);
  return head.pointAtBest(p);
}

BaseCommand SearchPattern::baseWhileSearching(double centre_bearing, bool have_bearing) const {
  BaseCommand c;
  if (!have_bearing) {
    c.omega = params_.base_turn_rate;
    return c;
  }
  c.omega = std::clamp(2.0 * wrap(centre_bearing), -params_.base_turn_rate * 2.0, params_.base_turn_rate * 2.0);
  return c;
}

}  // namespace viewline::control
