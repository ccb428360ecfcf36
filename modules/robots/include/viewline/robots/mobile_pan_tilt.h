#pragma once
// Pan/tilt head of [K]'s mobile robot (SPEC §4): kinematics from a Denavit-Hartenberg table,
// the closed-form camera centre, the inverse kinematics that points the camera at a point, and
// the camera pose on a robot that stands on the floor.
//
// Robot frame r: origin on the floor under the middle of the wheel axle, x forward, y left,
// z up. World frame w: z up, the floor is z = 0. w_M_r = (x, y, θ) of the base.
//
// Standard DH convention, one row (θ, d, a, α) per link:
//     (i-1)_M_i = Rz(θ) · Tz(d) · Tx(a) · Rx(α)
// SPEC §4's table, tilt α_t, pan β_p:
//     link 1 (0, l1, 0, -90°), link 2 (90° - α_t, 0, l2, 0), link 3 (90°, 0, 0, 90°),
//     link 4 (β_p, 0, l3, 0).
//
// Erratum (checked by test/mobile_pan_tilt_test.cpp): chaining that table literally puts the
// end of link 4 at
//     x = l2 sin α_t - l3 cos α_t cos β_p,   z = l1 - l2 cos α_t - l3 sin α_t cos β_p
// (the tilt link hangs *below* the shoulder), not at SPEC's closed form
//     x = l2 sin α_t + l3 cos α_t cos β_p,  y = l3 sin β_p,  z = l1 + l2 cos α_t - l3 sin α_t cos β_p.
// The closed form is the chain with link 2's joint angle θ2 = α_t - 90° (i.e. α_t → 180° - α_t
// in the printed row). We use that corrected row: then α_t = 0, β_p = 0 is a camera looking
// straight ahead, horizontally, from the top of a vertical l2 link, and α_t > 0 tilts it down;
// β_p > 0 pans it to the left (towards +y).
//
// Camera frame c (ViSP: x right, y down, z along the optical axis) at the end of link 4:
// z_c = x_4 (the optical axis continues link l3), x_c = -y_4, y_c = -z_4, i.e.
//     4_R_c = [[0, 0, 1], [-1, 0, 0], [0, -1, 0]].
// The optical axis therefore passes through the pan joint P2 = (l2 sin α_t, 0, l1 + l2 cos α_t)
// (r frame) and sweeps the plane through P2 normal to the pan axis z_4 = (sin α_t, 0, cos α_t).
//
// Inverse kinematics (pointAt): the axis meets a point p (r frame) iff p lies in that plane,
//     sin α_t · p_x + cos α_t · (p_z - l1) = l2,
// i.e. with ρ = |(p_x, p_z - l1)|, φ = atan2(p_z - l1, p_x):  α_t = asin(l2/ρ) - φ  or
// α_t = π - asin(l2/ρ) - φ (the one with the smaller |α_t| within the limits is taken); then
// β_p = atan2(d_y, d · (cos α_t, 0, -sin α_t)) with d = p - P2. Unreachable when ρ < l2
// (the point is inside the head) or when no solution lies within the joint limits. Note that the
// sweep plane always contains the lateral horizontal direction y_r, so a floor point far to the
// side needs |α_t| near 90°: the head reaches floor points ahead (and behind, with α_t < 0),
// the base has to turn for the others (pointAtBest gives the closest achievable pointing).

#include <Eigen/Geometry>
#include <array>
#include <vector>
#include <optional>
#include <visp3/core/vpHomogeneousMatrix.h>

