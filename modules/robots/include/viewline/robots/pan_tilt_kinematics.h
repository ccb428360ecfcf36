#pragma once
// Kinematic model of the pan-tilt head: ViSP's vpPtu46 (Directed Perception
// PTU-46, the FLIR PTU-D46's predecessor with the same geometry).
//
// Frames (vpPtu46): base frame f, x forward, y left, z up. At q = 0 the camera
// looks along +x_f with image x = −y_f and image y = −z_f. With c1 = cos pan,
// s1 = sin pan, c2 = cos tilt, s2 = sin tilt (L = 0.0765 m, h = 0.068 m):
//
//   f_M_c = [  s1   c1 s2   c1 c2   −h c1 s2 − L s1 ]
//           [ −c1   s1 s2   s1 c2   −h s1 s2 + L c1 ]
//           [  0   −c2      s2       h c2           ]
//
// so the optical axis is (c1 c2, s1 c2, s2): positive pan turns it left, positive
// tilt turns it up. The end-effector Jacobian (eJe, 6x2) and the camera/end-
// effector twist (cVe) are ViSP's; the test checks that cVe eJe q̇ equals the
// camera twist obtained by differentiating f_M_c(q) numerically.
//
// pointAt() is the inverse kinematics "put this point on the optical axis":
// the angles of the direction (atan2(y, x), atan2(z, hypot(x, y))) refined by
// Newton steps on the point's normalised image coordinates (the camera centre
// is offset from the axes by L and h, so the direction alone is off by ~3°
// at 1.3 m).
//
// Camera mount: vpPtu46 carries a nominal camera mount e_M_c (translation
// (h, −L, 0), rotation 90° about z). A real camera is mounted with errors, so the
// model can be built with another e_M_c (the true one in the simulator, the
// hand-eye calibration in the estimators): f_M_c(q) = f_M_e(q) e_M_c, with
// f_M_e(q) = f_M_c_nominal(q) c_M_e_nominal (vpPtu46's chain without its mount),
// and cVe the twist of c_M_e = e_M_c⁻¹. eJe does not depend on the mount.

#include <Eigen/Geometry>
#include <visp3/core/vpHomogeneousMatrix.h>
#include <visp3/core/vpMatrix.h>
#include <visp3/core/vpVelocityTwistMatrix.h>
#include <visp3/robot/vpPtu46.h>

namespace viewline::robots {

/// vpPtu46 kinematics of the pan-tilt head with a given camera mount e_M_c: camera pose f_M_c(q), Jacobian, pointing.
class PanTiltKinematics {
public:
  /// vpPtu46's nominal camera mount.
  PanTiltKinematics();
  /// The camera mounted at e_M_c on the end effector (maps camera to end-effector coordinates).
  explicit PanTiltKinematics(const Eigen::Isometry3d& e_M_c);

  /// The camera mount in use (the nominal one for the default constructor).
  const Eigen::Isometry3d& e_M_c() const { return e_M_c_; }
  /// vpPtu46's nominal camera mount.
  static Eigen::Isometry3d nominalEyeInHand();

  /// Pose of the camera in the base frame (maps camera coordinates to base coordinates).
  vpHomogeneousMatrix f_M_c(const Eigen::Vector2d& q) const;
  /// Pose of the base in the camera frame, as Eigen (c_M_f).
  Eigen::Isometry3d c_M_f(const Eigen::Vector2d& q) const;
  /// Camera / end-effector velocity twist (constant for the PTU-46).
  vpVelocityTwistMatrix cVe() const;
  /// End-effector Jacobian (6 x 2) at q.
  vpMatrix eJe(const Eigen::Vector2d& q) const;
  /// Normalised image coordinates (x, y) = (X/Z, Y/Z) of a base-frame point seen at q, and its depth.
  Eigen::Vector3d project(const Eigen::Vector2d& q, const Eigen::Vector3d& p_f) const;
  /// Joint angles that put p_f on the optical axis (|x|, |y| < 1e-10 after at most 10 Newton steps).
  /// Throws core::InvalidInput for a point at the head's centre or behind it when straight up.
  Eigen::Vector2d pointAt(const Eigen::Vector3d& p_f) const;

private:
  vpPtu46 ptu_;
  Eigen::Isometry3d e_M_c_;
  vpHomogeneousMatrix c_M_e_nominal_, e_M_c_vp_;
  vpVelocityTwistMatrix cVe_;
};

}  // namespace viewline::robots
