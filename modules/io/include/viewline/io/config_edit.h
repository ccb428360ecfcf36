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
// The values are written into the file's text (rewriteYamlText: in place, so comments stay and the
// lines keep their numbers, and messages point into the user's file) and read back through
// io::ConfigNode, so the scenario's strict loader still rejects a key it does not know (a mistyped
// --set key is named, not silently added) and a value of the wrong type. viewline_tune writes the
// same text into the configs it saves (best_config.yaml, autotuned_config.yaml).

#include <optional>
#include <string>
#include <utility>
#include <vector>
#include <yaml-cpp/yaml.h>

#include "viewline/io/config.h"

namespace viewline::io {

/// One segment of a dotted key: a map key, optionally indexed into a list ("cameras[1]").
struct KeySegment {
  std::string key;  ///< map key of the segment
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

/// The scenario text with the values replaced. rewriteYamlText() keeps the file as it is (comments,
/// order, layout) and replaces only the scalars of the given keys in place (found through the
/// parser's line/column marks); when a key is missing from the file, or its value is not a plain
/// one-line scalar, the whole tree is emitted instead (valid YAML with the same keys and the new
/// values, comments lost) and a comment line says so. `header` (lines) is put in comments at the top.
std::string rewriteYamlText(const std::string& original_text,
                            const std::vector<std::pair<std::string, YAML::Node>>& values,
                            const std::string& header);

/// The text of the scenario file at `path` with `key_values` ("key=value", as parseKeyValue) written
/// in (rewriteYamlText, no header). Throws core::InvalidInput naming the file when it cannot be read
/// or parsed, and naming the text of a malformed key=value.
std::string configTextWithValues(const std::string& path, const std::vector<std::string>& key_values);

/// A scenario file with `key_values` applied: ConfigNode::loadFile when there are none; otherwise
/// configTextWithValues() read through ConfigNode, so the scenario's strict loader still rejects a key
/// it does not know and a wrong type. Relative paths in the file resolve against its folder as with
/// loadFile; messages name the file "with --set" (their line numbers are the file's when the keys
/// were edited in place).
ConfigNode loadConfigWithValues(const std::string& path, const std::vector<std::string>& key_values);

/// The command-line help of every --set option (scenario apps, viewline_tune, benches).
inline constexpr const char* kSetOptionHelp =
    "KEY=VALUE: change one key of the --config file for this run (repeatable; dotted keys, list items as "
    "name[i], YAML values: --set camera.fps=60 --set filter.model=ct); unknown keys are refused";

}  // namespace viewline::io
