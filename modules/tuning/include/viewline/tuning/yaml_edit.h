#pragma once
// What the tuning sessions add to the config edits of viewline/io/config_edit.h (dotted keys,
// io::rewriteYamlText, --set): values as table text, a scenario tree with a sweep setting's values
// that still names the file's lines, and the relative paths of a config re-expressed for a copy
// written into another folder (the session's best_config.yaml).

#include <optional>
#include <string>
#include <utility>
#include <vector>
#include <yaml-cpp/yaml.h>

#include "viewline/io/config_edit.h"

namespace viewline::tuning {

/// The text of a scalar node ("0.5", "mahalanobis"); "[...]" rendering of sequences.
std::string scalarText(const YAML::Node& value);

/// `root` with each (dotted key, value) of `values` set, for a scenario loader to read directly
/// (io::ConfigNode::fromTree). The result shares every node of `root` that no edit touches, so
/// those keep the line/column marks of the file they were parsed from and messages about them name
/// its lines; the maps and lists on the path to an edited key are new, and the values are copies
/// without marks (they come from the sweep, not the file). Missing map keys are created; list items
/// must exist. `root` is not changed. Throws core::InvalidInput naming the key when a segment is
/// under a value that is not a map, or names a list item that does not exist.
YAML::Node editedTree(const YAML::Node& root, const std::vector<std::pair<std::string, YAML::Node>>& values);

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
