#pragma once
// The viewline version (semantic versioning: major.minor.patch; while major is 0 a minor release
// may change the API). The top-level CMakeLists.txt reads kVersion from this file, so the package
// version, every app's --version and every summary JSON's "viewline_version" agree.

namespace viewline::core {

inline constexpr const char* kVersion = "0.2.0";

}  // namespace viewline::core
