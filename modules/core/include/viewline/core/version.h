#pragma once
// The viewline version (semantic versioning: major.minor.patch; while major is 0 a minor release
// may change the API). The top-level CMakeLists.txt reads kVersion from this file, so the package
// version, every app's --version and every summary JSON's "viewline_version" agree.

namespace viewline::core {

/// viewline's version (major.minor.patch); its one owner, read by CMake, --version and summaries.
inline constexpr const char* kVersion = "0.2.0";

}  // namespace viewline::core
