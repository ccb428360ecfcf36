#include "viewline/tracking/planar_target/history.h"

#include <cmath>
#include <limits>

namespace viewline::tracking {

Eigen::Vector2d extrapolatePosition(const Eigen::VectorXd& x, double tau) {
  if (x.size() == 5) {
    // Coordinated turn, either direction in time: p(τ) = p + (sin ωτ / ω) v + ((1 − cos ωτ) / ω) J v.
    const double w = x(4), wt = w * tau;
    const double s = std::abs(wt) < 1e-4 ? tau * (1.0 - wt * wt / 6.0) : std::sin(wt) / w;
    const double c = std::abs(wt) < 1e-4 ? 0.5 * wt * tau : (1.0 - std::cos(wt)) / w;
    const Eigen::Vector2d v = x.segment<2>(2);
    return x.head<2>() + s * v + c * Eigen::Vector2d(-v.y(), v.x());
  }
  Eigen::Vector2d p = x.head<2>() + tau * x.segment<2>(2);
  if (x.size() == 6) p += 0.5 * tau * tau * x.segment<2>(4);
  return p;
}

double velocityDirection(const estimation::StateEstimate& s) {
  const Eigen::Vector2d v = s.x().segment<2>(2);
  return v.norm() > 1e-9 ? std::atan2(v.y(), v.x()) : std::numeric_limits<double>::quiet_NaN();
}

}  // namespace viewline::tracking
