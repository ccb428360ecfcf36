#pragma once
// A calibrated camera: ViSP intrinsics (with or without distortion), image size
// and pose. Shared by the tracker (viewline planes), the simulated worlds
// (rendering) and the detectors (pixel covariances), so all use one model.
//
// Frames (ViSP): camera x right, y down, z forward (optical axis).
// c_M_w maps world coordinates to camera coordinates: p_c = c_M_w * p_w.
// Normalised coordinates: (x, y) = (X/Z, Y/Z) of p_c; pixels (u, v) follow
// ViSP's model (vpMeterPixelConversion / vpPixelMeterConversion, ViSP 3.5):
// projection u = u0 + px x (1 + kud (x² + y²)), and back-projection
// x = (u − u0)/px · (1 + kdu r_pix²) with r_pix² = ((u−u0)/px)² + ((v−v0)/py)²,
// both applied only when the projection type is with distortion. The two
// coefficients are separate approximations, not exact inverses.

#include <Eigen/Geometry>
#include <optional>
#include <string>
#include <visp3/core/vpCameraParameters.h>

namespace viewline::core {

/// A calibrated camera: ViSP intrinsics, image size and pose c_M_w (world to camera), one model for tracker,
/// renderer and detectors.
struct Camera {
  std::string name = "camera";  ///< Name used in logs, rig files and error messages.
  vpCameraParameters intrinsics;                       ///< fx=px, fy=py, cx=u0, cy=v0, kud, kdu
  Eigen::Isometry3d c_M_w = Eigen::Isometry3d::Identity();  ///< world -> camera
  unsigned width = 640;                                ///< pixels
  unsigned height = 480;                               ///< pixels

  /// Pixel to normalised coordinates, lens distortion removed (vpPixelMeterConversion).
  Eigen::Vector2d pixelToNormalized(const Eigen::Vector2d& uv) const;
  /// Normalised coordinates to pixel, lens distortion applied (vpMeterPixelConversion).
  Eigen::Vector2d normalizedToPixel(const Eigen::Vector2d& xy) const;

  /// World point to camera frame.
  Eigen::Vector3d toCamera(const Eigen::Vector3d& p_w) const { return c_M_w * p_w; }
  /// Pixel of a world point, or nothing when it is not in front of the camera (Z <= min_depth).
  std::optional<Eigen::Vector2d> project(const Eigen::Vector3d& p_w, double min_depth = 1e-6) const;
  /// True when the pixel lies inside the image, at least `margin` pixels from the border.
  bool inImage(const Eigen::Vector2d& uv, double margin = 0.0) const;

  /// [R | t] = the 3x4 map from homogeneous world points to homogeneous normalised image points.
  Eigen::Matrix<double, 3, 4> normalizedProjection() const;
  /// K [R | t] (pixels, ignoring distortion).
  Eigen::Matrix<double, 3, 4> pixelProjection() const;
  /// Camera centre in world coordinates.
  Eigen::Vector3d center_w() const { return c_M_w.inverse().translation(); }
  /// Unit ray in the world frame through a pixel (distortion removed).
  Eigen::Vector3d rayThroughPixel_w(const Eigen::Vector2d& uv) const;

  /// Mean focal length in pixels (for converting pixel noise to normalised units).
  double focalPx() const { return 0.5 * (intrinsics.get_px() + intrinsics.get_py()); }
  /// Horizontal field of view in radians (ignoring distortion).
  double horizontalFov() const;
};

/// A pinhole camera without distortion from a horizontal field of view (radians) and image size,
/// principal point at the image centre, square pixels.
vpCameraParameters intrinsicsFromFov(double hfov_rad, unsigned width, unsigned height);

}  // namespace viewline::core
