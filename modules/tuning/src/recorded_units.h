#pragma once
// The folders of a scenario recording an adapter's loadRecording reads (runtime/recording.h).

#include <string>
#include <vector>

namespace viewline::tuning::detail {

/// The unit folders of a recording of `app` (its --record DIR): every `unit`_iii of a whole session
/// (session.json, runtime::readSessionRecording) or `dir` itself when it is one unit's folder
/// (recording.csv); anything else is refused, naming both.
std::vector<std::string> recordedUnitDirs(const std::string& dir, const std::string& app, const std::string& unit);

}  // namespace viewline::tuning::detail
