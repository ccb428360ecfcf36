#pragma once
// Locating an object on the floor from one image of the head camera (SPEC §4, [K]).
//
// Both methods return the point where the viewing ray of a pixel meets the horizontal plane
// z = plane_z (world frame, z up; plane_z = height of the object's centre for a blob centroid).
//
// Exact: the calibrated pinhole back-projection. The pixel is undistorted and back-projected with
// core::Camera::rayThroughPixel_w; p = c + s r with s = (plane_z - c_z) / r_z (r_z < 0).
//
// Angle per pixel ([K]): the camera's optical axis has yaw ψ (about z), depression δ below the
// horizon and roll φ about the axis. The centred pixel (j', k') = (u - u0, v - v0) is first
// rotated into a level image (roll removed): (j'', k'') are the components of j' x_c + k' y_c
// along the level right axis x_l = normalize(z_c × up) and the level down axis y_l = z_c × x_l.
// Then, with the image size (Px, Py) and the view angles (θ_rx, θ_ry), a linear angle per pixel:
//     ray depression  δ_r = δ + (k''/Py) θ_ry,      bearing  θ̂ = (j''/Px) θ_rx   (to the right)
//     printed range   r̂ = h / cos(π/2 - δ_r) = h / sin δ_r   (h = c_z - plane_z)
//     x̂ = c_x + r̂ cos(ψ - θ̂),  ŷ = c_y + r̂ sin(ψ - θ̂)          ([K]: r_cam cos θ_yaw + ...)
// As printed, r̂ is the *slant* range along the ray, used as if it were the horizontal distance;
// the horizontal distance is h / tan δ_r. `AngleRange::Horizontal` uses that corrected range
// (still with the angle-per-pixel approximation), `AngleRange::PrintedSlant` follows [K] as
// printed. The scenario reports the error of all three against the truth.

#include <Eigen/Core>
#include <optional>

#include "viewline/core/camera.h"

namespace viewline::robots {

/// Exact back-projection of pixel uv onto z = plane_z; nothing when the ray does not go down to it.
std::optional<Eigen::Vector2d> groundPointExact(const core::Camera& camera, const Eigen::Vector2d& uv,
                                                double plane_z = 0.0);

/// Which range [K]'s angle-per-pixel method uses: the slant range as printed, or the corrected horizontal distance.
enum class AngleRange { PrintedSlant, Horizontal };

/// [K]'s angle-per-pixel model: fields of view and range variant.
struct AnglePerPixel {
  double hfov = 0.0;  ///< θ_rx, rad (image width)
  double vfov = 0.0;  ///< θ_ry, rad (image height)
  AngleRange range = AngleRange::PrintedSlant;  ///< slant range as printed in [K], or the corrected horizontal range
};

/// Yaw ψ, depression δ and roll φ of a camera pose (definitions above), rad.
struct CameraAttitude {
  double yaw = 0.0,         ///< ψ, optical axis about world z from world x, rad
         depression = 0.0,  ///< δ, optical axis below the horizon, rad
         roll = 0.0;        ///< φ, rotation about the optical axis, rad
};
/// Yaw, depression and roll of the camera's optical axis in the world (z up).
CameraAttitude cameraAttitude(const core::Camera& camera);

/// [K]'s angle-per-pixel localisation; nothing when the ray points at or above the horizon.
std::optional<Eigen::Vector2d> groundPointAnglePerPixel(const core::Camera& camera, const Eigen::Vector2d& uv,
                                                        const AnglePerPixel& model, double plane_z = 0.0);

/// 2x2 covariance of the exact ground point for a pixel covariance (numerical Jacobian, 0.5 px
/// steps); nothing when the ray misses the plane.
std::optional<Eigen::Matrix2d> groundPointCovariance(const core::Camera& camera, const Eigen::Vector2d& uv,
                                                     const Eigen::Matrix2d& pixel_cov, double plane_z = 0.0);

}  // namespace viewline::robots
