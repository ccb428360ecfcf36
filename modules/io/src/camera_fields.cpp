#include "viewline/io/camera_fields.h"

#include <cmath>

#include "viewline/core/frames.h"

namespace viewline::io {

void readPinholeFields(const ConfigNode& n, PinholeFields& f) {
  f.width = n.getOr<unsigned>("width", f.width);
  f.height = n.getOr<unsigned>("height", f.height);
  if (f.width < 16 || f.height < 16) n.fail(n.has("width") ? "width" : "height", "an image of at least 16x16 pixels");
  f.hfov_rad = n.getAngleOr("hfov_deg", f.hfov_rad);
  if (!(f.hfov_rad > 0.0 && f.hfov_rad < core::deg2rad(170.0))) n.fail("hfov_deg", "an angle in (0, 170)");
  if (n.has("cx")) f.cx = n.get<double>("cx");
  if (n.has("cy")) f.cy = n.get<double>("cy");
  if (f.cx && !std::isfinite(*f.cx)) n.fail("cx", "a finite number (px)");
  if (f.cy && !std::isfinite(*f.cy)) n.fail("cy", "a finite number (px)");
  f.kud = n.getOr<double>("kud", f.kud);
  if (!std::isfinite(f.kud) || std::abs(f.kud) > 1.0) n.fail("kud", "a coefficient in [-1, 1]");
  if (n.has("position") != n.has("look_at") && !(f.position && f.look_at))
    n.fail(n.has("position") ? "look_at" : "position", "both position and look_at (the camera's pose)");
  if (n.has("position")) f.position = n.get<Eigen::Vector3d>("position");
  if (n.has("look_at")) f.look_at = n.get<Eigen::Vector3d>("look_at");
  if (f.position && f.look_at && (*f.position - *f.look_at).norm() < 1e-9)
    n.fail("look_at", "a point other than the camera position");
}

void refuseGeometryWithRig(const ConfigNode& n, const std::string& rig_folder,
                           std::initializer_list<const char*> keys) {
  for (const char* key : keys) {
    if (n.has(key)) {
      throw core::InvalidInput(n.location(key) + ": key '" + n.keyPath(key) + "': not allowed with 'rig' (the rig " +
                               rig_folder + " sets the camera: its truth.yaml and rig.yaml)");
    }
  }
}

}  // namespace viewline::io
