#include "viewline/core/frames.h"

#include <algorithm>
#include <cmath>

#include "viewline/core/error.h"

namespace viewline::core {

Eigen::Isometry3d toEigen(const vpHomogeneousMatrix& a_M_b) {
  Eigen::Isometry3d T = Eigen::Isometry3d::Identity();
  for (unsigned i = 0; i < 3; ++i) {
    for (unsigned j = 0; j < 3; ++j) T.linear()(i, j) = a_M_b[i][j];
    T.translation()[i] = a_M_b[i][3];
  }
  return T;
}

vpHomogeneousMatrix toVisp(const Eigen::Isometry3d& a_M_b) {
  vpHomogeneousMatrix M;
  for (unsigned i = 0; i < 3; ++i) {
    for (unsigned j = 0; j < 3; ++j) M[i][j] = a_M_b.linear()(i, j);
    M[i][3] = a_M_b.translation()[i];
  }
  return M;
}

Eigen::Matrix3d rotation(const Eigen::Vector3d& axis, double rad) {
  return Eigen::AngleAxisd(rad, axis.normalized()).toRotationMatrix();
}

Eigen::Isometry3d lookAt(const Eigen::Vector3d& eye_w, const Eigen::Vector3d& target_w,
                         const Eigen::Vector3d& up_w) {
  const Eigen::Vector3d z = (target_w - eye_w);
  if (z.norm() < 1e-12) throw InvalidInput("lookAt: eye and target coincide");
  const Eigen::Vector3d zc = z.normalized();
  Eigen::Vector3d x = zc.cross(up_w);  // right = forward x up; image y (down) = z x x
  if (x.norm() < 1e-9) throw InvalidInput("lookAt: up vector parallel to the viewing direction");
  x.normalize();
  const Eigen::Vector3d y = zc.cross(x);
  Eigen::Matrix3d w_R_c;
  w_R_c.col(0) = x;
  w_R_c.col(1) = y;
  w_R_c.col(2) = zc;
  Eigen::Isometry3d w_M_c = Eigen::Isometry3d::Identity();
  w_M_c.linear() = w_R_c;
  w_M_c.translation() = eye_w;
  return w_M_c.inverse();
}

double rotationAngle(const Eigen::Matrix3d& a, const Eigen::Matrix3d& b) {
  const double c = std::clamp(((a.transpose() * b).trace() - 1.0) / 2.0, -1.0, 1.0);
  return std::acos(c);
}

}  // namespace viewline::core
