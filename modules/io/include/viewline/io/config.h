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
class ConfigRecorder;  // the key recorder, below ConfigNode
}  // namespace viewline::io

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
    const KeyNote note = noteDefault(key, [] { return configTypeName<T>(); }, [&] { return configValueText(fallback); });
    return has(key) ? get<T>(key) : fallback;
  }

  /// A value that may also be the word `auto` (chosen by the code that reads it): std::nullopt for
  /// `auto`, `fallback` when the key is absent; anything else that is not a T is refused as
  /// "expected <what> or auto".
  template <class T>
  std::optional<T> getOrAuto(const std::string& key, const std::optional<T>& fallback, const std::string& what) const {
    const KeyNote note = noteDefault(key, [] { return configTypeName<T>() + " or auto"; },
                                     [&] { return fallback ? configValueText(*fallback) : std::string("auto"); });
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

  // ---- key recorder: which keys a reader visits, with type and default (docs/config_reference.md) ----

  /// Attaches `recorder` to this config (root and every node read from it): from now on each
  /// get/getOr/getAngle/getChoice/getPath/child/childList/ignore notes the key it reads.
  void recordTo(std::shared_ptr<ConfigRecorder> recorder) const;
  /// Type name of a value type in the reference ("number", "integer", "[x, y, z]", ...).
  template <class T>
  static std::string configTypeName();
  /// A value as YAML text ("0.5", "true", "[1, 0, 0]", ".inf"), the way a default is shown.
  template <class T>
  static std::string configValueText(const T& value);

private:
  struct Shared {
    std::string file;
    std::string dir;
    std::set<std::string> read;       ///< key paths read as nodes (their children are checked)
    std::set<std::string> consumed;   ///< key paths read whole (scalars, vectors)
    std::shared_ptr<ConfigRecorder> recorder;  ///< null unless recordTo() was called
    std::set<std::string> probed;     ///< normalised key paths asked with has() (optional reads)
    bool noting = false;              ///< a read is being noted: the reads it makes are not noted again
  };
  /// Ends the note of one outer read (a getOr calls get<T>, whose read is the same key).
  class KeyNote {
  public:
    KeyNote() = default;
    explicit KeyNote(Shared* shared) : shared_(shared) {}
    KeyNote(const KeyNote&) = delete;
    KeyNote& operator=(const KeyNote&) = delete;
    ~KeyNote() {
      if (shared_) shared_->noting = false;
    }

  private:
    Shared* shared_ = nullptr;
  };
  /// Notes a read of `key` without a default (required, or optional when has() asked for it first).
  KeyNote noteRead(const std::string& key, const char* type) const;
  /// Notes a read of `key` of type `type()` that falls back to the default `text()` (both called
  /// only when recording, so reading without a recorder formats nothing).
  template <class F, class G>
  KeyNote noteDefault(const std::string& key, F&& type, G&& text) const {
    if (!shared_->recorder || shared_->noting) return KeyNote();
    return noteWith(key, type(), text(), true);
  }
  KeyNote noteWith(const std::string& key, const std::string& type, const std::string& default_text,
                   bool has_default) const;

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

// ---- key recorder ----------------------------------------------------------------------------

/// Every key that config readers visited, in the order the code reads them, with its type,
/// whether it is required and the default the code falls back to. One recorder may watch several
/// reads (an empty config and each shipped file): keys are united, a key first seen in a later read
/// is placed after the key read just before it.
class ConfigRecorder {
public:
  /// How a key is read: without a default and unconditionally (required), only when present
  /// (optional: absent has a meaning the code gives), or with a default value.
  enum class Presence {
    Required,  ///< read without a default and without asking has() first
    Optional,  ///< read only when present (has() asked first): absent keeps what the code chose
    Default,   ///< read with getOr and its fallback: absent means that default
  };
  /// One key: dotted path with list items as "cameras[]", type, presence and default(s).
  struct Key {
    std::string path;                   ///< "tracker.gate", "cameras[].name"
    std::string type;                   ///< "number", "integer >= 0", "one of: a, b", "section", ...
    Presence presence = Presence::Required;  ///< how the code reads it (the loosest of all reads)
    std::vector<std::string> defaults;  ///< distinct defaults seen (YAML text); more than one: derived
  };

  /// Starts a new read: keys first seen from now on are placed after the keys this read visits.
  void beginRead() { cursor_ = 0; }
  /// Records one read of `path` (list indices already normalised to []).
  void note(const std::string& path, const std::string& type, Presence presence, const std::string& default_text);
  /// The keys, in reading order.
  const std::vector<Key>& keys() const { return keys_; }
  /// The key with this path, or null.
  const Key* find(const std::string& path) const;
  /// "cameras[2].name" -> "cameras[].name" (the reference documents a list item once).
  static std::string normalisePath(const std::string& path);

private:
  std::vector<Key> keys_;
  std::size_t cursor_ = 0;  ///< where a key first seen in the current read is inserted
};

/// Reference type name of a bool key: `bool`.
template <> std::string ConfigNode::configTypeName<bool>();
/// Reference type name of an int key: `integer`.
template <> std::string ConfigNode::configTypeName<int>();
/// Reference type name of an unsigned key: `integer >= 0`.
template <> std::string ConfigNode::configTypeName<unsigned>();
/// Reference type name of a long long key: `integer`.
template <> std::string ConfigNode::configTypeName<long long>();
/// Reference type name of an unsigned long key: `integer >= 0`.
template <> std::string ConfigNode::configTypeName<unsigned long>();
/// Reference type name of an unsigned long long key: `integer >= 0`.
template <> std::string ConfigNode::configTypeName<unsigned long long>();
/// Reference type name of a double key: `number`.
template <> std::string ConfigNode::configTypeName<double>();
/// Reference type name of a std::string key: `string`.
template <> std::string ConfigNode::configTypeName<std::string>();
/// Reference type name of a list of numbers key: `list of numbers`.
template <> std::string ConfigNode::configTypeName<std::vector<double>>();
/// Reference type name of a list of integers key: `list of integers`.
template <> std::string ConfigNode::configTypeName<std::vector<int>>();
/// Reference type name of a list of strings key: `list of strings`.
template <> std::string ConfigNode::configTypeName<std::vector<std::string>>();
/// Reference type name of a 2-vector key: `[x, y]`.
template <> std::string ConfigNode::configTypeName<Eigen::Vector2d>();
/// Reference type name of a 3-vector key: `[x, y, z]`.
template <> std::string ConfigNode::configTypeName<Eigen::Vector3d>();
/// Reference type name of a vector key: `list of numbers`.
template <> std::string ConfigNode::configTypeName<Eigen::VectorXd>();
/// Reference type name of a 3x3 matrix key: `3x3 matrix, rows`.
template <> std::string ConfigNode::configTypeName<Eigen::Matrix3d>();
/// A bool default as YAML text: true / false.
template <> std::string ConfigNode::configValueText<bool>(const bool& value);
/// An int default as YAML text: decimal.
template <> std::string ConfigNode::configValueText<int>(const int& value);
/// An unsigned default as YAML text: decimal.
template <> std::string ConfigNode::configValueText<unsigned>(const unsigned& value);
/// A long long default as YAML text: decimal.
template <> std::string ConfigNode::configValueText<long long>(const long long& value);
/// An unsigned long default as YAML text: decimal.
template <> std::string ConfigNode::configValueText<unsigned long>(const unsigned long& value);
/// An unsigned long long default as YAML text: decimal.
template <> std::string ConfigNode::configValueText<unsigned long long>(const unsigned long long& value);
/// A double default as YAML text: shortest decimal that reads back exactly; .inf, .nan.
template <> std::string ConfigNode::configValueText<double>(const double& value);
/// A std::string default as YAML text: plain, or double-quoted when YAML would read it otherwise.
template <> std::string ConfigNode::configValueText<std::string>(const std::string& value);
/// A list of numbers default as YAML text: [a, b, ...].
template <> std::string ConfigNode::configValueText<std::vector<double>>(const std::vector<double>& value);
/// A list of integers default as YAML text: [a, b, ...].
template <> std::string ConfigNode::configValueText<std::vector<int>>(const std::vector<int>& value);
/// A list of strings default as YAML text: [a, b, ...].
template <> std::string ConfigNode::configValueText<std::vector<std::string>>(const std::vector<std::string>& value);
/// A 2-vector default as YAML text: [x, y].
template <> std::string ConfigNode::configValueText<Eigen::Vector2d>(const Eigen::Vector2d& value);
/// A 3-vector default as YAML text: [x, y, z].
template <> std::string ConfigNode::configValueText<Eigen::Vector3d>(const Eigen::Vector3d& value);
/// A vector default as YAML text: [a, b, ...].
template <> std::string ConfigNode::configValueText<Eigen::VectorXd>(const Eigen::VectorXd& value);
/// A 3x3 matrix default as YAML text: [[row 0], [row 1], [row 2]].
template <> std::string ConfigNode::configValueText<Eigen::Matrix3d>(const Eigen::Matrix3d& value);

}  // namespace viewline::io
