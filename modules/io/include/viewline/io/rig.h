#pragma once
// Camera rig files: the cameras of a scene, each with its intrinsics file and its pose.
//
//   # rig.yaml                      (paths relative to this file)
//   cameras:
//     - name: left
//       intrinsics: left.xml        # ViSP camera XML (or OpenCV .yaml/.yml without distortion)
//       camera_name: left           # name inside the XML (default: name)
//       projection: with_distortion # or without_distortion (default: with_distortion)
//       width: 640                  # optional: must match the intrinsics file
//       height: 480
//       c_M_w:                      # world -> camera; or w_M_c (camera pose in the world)
//         translation: [0.1, 0.0, 2.0]                  # metres
//         rotation: [[1,0,0],[0,1,0],[0,0,1]]           # rows; or theta_u_deg: [rx, ry, rz]
//
// A rig can also be embedded in a scenario config under a key (loadRig(cfg.child("rig"))).

#include <Eigen/Geometry>
#include <string>
#include <vector>

#include "viewline/core/camera.h"
#include "viewline/io/camera_io.h"
#include "viewline/io/config.h"

namespace viewline::io {

/// Loads every camera of a rig file; unknown keys, missing files and bad poses are errors
/// naming the file, line and key.
std::vector<core::Camera> loadRig(const std::string& path);
/// Loads the cameras listed under `node` ("cameras: [...]"); marks its keys as read.
std::vector<core::Camera> loadRig(const ConfigNode& node);

/// A pose map {translation, rotation | theta_u_deg}; the rotation must be orthonormal with det +1
/// (tolerance 1e-6); it is re-orthonormalised.
Eigen::Isometry3d readPose(const ConfigNode& pose_node);

/// Writes a rig file plus one ViSP XML per camera, "<camera.name>.xml", next to it; all files
/// appear together or not at all. Cameras need distinct non-empty names. Returns the paths written.
std::vector<std::string> saveRig(const std::string& path, const std::vector<core::Camera>& cameras,
                                 const std::string& comment = {});

}  // namespace viewline::io
