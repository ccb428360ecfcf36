#include "viewline/tracking/viewline.h"

#include <Eigen/LU>
#include <cmath>

#include "viewline/core/checks.h"

namespace viewline::tracking {

Eigen::Vector3d ViewlinePlanes::direction_w() const {
  Eigen::Vector3d d = pi_x.head<3>().cross(pi_y.head<3>());
  return d.normalized();
}

ViewlinePlanes viewlinePlanes(const core::Camera& camera, const Eigen::Vector2d& uv) {
  core::requireFinite(uv, "viewline: pixel");
  ViewlinePlanes out;
  out.xy = camera.pixelToNormalized(uv);
  if (!out.xy.allFinite()) core::requireFinite(out.xy, "viewline: undistorted pixel");
  const Eigen::Matrix<double, 3, 4> Pc = camera.normalizedProjection();
  const Eigen::Vector3d lx(-1.0, 0.0, out.xy.x());
  const Eigen::Vector3d ly(0.0, -1.0, out.xy.y());
  out.pi_x = Pc.transpose() * lx;
  out.pi_y = Pc.transpose() * ly;
  out.pi_x /= out.pi_x.head<3>().norm();
  out.pi_y /= out.pi_y.head<3>().norm();
  return out;
}

Eigen::Matrix2d undistortionJacobian(const core::Camera& camera, const Eigen::Vector2d& uv) {
  const double h = 1e-2;  // pixels; the map is smooth (polynomial), central differences are O(h²)
  Eigen::Matrix2d J;
  for (int k = 0; k < 2; ++k) {
    Eigen::Vector2d e = Eigen::Vector2d::Zero();
    e[k] = h;
    J.col(k) = (camera.pixelToNormalized(uv + e) - camera.pixelToNormalized(uv - e)) / (2.0 * h);
  }
  return J;
}

Eigen::Vector2d exactPixelOf(const core::Camera& camera, const Eigen::Vector2d& xy) {
  if (!xy.allFinite()) core::requireFinite(xy, "exactPixelOf: normalised point");
  Eigen::Vector2d uv = camera.normalizedToPixel(xy);
  for (int it = 0; it < 20; ++it) {
    const Eigen::Vector2d r = camera.pixelToNormalized(uv) - xy;
    if (r.norm() < 1e-15) break;
    uv -= undistortionJacobian(camera, uv).inverse() * r;
  }
  return uv;
}

Eigen::Matrix2d viewlineRowNoise(const core::Camera& camera, const Eigen::Vector2d& uv,
                                 const ViewlinePlanes& planes, double sigma_px, double depth_sq) {
  if (!(std::isfinite(sigma_px) && sigma_px > 0.0)) core::requirePositive(sigma_px, "viewline: pixel noise sigma_px");
  if (!(std::isfinite(depth_sq) && depth_sq > 0.0)) core::requirePositive(depth_sq, "viewline: expected squared depth");
  const Eigen::Matrix2d J = undistortionJacobian(camera, uv);
  Eigen::Matrix2d D = Eigen::Matrix2d::Zero();
  D(0, 0) = 1.0 / std::sqrt(1.0 + planes.xy.x() * planes.xy.x());
  D(1, 1) = 1.0 / std::sqrt(1.0 + planes.xy.y() * planes.xy.y());
  Eigen::Matrix2d R = depth_sq * sigma_px * sigma_px * D * J * J.transpose() * D;
  R(0, 1) = R(1, 0) = 0.5 * (R(0, 1) + R(1, 0));
  return R;
}

Eigen::Matrix2d viewlinePixelJacobian(const core::Camera& camera, const Eigen::Vector2d& uv, double depth_sq) {
  if (!(std::isfinite(depth_sq) && depth_sq > 0.0)) core::requirePositive(depth_sq, "viewline: expected squared depth");
  const Eigen::Vector2d xy = camera.pixelToNormalized(uv);
  const Eigen::Matrix2d J = undistortionJacobian(camera, uv);
  const Eigen::Vector2d D(1.0 / std::sqrt(1.0 + xy.x() * xy.x()), 1.0 / std::sqrt(1.0 + xy.y() * xy.y()));
  return -std::sqrt(depth_sq) * (D.asDiagonal() * J);
}

double expectedSquaredDepth(const core::Camera& camera, const Vector6& x, const Matrix6& P,
                            double dt_offset, const BallisticModel& model, double min_depth,
                            bool include_variance) {
  const Eigen::Vector3d r3 = camera.c_M_w.linear().row(2).transpose();
  const Eigen::Vector3d p = x.head<3>() + dt_offset * x.tail<3>() + 0.5 * dt_offset * dt_offset * model.gravity_w;
  const double z = std::max(r3.dot(p) + camera.c_M_w.translation().z(), min_depth);
  if (!include_variance) return z * z;
  // Var of r3·(p + Δt v): a = (r3, Δt r3).
  Vector6 a;
  a.head<3>() = r3;
  a.tail<3>() = dt_offset * r3;
  const double var = std::max(0.0, a.dot(P * a));
  return z * z + var;
}

ViewlineRows viewlineRowsWithDepth(const core::Camera& camera, const Eigen::Vector2d& uv, double sigma_px,
                                   double dt_offset, const BallisticModel& model, double depth_sq) {
  if (!std::isfinite(dt_offset)) core::requireFinite(dt_offset, "viewline: capture-time offset dt");
  const ViewlinePlanes planes = viewlinePlanes(camera, uv);
  ViewlineRows rows;
  const Eigen::Vector4d* pis[2] = {&planes.pi_x, &planes.pi_y};
  const Eigen::Vector3d half_g = 0.5 * dt_offset * dt_offset * model.gravity_w;
  for (int i = 0; i < 2; ++i) {
    const Eigen::Vector4d& pi = *pis[i];
    rows.C.row(i).head<3>() = pi.head<3>().transpose();
    rows.C.row(i).tail<3>() = dt_offset * pi.head<3>().transpose();
    rows.y[i] = -pi[3] - pi.head<3>().dot(half_g);
  }
  rows.R = viewlineRowNoise(camera, uv, planes, sigma_px, depth_sq);
  if (dt_offset != 0.0 && model.accel_psd > 0.0) {
    const Eigen::Matrix<double, 2, 3> N = rows.C.leftCols<3>();
    rows.R += N * model.processNoise(std::abs(dt_offset)).topLeftCorner<3, 3>() * N.transpose();
  }
  return rows;
}

ViewlineRows viewlineRows(const core::Camera& camera, const Eigen::Vector2d& uv, double sigma_px,
                          const Vector6& predicted, const Matrix6& P, double dt_offset,
                          const BallisticModel& model, double min_depth, bool depth_variance_in_noise) {
  if (!std::isfinite(dt_offset)) core::requireFinite(dt_offset, "viewline: capture-time offset dt");
  const double depth_sq =
      expectedSquaredDepth(camera, predicted, P, dt_offset, model, min_depth, depth_variance_in_noise);
  return viewlineRowsWithDepth(camera, uv, sigma_px, dt_offset, model, depth_sq);
}

estimation::LinearMeasurement stackRows(const std::vector<ViewlineRows>& images) {
  const auto m = static_cast<Eigen::Index>(2 * images.size());
  estimation::LinearMeasurement out;
  out.C = Eigen::MatrixXd::Zero(m, 6);
  out.y = Eigen::VectorXd::Zero(m);
  out.R = Eigen::MatrixXd::Zero(m, m);
  for (std::size_t i = 0; i < images.size(); ++i) {
    const auto r = static_cast<Eigen::Index>(2 * i);
    out.C.middleRows(r, 2) = images[i].C;
    out.y.segment(r, 2) = images[i].y;
    out.R.block(r, r, 2, 2) = images[i].R;
  }
  return out;
}

}  // namespace viewline::tracking
