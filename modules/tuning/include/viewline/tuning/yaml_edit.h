#pragma once
// Writing a scenario file back with some values replaced (the session's best_config.yaml). The
// dotted-key edits of YAML trees it builds on (io::withValue, io::findKey, io::loadConfigWithValues
// for --set) live in viewline/io/config_edit.h.
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

#include "viewline/io/config_edit.h"

namespace viewline::tuning {

/// The text of a scalar node ("0.5", "mahalanobis"); "[...]" rendering of sequences.
std::string scalarText(const YAML::Node& value);

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
