#pragma once
// Strict YAML scenario configs. Every app reads one YAML file with documented
// keys; a key that no code reads is an error (a typo must not silently leave a
// default in place).
//
//   auto cfg = io::ConfigNode::loadFile("config/catching.yaml");
//   const double rate = cfg.get<double>("rate_hz");                 // required
//   const int n = cfg.getOr<int>("cameras_count", 2);               // optional
//   const double pan = cfg.getAngle("pan_limit_deg");               // degrees in file, radians returned
//   auto tracker = cfg.child("tracker");                            // nested map
//   for (const auto& cam : cfg.childList("cameras")) cam.get<std::string>("name");
//   cfg.finish();   // throws InvalidInput naming file:line and key path of every unknown key
//
// Every error (missing key, wrong type, unknown key, out-of-range value via
// fail()) is a core::InvalidInput whose message starts with "<file>:<line>:<col>:"
// and names the key path (e.g. "tracker.cameras[1].sigma_px") and what was expected.
//
// Supported value types for get/getOr: bool, int, unsigned, long long, std::uint64_t,
// double, std::string, std::vector<double>, std::vector<int>, std::vector<std::string>,
// Eigen::Vector2d, Eigen::Vector3d, Eigen::VectorXd, Eigen::Matrix3d (3 rows of 3).

#include <Eigen/Core>
#include <cstdint>
#include <memory>
#include <optional>
#include <set>
#include <string>
#include <vector>
#include <yaml-cpp/yaml.h>

#include "viewline/core/error.h"

namespace viewline::io {

/// A node of a strict YAML config: typed reads with file:line:col errors, and a check that every key was read.
class ConfigNode {
public:
  /// Parses a YAML file; throws InvalidInput naming the file (and line for syntax errors,
  /// duplicate keys) when it cannot be read or parsed. The root must be a map.
  static ConfigNode loadFile(const std::string& path);
  /// Parses YAML text; `name` stands for the file name in messages. Relative paths (getPath) are
  /// resolved against `base_dir` (empty: returned as written), as loadFile resolves them against
  /// the file's folder.
  static ConfigNode fromString(const std::string& text, const std::string& name = "<string>",
                               const std::string& base_dir = "");
  /// Reads a tree already parsed (and perhaps edited, e.g. a sweep setting) without a text round
  /// trip: `name` names the file in messages, relative paths (getPath) resolve against `base_dir`.
  /// Nodes keep the line/column marks the parser gave them, so errors name `name:line:col` where
  /// the node came from the file; nodes built in code carry no mark and their errors name the file
  /// alone. The tree is shared, not copied: the caller must not change it while the node is read.
  /// A null root is an empty map; any other non-map root, a non-scalar or duplicate key is refused.
  static ConfigNode fromTree(const YAML::Node& root, const std::string& name, const std::string& base_dir = "");

  /// True when the map has this key (does not mark it as read).
  bool has(const std::string& key) const;

  /// Required value; throws when missing or of the wrong type.
  template <class T>
  T get(const std::string& key) const;

  /// Optional value: `fallback` when the key is absent; throws when present with the wrong type.
  template <class T>
  T getOr(const std::string& key, const T& fallback) const {
    return has(key) ? get<T>(key) : fallback;
  }

  /// A value that may also be the word `auto` (chosen by the code that reads it): std::nullopt for
  /// `auto`, `fallback` when the key is absent; anything else that is not a T is refused as
  /// "expected <what> or auto".
  template <class T>
  std::optional<T> getOrAuto(const std::string& key, const std::optional<T>& fallback, const std::string& what) const {
    if (!has(key)) return fallback;
    if (isWord(key, "auto")) return std::nullopt;
    try {
      return get<T>(key);
    } catch (const core::InvalidInput&) {
      fail(key, what + " or auto");
    }
  }
  /// True (and the key marked as read) when the key holds exactly this plain scalar word.
  bool isWord(const std::string& key, const std::string& word) const;

  /// An angle: the key must end in "_deg"; the file holds degrees, the result is radians.
  double getAngle(const std::string& key) const;
  /// Optional angle: the `_deg` key in degrees converted to radians, `fallback_rad` (rad) when absent.
  double getAngleOr(const std::string& key, double fallback_rad) const;

  /// A string that must be one of `choices`; the error lists them.
  std::string getChoice(const std::string& key, const std::vector<std::string>& choices) const;
  /// Optional choice among `choices`: `fallback` when absent, the error lists the choices otherwise.
  std::string getChoiceOr(const std::string& key, const std::vector<std::string>& choices,
                          const std::string& fallback) const;

