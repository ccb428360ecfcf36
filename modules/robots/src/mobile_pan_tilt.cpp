#include "viewline/robots/mobile_pan_tilt.h"

#include <algorithm>
#include <cmath>
#include <sstream>

#include "viewline/core/checks.h"
#include "viewline/core/error.h"
#include "viewline/core/frames.h"

namespace viewline::robots {

namespace {
constexpr double kHalfPi = 0.5 * core::kPi;

double wrap(double a) {
  double w = std::remainder(a, 2.0 * core::kPi);
  if (w <= -core::kPi) w += 2.0 * core::kPi;
  return w;
}
}  // namespace

vpHomogeneousMatrix dhTransform(const DhRow& row) {
  core::requireFinite(row.theta, "DhRow.theta");
  core::requireFinite(row.d, "DhRow.d");
  core::requireFinite(row.a, "DhRow.a");
  core::requireFinite(row.alpha, "DhRow.alpha");
  // Rz(θ) Tz(d) Tx(a) Rx(α), each factor a ViSP homogeneous matrix (translation, θu rotation).
  const vpHomogeneousMatrix rz(0, 0, 0, 0, 0, row.theta);
  const vpHomogeneousMatrix tz(0, 0, row.d, 0, 0, 0);
  const vpHomogeneousMatrix tx(row.a, 0, 0, 0, 0, 0);
  const vpHomogeneousMatrix rx(0, 0, 0, row.alpha, 0, 0);
  return rz * tz * tx * rx;
}

vpHomogeneousMatrix dhChain(const std::vector<DhRow>& rows) {
  vpHomogeneousMatrix m;  // identity
  for (const auto& r : rows) m = m * dhTransform(r);
  return m;
}

void MobilePanTiltParams::validate() const {
  core::requirePositive(l1, "MobilePanTiltParams.l1");
  core::requirePositive(l2, "MobilePanTiltParams.l2");
  core::requirePositive(l3, "MobilePanTiltParams.l3");
  core::requireFinite(tilt_min, "MobilePanTiltParams.tilt_min");
  core::requireFinite(tilt_max, "MobilePanTiltParams.tilt_max");
  core::requireFinite(pan_min, "MobilePanTiltParams.pan_min");
  core::requireFinite(pan_max, "MobilePanTiltParams.pan_max");
  if (!(tilt_min < tilt_max) || tilt_min < -kHalfPi || tilt_max > kHalfPi) {
    throw core::InvalidInput("MobilePanTiltParams.tilt_min/tilt_max: expected -90° <= tilt_min < tilt_max <= 90°");
  }
  if (!(pan_min < pan_max) || pan_min < -core::kPi || pan_max > core::kPi) {
    throw core::InvalidInput("MobilePanTiltParams.pan_min/pan_max: expected -180° <= pan_min < pan_max <= 180°");
  }
  core::requirePositive(tilt_rate_max, "MobilePanTiltParams.tilt_rate_max");
  core::requirePositive(pan_rate_max, "MobilePanTiltParams.pan_rate_max");
}

MobilePanTilt::MobilePanTilt(const MobilePanTiltParams& params) : params_(params) { params_.validate(); }

std::vector<DhRow> MobilePanTilt::dhTablePrinted(const PanTiltJoints& q) const {
  return {{0.0, params_.l1, 0.0, -kHalfPi},
          {kHalfPi - q.tilt, 0.0, params_.l2, 0.0},
          {kHalfPi, 0.0, 0.0, kHalfPi},
          {q.pan, 0.0, params_.l3, 0.0}};
}

std::vector<DhRow> MobilePanTilt::dhTable(const PanTiltJoints& q) const {
  auto rows = dhTablePrinted(q);
  rows[1].theta = q.tilt - kHalfPi;  // erratum: see the header
  return rows;
}

Eigen::Vector3d MobilePanTilt::cameraCenter(const PanTiltJoints& q) const {
  const double sa = std::sin(q.tilt), ca = std::cos(q.tilt), sb = std::sin(q.pan), cb = std::cos(q.pan);
  const double l1 = params_.l1, l2 = params_.l2, l3 = params_.l3;
  return {l2 * sa + l3 * ca * cb, l3 * sb, l1 + l2 * ca - l3 * sa * cb};
}

Eigen::Isometry3d MobilePanTilt::r_M_link4(const PanTiltJoints& q) const {
  core::requireFinite(q.tilt, "PanTiltJoints.tilt");
  core::requireFinite(q.pan, "PanTiltJoints.pan");
  return core::toEigen(dhChain(dhTable(q)));
}

Eigen::Isometry3d MobilePanTilt::r_M_c(const PanTiltJoints& q) const {
  Eigen::Isometry3d l4_M_c = Eigen::Isometry3d::Identity();
  Eigen::Matrix3d R;
  R << 0, 0, 1, -1, 0, 0, 0, -1, 0;
  l4_M_c.linear() = R;
  return r_M_link4(q) * l4_M_c;
}

Eigen::Vector3d MobilePanTilt::panJoint(double tilt) const {
  return {params_.l2 * std::sin(tilt), 0.0, params_.l1 + params_.l2 * std::cos(tilt)};
}

bool MobilePanTilt::withinLimits(const PanTiltJoints& q, double tol) const {
  return q.tilt >= params_.tilt_min - tol && q.tilt <= params_.tilt_max + tol && q.pan >= params_.pan_min - tol &&
         q.pan <= params_.pan_max + tol;
}

PanTiltJoints MobilePanTilt::clampToLimits(const PanTiltJoints& q) const {
  return {std::clamp(q.tilt, params_.tilt_min, params_.tilt_max), std::clamp(q.pan, params_.pan_min, params_.pan_max)};
}

std::optional<PanTiltJoints> MobilePanTilt::pointAt(const Eigen::Vector3d& p_r) const {
  core::requireFinite(p_r, "MobilePanTilt::pointAt: point");
  const double A = p_r.x(), B = p_r.z() - params_.l1;
  const double rho = std::hypot(A, B);
  if (rho <= params_.l2 * (1.0 + 1e-12)) return std::nullopt;  // inside the head
  const double phi = std::atan2(B, A);
  const double base = std::asin(params_.l2 / rho);
  std::optional<PanTiltJoints> best;
  for (const double tilt_raw : {base - phi, core::kPi - base - phi}) {
    const double tilt = wrap(tilt_raw);
    const Eigen::Vector3d d = p_r - panJoint(tilt);
    // Axis x_4 = cos β (cos α, 0, -sin α) + sin β (0, 1, 0).
    const double along = d.x() * std::cos(tilt) - d.z() * std::sin(tilt);
    const PanTiltJoints q{tilt, std::atan2(d.y(), along)};
    if (!withinLimits(q)) continue;
    if (!best || std::abs(q.tilt) < std::abs(best->tilt)) best = q;
  }
  return best;
}

double MobilePanTilt::pointingError(const PanTiltJoints& q, const Eigen::Vector3d& p_r) const {
  const Eigen::Vector3d d = (p_r - cameraCenter(q)).normalized();
  const double sa = std::sin(q.tilt), ca = std::cos(q.tilt), sb = std::sin(q.pan), cb = std::cos(q.pan);
  const Eigen::Vector3d axis(cb * ca, sb, -cb * sa);
  return std::acos(std::clamp(axis.dot(d), -1.0, 1.0));
}

PanTiltJoints MobilePanTilt::pointAtBest(const Eigen::Vector3d& p_r, double* angle_error) const {
  if (const auto exact = pointAt(p_r)) {
    if (angle_error) *angle_error = 0.0;
    return *exact;
  }
  // For a fixed tilt the best pan points the axis at the projection of d = p - P2 on the sweep plane.
  auto bestFor = [&](double tilt) {
    const Eigen::Vector3d d = p_r - panJoint(tilt);
    const double along = d.x() * std::cos(tilt) - d.z() * std::sin(tilt);
    const PanTiltJoints q = clampToLimits({tilt, std::atan2(d.y(), along)});
    return std::pair{q, pointingError(q, p_r)};
  };
  const int n = 64;
  double lo = params_.tilt_min, hi = params_.tilt_max;
  auto best = bestFor(lo);
  double best_tilt = lo;
  for (int i = 1; i <= n; ++i) {
    const double tilt = lo + (hi - lo) * i / n;
    const auto c = bestFor(tilt);
    if (c.second < best.second) best = c, best_tilt = tilt;
  }
  // Golden-section refinement around the best grid tilt.
  double a = std::max(lo, best_tilt - (hi - lo) / n), b = std::min(hi, best_tilt + (hi - lo) / n);
  const double g = 0.5 * (std::sqrt(5.0) - 1.0);
  for (int it = 0; it < 40; ++it) {
    const double c1 = b - g * (b - a), c2 = a + g * (b - a);
    if (bestFor(c1).second < bestFor(c2).second) b = c2; else a = c1;
  }
  const auto refined = bestFor(0.5 * (a + b));
  if (refined.second < best.second) best = refined;
  if (angle_error) *angle_error = best.second;
  return best.first;
}

Eigen::Isometry3d baseOnFloor(double x, double y, double theta) {
  Eigen::Isometry3d m = Eigen::Isometry3d::Identity();
  m.linear() = Eigen::AngleAxisd(theta, Eigen::Vector3d::UnitZ()).toRotationMatrix();
  m.translation() = Eigen::Vector3d(x, y, 0.0);
  return m;
}

Eigen::Isometry3d headCamera_c_M_w(const MobilePanTilt& head, const PanTiltJoints& q, double x, double y,
                                   double theta) {
  return (baseOnFloor(x, y, theta) * head.r_M_c(q)).inverse();
}

}  // namespace viewline::robots
