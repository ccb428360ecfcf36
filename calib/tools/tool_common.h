#pragma once
// Shared bits of the calibration tools: loading intrinsics for pose estimation, pose YAML output,
// and the error handling of main().

#include <CLI/CLI.hpp>
#include <Eigen/Geometry>
#include <exception>
#include <iostream>
#include <optional>
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

/// Parses the command line. nullopt: go on; otherwise the exit status to return at once: 0 after
/// --help/--version, 2 for a usage error (CLI11's message; CLI11_PARSE would return CLI11's own codes).
inline std::optional<int> parseCommandLine(CLI::App& app, int argc, char** argv) {
  try {
    app.parse(argc, argv);
  } catch (const CLI::ParseError& e) {
    const int code = app.exit(e);
    return code == 0 ? 0 : 2;
  }
  return std::nullopt;
}

/// Runs f; prints "<tool>: error: <message>" and returns 1 (a runtime error: the command line was
/// well formed, a file or a computation was not) on any exception.
template <class F>
int runTool(const char* tool, F&& f) {
  try {
    return f();
  } catch (const std::exception& e) {
    std::cerr << tool << ": error: " << e.what() << "\n";
    return 1;
  }
}

}  // namespace viewline::calib::tools
