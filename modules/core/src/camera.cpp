#include "viewline/core/camera.h"

#include <cmath>
#include <visp3/core/vpMeterPixelConversion.h>
#include <visp3/core/vpPixelMeterConversion.h>

#include "viewline/core/checks.h"

namespace viewline::core {

Eigen::Vector2d Camera::pixelToNormalized(const Eigen::Vector2d& uv) const {
  double x = 0.0, y = 0.0;
  vpPixelMeterConversion::convertPoint(intrinsics, uv.x(), uv.y(), x, y);
  return {x, y};
}

Eigen::Vector2d Camera::normalizedToPixel(const Eigen::Vector2d& xy) const {
  double u = 0.0, v = 0.0;
  vpMeterPixelConversion::convertPoint(intrinsics, xy.x(), xy.y(), u, v);
  return {u, v};
}

std::optional<Eigen::Vector2d> Camera::project(const Eigen::Vector3d& p_w, double min_depth) const {
  const Eigen::Vector3d p_c = c_M_w * p_w;
  if (!(p_c.z() > min_depth)) return std::nullopt;
  return normalizedToPixel({p_c.x() / p_c.z(), p_c.y() / p_c.z()});
}

bool Camera::inImage(const Eigen::Vector2d& uv, double margin) const {
  return uv.x() >= margin && uv.y() >= margin && uv.x() <= width - 1.0 - margin &&
         uv.y() <= height - 1.0 - margin;
}

Eigen::Matrix<double, 3, 4> Camera::normalizedProjection() const {
  Eigen::Matrix<double, 3, 4> P;
  P.leftCols<3>() = c_M_w.linear();
  P.col(3) = c_M_w.translation();
  return P;
}

Eigen::Matrix<double, 3, 4> Camera::pixelProjection() const {
  Eigen::Matrix3d K;
  K << intrinsics.get_px(), 0.0, intrinsics.get_u0(), 0.0, intrinsics.get_py(), intrinsics.get_v0(),
      0.0, 0.0, 1.0;
  return K * normalizedProjection();
}

Eigen::Vector3d Camera::rayThroughPixel_w(const Eigen::Vector2d& uv) const {
  const Eigen::Vector2d xy = pixelToNormalized(uv);
  return (c_M_w.linear().transpose() * Eigen::Vector3d(xy.x(), xy.y(), 1.0)).normalized();
}

double Camera::horizontalFov() const { return 2.0 * std::atan(0.5 * width / intrinsics.get_px()); }

vpCameraParameters intrinsicsFromFov(double hfov_rad, unsigned width, unsigned height) {
  requirePositive(hfov_rad, "intrinsicsFromFov: horizontal field of view");
  if (hfov_rad >= 3.1) throw InvalidInput("intrinsicsFromFov: field of view must be < 180 deg");
  const double f = 0.5 * width / std::tan(0.5 * hfov_rad);
  return vpCameraParameters(f, f, 0.5 * width, 0.5 * height);
}

}  // namespace viewline::core
