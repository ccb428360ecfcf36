#include "recorded_units.h"

#include <filesystem>

#include "viewline/core/error.h"
#include "viewline/runtime/recording.h"

namespace viewline::tuning::detail {

std::vector<std::string> recordedUnitDirs(const std::string& dir, const std::string& app, const std::string& unit) {
  namespace fs = std::filesystem;
  std::vector<std::string> dirs;
  if (fs::exists(fs::path(dir) / "session.json")) {
    const int n = runtime::readSessionRecording(dir, app).units;
    for (int i = 0; i < n; ++i) dirs.push_back(runtime::sessionUnitDir(dir, unit, i));
  } else if (fs::exists(fs::path(dir) / "recording.csv")) {
    dirs.push_back(dir);
  } else {
    throw core::InvalidInput(dir + ": not a recording (no session.json, as " + app + " --record DIR writes, nor one " +
                             unit + "'s recording.csv)");
  }
  return dirs;
}

}  // namespace viewline::tuning::detail
