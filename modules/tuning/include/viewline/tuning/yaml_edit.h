#pragma once
// Dotted config keys ("tracker.accel_psd", "cameras[1].hfov_deg") on YAML trees, and writing a
// scenario file back with some values replaced.
//
// rewriteYamlText() keeps the user's file as it is (comments, order, layout) and replaces only
// the scalars of the given keys in place (found through the parser's line/column marks); when a
// key is missing from the file, or its value is not a plain one-line scalar, the whole tree is
// emitted instead (valid YAML with the same keys, comments lost) and a header comment says so.

#include <optional>
#include <string>
#include <utility>
#include <vector>
#include <yaml-cpp/yaml.h>

#include "viewline/io/config.h"

namespace viewline::tuning {

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

/// The text of a scalar node ("0.5", "mahalanobis"); "[...]" rendering of sequences.
std::string scalarText(const YAML::Node& value);

/// YAML text of a node (block style).
std::string emitYaml(const YAML::Node& node);

/// "key=value" (a command line's --set): the dotted key and the value parsed as YAML ("0.3", "[1, 2]",
/// "ct"). Throws core::InvalidInput naming the text when there is no '=', the key is malformed or the
/// value is not YAML.
std::pair<std::string, YAML::Node> parseKeyValue(const std::string& text);

/// A scenario file with `key_values` ("key=value", as parseKeyValue) applied: io::ConfigNode::loadFile
/// when there are none; otherwise the file's tree with the values set (maps created as needed), read
/// back through io::ConfigNode, so the scenario's strict loader still rejects a key it does not know
/// and a wrong type. Relative paths in the file resolve against its folder as with loadFile; messages
/// name the file "with --set" (their line numbers are those of the edited tree).
io::ConfigNode loadConfigWithValues(const std::string& path, const std::vector<std::string>& key_values);

/// The scenario text with the values replaced (see the file comment). `header` is put in a
/// comment at the top.
std::string rewriteYamlText(const std::string& original_text,
                            const std::vector<std::pair<std::string, YAML::Node>>& values,
                            const std::string& header);

}  // namespace viewline::tuning

namespace viewline::tuning {

/// The string scalars of a scenario tree that name a file or folder relative to the config's own
/// folder (scenario loaders resolve relative paths such as `rig: ../calib/rigs/pan_tilt` against
/// the directory of the config file, io::ConfigNode::getPath), re-expressed relative to
/// `to_dir`, as (dotted key, new value) pairs for rewriteYamlText(). A config written into
/// another folder (the session's best_config.yaml, autotuned_config.yaml) then still finds them.
/// A scalar counts as a path when it is relative, contains '/' or '.', and exists relative to
/// `from_dir`; absolute paths and other scalars are left alone. Where no relative form exists
/// the absolute path is used.
std::vector<std::pair<std::string, YAML::Node>> relocatedPaths(const YAML::Node& root, const std::string& from_dir,
                                                                 const std::string& to_dir);

}  // namespace viewline::tuning
