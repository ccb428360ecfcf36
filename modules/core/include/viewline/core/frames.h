#pragma once
// Frame helpers between ViSP and Eigen. Naming follows ViSP: `a_M_b` is the
// pose of frame b expressed in frame a; it maps coordinates of a point in b to
// its coordinates in a: p_a = a_M_b * p_b.

#include <Eigen/Geometry>
#include <visp3/core/vpHomogeneousMatrix.h>

namespace viewline::core {

/// Eigen isometry of a ViSP pose a_M_b (same frames, same meaning: p_a = a_M_b * p_b).
Eigen::Isometry3d toEigen(const vpHomogeneousMatrix& a_M_b);
/// ViSP pose of an Eigen isometry a_M_b (same frames, same meaning: p_a = a_M_b * p_b).
vpHomogeneousMatrix toVisp(const Eigen::Isometry3d& a_M_b);

/// Rotation about a unit axis of angle `rad` (right-handed).
Eigen::Matrix3d rotation(const Eigen::Vector3d& axis, double rad);

/// A camera pose c_M_w looking from `eye` towards `target` (both in world), with the
/// image "up" as close as possible to `up_w`. Camera frame as ViSP: x right, y down, z forward.
Eigen::Isometry3d lookAt(const Eigen::Vector3d& eye_w, const Eigen::Vector3d& target_w,
                         const Eigen::Vector3d& up_w);

/// Angle in radians between two rotations.
double rotationAngle(const Eigen::Matrix3d& a, const Eigen::Matrix3d& b);

/// Pi (rad).
constexpr double kPi = 3.14159265358979323846;
/// Degrees to radians.
constexpr double deg2rad(double d) { return d * kPi / 180.0; }
/// Radians to degrees.
constexpr double rad2deg(double r) { return r * 180.0 / kPi; }

}  // namespace viewline::core