namespace viewline::robots {

/// One Denavit-Hartenberg row (standard convention), angles in rad, lengths in m.
struct DhRow {
  double theta = 0.0;  ///< joint angle θ, rad
  double d = 0.0;  ///< offset d along the previous z, m
  double a = 0.0;  ///< link length a along the new x, m
  double alpha = 0.0;  ///< twist α about the new x, rad
};

/// (i-1)_M_i = Rz(θ) Tz(d) Tx(a) Rx(α), built with ViSP (vpHomogeneousMatrix).
vpHomogeneousMatrix dhTransform(const DhRow& row);
/// Product of the rows' transforms: 0_M_n.
vpHomogeneousMatrix dhChain(const std::vector<DhRow>& rows);

/// Joint angles of the mobile robot's pan/tilt head (corrected DH convention), rad.
struct PanTiltJoints {
  double tilt = 0.0;  ///< α_t, rad (> 0: camera looks down)
  double pan = 0.0;   ///< β_p, rad (> 0: camera looks left)
};

/// Link lengths and joint limits of the mobile robot's pan/tilt head ([K], SPEC §4).
struct MobilePanTiltParams {
  double l1 = 0.40;   ///< shoulder height above the floor, m
  double l2 = 0.075;  ///< tilt link, m
  double l3 = 0.04;   ///< pan link (to the camera centre), m
  double tilt_min = -0.6,   ///< lower tilt limit, rad (about -34°)
         tilt_max = 1.45;   ///< upper tilt limit, rad (about 83°)
  double pan_min = -2.97,   ///< lower pan limit, rad (about -170°)
         pan_max = 2.97;    ///< upper pan limit, rad (about 170°)
  double tilt_rate_max = 3.14,  ///< tilt rate limit, rad/s
         pan_rate_max = 3.14;   ///< pan rate limit, rad/s

  /// Throws core::InvalidInput naming the field.
  void validate() const;
};

/// Kinematics of the mobile robot's pan/tilt head: DH chain, camera pose r_M_c and inverse kinematics (pointAt).
class MobilePanTilt {
public:
  /// Head with these parameters (validated; throws core::InvalidInput).
  explicit MobilePanTilt(const MobilePanTiltParams& params = {});
  /// The parameters in use.
  const MobilePanTiltParams& params() const { return params_; }

  /// The DH rows as printed in SPEC §4 (link 2 θ = 90° - α_t): kept to document the erratum.
  std::vector<DhRow> dhTablePrinted(const PanTiltJoints& q) const;
  /// The corrected rows (link 2 θ = α_t - 90°) that match the closed form; used everywhere.
  std::vector<DhRow> dhTable(const PanTiltJoints& q) const;

  /// SPEC §4 closed-form camera centre in the robot frame.
  Eigen::Vector3d cameraCenter(const PanTiltJoints& q) const;
  /// r_M_4 from the (corrected) DH chain.
  Eigen::Isometry3d r_M_link4(const PanTiltJoints& q) const;
  /// r_M_c: camera frame (ViSP convention) in the robot frame.
  Eigen::Isometry3d r_M_c(const PanTiltJoints& q) const;
  /// Pan joint position P2 (on the optical axis) in the robot frame.
  Eigen::Vector3d panJoint(double tilt) const;

  /// Joint angles that put point p_r (robot frame) on the optical axis, in front of the camera
  /// and within the joint limits; nothing when impossible.
  std::optional<PanTiltJoints> pointAt(const Eigen::Vector3d& p_r) const;

  /// Joints within the limits whose optical axis makes the smallest angle with the direction
  /// to p_r (exact pointAt when it exists, otherwise a 1-D search over the tilt with the best pan
  /// for each tilt). `angle_error` receives that angle (rad) when non-null.
  PanTiltJoints pointAtBest(const Eigen::Vector3d& p_r, double* angle_error = nullptr) const;
  /// Angle between the optical axis for q and the direction from the camera centre to p_r.
  double pointingError(const PanTiltJoints& q, const Eigen::Vector3d& p_r) const;

  /// True when both joints are within their limits (+ tol, rad).
  bool withinLimits(const PanTiltJoints& q, double tol = 1e-9) const;
  /// The joints clamped to their limits.
  PanTiltJoints clampToLimits(const PanTiltJoints& q) const;

private:
  MobilePanTiltParams params_;
};

/// Pose of the robot base on the floor: w_M_r for (x, y, θ).
Eigen::Isometry3d baseOnFloor(double x, double y, double theta);

/// c_M_w of the head camera on a base at (x, y, θ).
Eigen::Isometry3d headCamera_c_M_w(const MobilePanTilt& head, const PanTiltJoints& q, double x, double y,
                                   double theta);

}  // namespace viewline::robots
