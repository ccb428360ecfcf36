#include "viewline/robots/pan_tilt_kinematics.h"

#include <cmath>
#include <visp3/core/vpColVector.h>

#include "viewline/core/checks.h"
#include "viewline/core/frames.h"

namespace viewline::robots {

namespace {
vpColVector toCol(const Eigen::Vector2d& q) {
  vpColVector v(2);
  v[0] = q(0);
  v[1] = q(1);
  return v;
}
}  // namespace

Eigen::Isometry3d PanTiltKinematics::nominalEyeInHand() {
  vpPtu46 ptu;
  vpHomogeneousMatrix cMe;
  ptu.get_cMe(cMe);
  return core::toEigen(cMe.inverse());
}

PanTiltKinematics::PanTiltKinematics() : PanTiltKinematics(nominalEyeInHand()) {}

PanTiltKinematics::PanTiltKinematics(const Eigen::Isometry3d& e_M_c) : e_M_c_(e_M_c) {
  core::requireFinite(e_M_c.matrix(), "PanTiltKinematics: e_M_c");
  ptu_.get_cMe(c_M_e_nominal_);
  e_M_c_vp_ = core::toVisp(e_M_c);
  cVe_.buildFrom(e_M_c_vp_.inverse());
}

vpHomogeneousMatrix PanTiltKinematics::f_M_c(const Eigen::Vector2d& q) const {
  core::requireFinite(q, "PanTiltKinematics: q");
  // f_M_e(q) = f_M_c_nominal(q) c_M_e_nominal; then the actual mount.
  return ptu_.computeMGD(toCol(q)) * c_M_e_nominal_ * e_M_c_vp_;
}

Eigen::Isometry3d PanTiltKinematics::c_M_f(const Eigen::Vector2d& q) const {
  return core::toEigen(f_M_c(q).inverse());
}

vpVelocityTwistMatrix PanTiltKinematics::cVe() const { return cVe_; }

vpMatrix PanTiltKinematics::eJe(const Eigen::Vector2d& q) const {
  core::requireFinite(q, "PanTiltKinematics: q");
  vpMatrix J;
  ptu_.get_eJe(toCol(q), J);
  return J;
}

Eigen::Vector3d PanTiltKinematics::project(const Eigen::Vector2d& q, const Eigen::Vector3d& p_f) const {
  const Eigen::Vector3d p_c = c_M_f(q) * p_f;
  return {p_c.x() / p_c.z(), p_c.y() / p_c.z(), p_c.z()};
}

Eigen::Vector2d PanTiltKinematics::pointAt(const Eigen::Vector3d& p_f) const {
  core::requireFinite(p_f, "PanTiltKinematics::pointAt: p_f");
  const double r = std::hypot(p_f.x(), p_f.y());
  if (p_f.norm() < 0.2) throw core::InvalidInput("PanTiltKinematics::pointAt: point closer than 0.2 m to the head");
  Eigen::Vector2d q(std::atan2(p_f.y(), p_f.x()), std::atan2(p_f.z(), r));
  for (int it = 0; it < 10; ++it) {
    const Eigen::Vector3d s = project(q, p_f);
    if (s.z() <= 0.0) break;
    if (std::abs(s.x()) < 1e-12 && std::abs(s.y()) < 1e-12) break;
    // Numerical Jacobian d(x, y)/dq (2x2); well conditioned away from tilt = ±90°.
    Eigen::Matrix2d J;
    const double h = 1e-7;
    for (int j = 0; j < 2; ++j) {
      Eigen::Vector2d qh = q;
      qh(j) += h;
      J.col(j) = (project(qh, p_f).head<2>() - s.head<2>()) / h;
    }
    q -= J.fullPivLu().solve(s.head<2>());
  }
  return q;
}

}  // namespace viewline::robots
