#pragma once
// The camera geometry keys that scenario configs share, read by one function.
//
// A simulated camera in a scenario file is a pinhole looking from `position` at `look_at`
// (world frame, m) with a horizontal field of view, an image size, an optional principal point
// and the one-coefficient radial distortion of ViSP's vpCameraParameters (kud). When the scenario
// names a calibrated rig (`rig: <folder>`) the geometry comes from the rig's truth.yaml / rig.yaml
// and the same keys in the file are refused, naming the key and where the geometry comes from.
//
//   io::PinholeFields f;                         // the scenario's defaults
//   f.width = 656; f.height = 480;
//   io::readPinholeFields(node, f);              // keys present override the defaults
//
// Keys (all optional): width, height (px), hfov_deg, cx, cy (px), kud, position, look_at (m).

#include <Eigen/Core>
#include <initializer_list>
#include <optional>
#include <string>

#include "viewline/io/config.h"

namespace viewline::io {

/// Geometry of a simulated pinhole camera as a scenario file gives it (pixels, radians, world frame in metres).
struct PinholeFields {
  unsigned width = 640;  ///< image width, px
  unsigned height = 480;  ///< image height, px
  double hfov_rad = 1.0;                      ///< horizontal field of view, rad
  /// Principal point (cx, cy), px; absent: the image centre.
  std::optional<double> cx, cy;               ///< principal point, px (absent: the image centre)
  double kud = 0.0;                           ///< radial distortion (undistorted -> distorted)
  std::optional<Eigen::Vector3d> position;    ///< camera centre in the world, m
  std::optional<Eigen::Vector3d> look_at;     ///< a point on the optical axis, m
};

/// The geometry keys of a scenario camera.
inline constexpr std::initializer_list<const char*> kPinholeKeys = {"width", "height", "hfov_deg", "cx", "cy",
                                                                    "kud", "position", "look_at"};

/// Reads the geometry keys present in `n` into `f` (absent keys keep their value). Checks
/// width/height >= 16 px, hfov in (0, 170) degrees, |kud| <= 1, finite centre; errors name the
/// file, line and key. `position` and `look_at` go together.
void readPinholeFields(const ConfigNode& n, PinholeFields& f);

/// Refuses any of `keys` present in `n` because the rig in `rig_folder` sets the camera:
/// "<file:line:col>: key 'camera.hfov_deg': not allowed with 'rig' (...)".
void refuseGeometryWithRig(const ConfigNode& n, const std::string& rig_folder,
                           std::initializer_list<const char*> keys = kPinholeKeys);

}  // namespace viewline::io
