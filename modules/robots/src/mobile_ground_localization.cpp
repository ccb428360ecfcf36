#include "viewline/robots/mobile_ground_localization.h"

#include <algorithm>
#include <cmath>

#include "viewline/core/checks.h"

namespace viewline::robots {

std::optional<Eigen::Vector2d> groundPointExact(const core::Camera& camera, const Eigen::Vector2d& uv,
                                                double plane_z) {
  core::requireFinite(uv, "groundPointExact: pixel");
  const Eigen::Vector3d c = camera.center_w();
  const Eigen::Vector3d r = camera.rayThroughPixel_w(uv);
  if (!(r.z() < -1e-9) || !(c.z() > plane_z)) return std::nullopt;
  const double s = (plane_z - c.z()) / r.z();
  return (c + s * r).head<2>().eval();
}

CameraAttitude cameraAttitude(const core::Camera& camera) {
  const Eigen::Matrix3d w_R_c = camera.c_M_w.linear().transpose();
  const Eigen::Vector3d xc = w_R_c.col(0), zc = w_R_c.col(2);
  CameraAttitude a;
  a.yaw = std::atan2(zc.y(), zc.x());
  a.depression = std::asin(std::clamp(-zc.z(), -1.0, 1.0));
  const Eigen::Vector3d xl = zc.cross(Eigen::Vector3d::UnitZ()).normalized();
  const Eigen::Vector3d yl = zc.cross(xl);
  a.roll = std::atan2(xc.dot(yl), xc.dot(xl));
  return a;
}

std::optional<Eigen::Vector2d> groundPointAnglePerPixel(const core::Camera& camera, const Eigen::Vector2d& uv,
                                                        const AnglePerPixel& model, double plane_z) {
  core::requireFinite(uv, "groundPointAnglePerPixel: pixel");
  core::requirePositive(model.hfov, "AnglePerPixel.hfov");
  core::requirePositive(model.vfov, "AnglePerPixel.vfov");
  const Eigen::Matrix3d w_R_c = camera.c_M_w.linear().transpose();
  const Eigen::Vector3d xc = w_R_c.col(0), yc = w_R_c.col(1), zc = w_R_c.col(2);
  if (std::abs(zc.z()) > 1.0 - 1e-9) return std::nullopt;  // looking straight down/up: yaw undefined
  const Eigen::Vector3d xl = zc.cross(Eigen::Vector3d::UnitZ()).normalized();
  const Eigen::Vector3d yl = zc.cross(xl);
  const double j = uv.x() - camera.intrinsics.get_u0(), k = uv.y() - camera.intrinsics.get_v0();
  const Eigen::Vector3d offset = j * xc + k * yc;  // roll removed by projecting on the level axes
  const double jl = offset.dot(xl), kl = offset.dot(yl);
  const CameraAttitude att = cameraAttitude(camera);
  const double delta_r = att.depression + kl / camera.height * model.vfov;
  const double bearing = jl / camera.width * model.hfov;
  const double h = camera.center_w().z() - plane_z;
  if (!(delta_r > 1e-6) || !(h > 0.0)) return std::nullopt;
  const double range = model.range == AngleRange::PrintedSlant ? h / std::cos(0.5 * M_PI - delta_r)
                                                               : h / std::tan(delta_r);
  const Eigen::Vector3d c = camera.center_w();
  return Eigen::Vector2d(c.x() + range * std::cos(att.yaw - bearing), c.y() + range * std::sin(att.yaw - bearing));
}

std::optional<Eigen::Matrix2d> groundPointCovariance(const core::Camera& camera, const Eigen::Vector2d& uv,
                                                     const Eigen::Matrix2d& pixel_cov, double plane_z) {
  Eigen::Matrix2d J;
  for (int i = 0; i < 2; ++i) {
    Eigen::Vector2d d = Eigen::Vector2d::Zero();
    d[i] = 0.5;
    const auto a = groundPointExact(camera, uv + d, plane_z), b = groundPointExact(camera, uv - d, plane_z);
    if (!a || !b) return std::nullopt;
    J.col(i) = (*a - *b) / 1.0;
  }
  return (J * pixel_cov * J.transpose()).eval();
}

}  // namespace viewline::robots
