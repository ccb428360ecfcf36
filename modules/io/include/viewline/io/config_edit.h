#pragma once
// Dotted config keys ("tracker.accel_psd", "cameras[1].hfov_deg") on YAML trees, and a scenario
// file loaded with some of its values changed from the command line (the --set of every scenario
// app and of bench/pan_tilt_seeds; viewline_tune's --set edits the text instead, so that the configs
// it writes back keep the values: tuning::SessionOptions::set):
//
//   pan_tilt_tracking --config config/pan_tilt_random.yaml --set camera.fps=60 --set unit.latency=0.02
//
//   const io::ConfigNode cfg = io::loadConfigWithValues(path, sets);   // sets: {"camera.fps=60", ...}
//
// The edited tree is read back through io::ConfigNode, so the scenario's strict loader still
// rejects a key it does not know (a mistyped --set key is named, not silently added) and a value
// of the wrong type. Writing a file back with values replaced (keeping its comments) is
// tuning::rewriteYamlText (viewline/tuning/yaml_edit.h).

#include <optional>
#include <string>
#include <utility>
#include <vector>
#include <yaml-cpp/yaml.h>

#include "viewline/io/config.h"

namespace viewline::io {

struct KeySegment {
  std::string key;
  int index = -1;  ///< list index when the segment is "name[i]"
};

/// "a.b[1].c" -> {a}, {b, 1}, {c}. Throws core::InvalidInput on an empty or malformed key.
std::vector<KeySegment> parseDottedKey(const std::string& dotted);

/// The node at a dotted key, or nullopt when any segment is missing.
std::optional<YAML::Node> findKey(const YAML::Node& root, const std::string& dotted);

/// A deep copy of `root` with `value` at the dotted key (maps are created as needed; list items
/// must exist). Throws core::InvalidInput naming the key when a segment is not a map/list.
YAML::Node withValue(const YAML::Node& root, const std::string& dotted, const YAML::Node& value);

/// A deep copy with every (key, value) applied.
YAML::Node withValues(const YAML::Node& root, const std::vector<std::pair<std::string, YAML::Node>>& values);

/// YAML text of a node (block style).
std::string emitYaml(const YAML::Node& node);

/// "key=value" (a command line's --set): the dotted key and the value parsed as YAML ("0.3", "[1, 2]",
/// "ct"). Throws core::InvalidInput naming the text when there is no '=', the key is malformed or the
/// value is not YAML.
std::pair<std::string, YAML::Node> parseKeyValue(const std::string& text);

/// A scenario file with `key_values` ("key=value", as parseKeyValue) applied: ConfigNode::loadFile
/// when there are none; otherwise the file's tree with the values set (maps created as needed), read
/// back through ConfigNode, so the scenario's strict loader still rejects a key it does not know
/// and a wrong type. Relative paths in the file resolve against its folder as with loadFile; messages
/// name the file "with --set" (their line numbers are those of the edited tree).
ConfigNode loadConfigWithValues(const std::string& path, const std::vector<std::string>& key_values);

/// The command-line help of every --set option (scenario apps, viewline_tune, benches).
inline constexpr const char* kSetOptionHelp =
    "KEY=VALUE: change one key of the --config file for this run (repeatable; dotted keys, list items as "
    "name[i], YAML values: --set camera.fps=60 --set filter.model=ct); unknown keys are refused";

}  // namespace viewline::io