  /// A file path; relative paths are resolved against the directory of the config file.
  std::string getPath(const std::string& key) const;

  /// Nested map (required / optional) and list of maps.
  ConfigNode child(const std::string& key) const;
  /// True when the key is present (a nested map is expected there).
  bool hasChild(const std::string& key) const { return has(key); }
  /// Required list of maps under `key` (each a node with its own key path, e.g. "cameras[1]").
  std::vector<ConfigNode> childList(const std::string& key) const;

  /// Marks a key as read without reading it (a documented key that this program ignores).
  void ignore(const std::string& key) const;

  /// Throws InvalidInput naming file:line:col and the path of `key` (or of this node when
  /// `key` is empty) with "expected <expected>". For range checks by the caller:
  ///   if (rate <= 0) cfg.fail("rate_hz", "a positive number");
  [[noreturn]] void fail(const std::string& key, const std::string& expected) const;

  /// Throws InvalidInput listing every key under this node (recursively) that was never read,
  /// each with its file:line:col and key path. Call once, after reading everything.
  void finish() const;
  /// Same as finish(): throws InvalidInput for every key never read.
  void requireAllUsed() const { finish(); }

  /// Name of the file the node was read from (or the name given to fromString).
  const std::string& fileName() const;
  /// Key path of this node ("" for the root, "tracker", "cameras[0]").
  const std::string& path() const { return path_; }
  /// Path of a key of this node ("tracker.rate_hz").
  std::string keyPath(const std::string& key) const;
  /// "<file>:<line>:<col>" of a key (or of this node when key is empty or absent).
  std::string location(const std::string& key = {}) const;

  /// The underlying yaml-cpp node (read access; does not mark keys as read).
  const YAML::Node& yaml() const { return node_; }

private:
  struct Shared {
    std::string file;
    std::string dir;
    std::set<std::string> read;       ///< key paths read as nodes (their children are checked)
    std::set<std::string> consumed;   ///< key paths read whole (scalars, vectors)
  };
  ConfigNode(std::shared_ptr<Shared> shared, YAML::Node node, std::string path);
  YAML::Node valueNode(const std::string& key, const char* expected) const;  // required, marks consumed
  void collectUnknown(const YAML::Node& node, const std::string& path,
                      std::vector<std::string>& errors) const;

  std::shared_ptr<Shared> shared_;
  YAML::Node node_;
  std::string path_;
};

/// Reads a boolean (YAML true/false).
template <> bool ConfigNode::get<bool>(const std::string& key) const;
/// Reads an int; a non-integer or out-of-range value is refused.
template <> int ConfigNode::get<int>(const std::string& key) const;
/// Reads an unsigned int; a negative value is refused.
template <> unsigned ConfigNode::get<unsigned>(const std::string& key) const;
/// Reads a long long.
template <> long long ConfigNode::get<long long>(const std::string& key) const;
/// Reads an unsigned long; a negative value is refused.
template <> unsigned long ConfigNode::get<unsigned long>(const std::string& key) const;
/// Reads an unsigned long long (seeds); a negative value is refused.
template <> unsigned long long ConfigNode::get<unsigned long long>(const std::string& key) const;
/// Reads a finite double.
template <> double ConfigNode::get<double>(const std::string& key) const;
/// Reads a string scalar.
template <> std::string ConfigNode::get<std::string>(const std::string& key) const;
/// Reads a list of finite numbers.
template <> std::vector<double> ConfigNode::get<std::vector<double>>(const std::string& key) const;
/// Reads a list of integers.
template <> std::vector<int> ConfigNode::get<std::vector<int>>(const std::string& key) const;
/// Reads a list of strings.
template <> std::vector<std::string> ConfigNode::get<std::vector<std::string>>(const std::string& key) const;
/// Reads a 2-vector from a list of 2 numbers.
template <> Eigen::Vector2d ConfigNode::get<Eigen::Vector2d>(const std::string& key) const;
/// Reads a 3-vector from a list of 3 numbers.
template <> Eigen::Vector3d ConfigNode::get<Eigen::Vector3d>(const std::string& key) const;
/// Reads a vector from a list of numbers of any length.
template <> Eigen::VectorXd ConfigNode::get<Eigen::VectorXd>(const std::string& key) const;
/// Reads a 3x3 matrix from 3 rows of 3 numbers.
template <> Eigen::Matrix3d ConfigNode::get<Eigen::Matrix3d>(const std::string& key) const;

}  // namespace viewline::io
