#pragma once
// Shared bits of the calibration tools: loading intrinsics for pose estimation, pose YAML output,
// and the error handling of main().

#include <Eigen/Geometry>
#include <exception>
#include <iostream>
#include <sstream>
#include <string>

#include "viewline/calib/extrinsics.h"
#include "viewline/core/error.h"

namespace viewline::calib::tools {

/// Intrinsics for pose estimation: an OpenCV YAML (.yaml/.yml, full OpenCV model) or a ViSP XML
/// (camera `camera_name`, model `projection`).
PoseCamera loadPoseCamera(const std::string& path, const std::string& camera_name, const std::string& projection);

/// "translation: [..]\n rotation: [[..],[..],[..]]" at the given indentation (YAML block map).
std::string poseYaml(const Eigen::Isometry3d& T, int indent);

/// Runs f; prints "<tool>: error: <message>" and returns 1 on viewline errors, 2 on others.
template <class F>
int runTool(const char* tool, F&& f) {
  try {
    return f();
  } catch (const core::Error& e) {
    std::cerr << tool << ": error: " << e.what() << "\n";
    return 1;
  } catch (const std::exception& e) {
    std::cerr << tool << ": error: " << e.what() << "\n";
    return 2;
  }
}

}  // namespace viewline::calib::tools
