// The waypoint region: model in the header.
#include "viewline/tracking/planar_target/waypoint_region.h"

#include <algorithm>
#include <cmath>
#include <limits>

#include "viewline/core/error.h"

namespace viewline::tracking {

double boxReach(const Eigen::Vector2d& c, const Eigen::Vector2d& lo, const Eigen::Vector2d& hi, double th) {
  return boxReach(c, lo, hi, Eigen::Vector2d(std::cos(th), std::sin(th)));
}

double boxReach(const Eigen::Vector2d& c, const Eigen::Vector2d& lo, const Eigen::Vector2d& hi, const Eigen::Vector2d& u) {
  double r = std::numeric_limits<double>::infinity();
  for (int a = 0; a < 2; ++a) {
    if (u(a) > 1e-12) r = std::min(r, (hi(a) - c(a)) / u(a));
    if (u(a) < -1e-12) r = std::min(r, (lo(a) - c(a)) / u(a));
  }
  return std::max(r, 0.0);
}

double waypointDirectionDensity(const Eigen::Vector2d& c, const Eigen::Vector2d& center, const Eigen::Vector2d& size,
                                double theta) {
  if (!(size.x() > 0.0 && size.y() > 0.0)) throw core::InvalidInput("waypointDirectionDensity: size must be > 0");
  const Eigen::Vector2d lo = center - 0.5 * size, hi = center + 0.5 * size;
  const double R = boxReach(c.cwiseMax(lo).cwiseMin(hi), lo, hi, theta);
  return R * R / (2.0 * size.x() * size.y());
}

Eigen::Vector2d WaypointRegion::clampInside(const Eigen::Vector2d& c) const {
  const Eigen::Vector2d inset = 1e-3 * size_;
  return c.cwiseMax(lo() + inset).cwiseMin(hi() - inset);
}

double WaypointRegion::reach(const Eigen::Vector2d& c, double theta) const {
  return boxReach(clampInside(c), lo(), hi(), theta);
}

void WaypointRegion::check(const Eigen::Vector2d& p, const Eigen::Matrix2d& R) {
  if (!active()) return;
  const Eigen::Vector2d sd = R.diagonal().cwiseMax(0.0).cwiseSqrt();
  const Eigen::Vector2d half = 0.5 * size_;
  const Eigen::Vector2d outside = ((p - center_).cwiseAbs() - half).cwiseMax(0.0);
  const bool out = (outside.array() > 2.0 * sd.array()).any();
  outside_run_ = out ? outside_run_ + 1 : 0;
  if (outside_run_ >= 5) dropped_ = true;
}

std::vector<double> WaypointRegion::jumpOdds(const Eigen::Vector2d& p, const Eigen::Vector2d& v, core::Timestamp t_c,
                                             const PlanarHistory& history) const {
  // The current leg started at t_c from c and runs at speed s along u (the estimate's velocity): the
  // target is s (t − t_c) along it at t, and the next waypoint lies on the ray within R = R(θ_u) with
  // density ∝ r (see the header). odds_j = (s_j² − s_{j−1}²) / (R² − s_n²), s_n now; the
  // denominator is floored at (1 mm)² once the straight leg would have left the region.
  if (!active() || history.size() < 2) return {};
  const double speed = v.norm();
  if (!(speed > 1e-6)) return {};
  const double t_n = history.back().t;
  const Eigen::Vector2d c = p - v * (t_n - t_c);
  const double R = reach(c, std::atan2(v.y(), v.x()));
  const auto along = [&](double t) { return speed * std::max(t - t_c, 0.0); };
  const double s_n = along(t_n);
  const double log_den = std::log(std::max(R * R - s_n * s_n, 1e-6));
  std::vector<double> odds(history.size(), -1e300);
  for (std::size_t j = 1; j < history.size(); ++j) {
    const double a = along(history[j - 1].t), b = along(history[j].t);
    odds[j] = std::log(std::max(b * b - a * a, 1e-300)) - log_den;
  }
  return odds;
}

void WaypointRegion::stopAtBoundary(const Eigen::Vector2d& p0, Eigen::Vector2d& p, Eigen::Vector2d& v,
                                    Eigen::Vector2d& a) const {
  // The model says every leg joins two points of the box B (convex), so the target never leaves B. An
  // extrapolation from p0 (inside B) that ends outside stops where the chord p0 -> p meets B's boundary,
  // with v = a = 0 there: the target turns somewhere before it, towards a waypoint the measurements have
  // not shown yet. Without this, coasting through an occlusion at a corner near the edge runs the camera
  // straight out of B (at 0.3 m/s, a 1 s occlusion then cost a 1.9 s search). An estimate already
  // outside B (noise near the edge) is left as extrapolated.
  const Eigen::Vector2d b_lo = lo(), b_hi = hi();
  const auto inside = [&](const Eigen::Vector2d& q) { return (q.array() >= b_lo.array()).all() && (q.array() <= b_hi.array()).all(); };
  if (!inside(p0) || inside(p)) return;
  const Eigen::Vector2d d = p - p0;
  double f = 1.0;  // the largest f with p0 + f d in B
  for (int i = 0; i < 2; ++i) {
    if (p(i) > b_hi(i)) f = std::min(f, (b_hi(i) - p0(i)) / d(i));
    if (p(i) < b_lo(i)) f = std::min(f, (b_lo(i) - p0(i)) / d(i));
  }
  p = p0 + std::clamp(f, 0.0, 1.0) * d;
  v.setZero();
  a.setZero();
}

}  // namespace viewline::tracking
