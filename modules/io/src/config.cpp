#include "viewline/io/config.h"

#include <algorithm>
#include <cctype>
#include <cmath>
#include <filesystem>
#include <limits>
#include <optional>
#include <cstdio>
#include <cstdlib>
#include <sstream>

#include "viewline/core/error.h"
#include "viewline/core/frames.h"

namespace viewline::io {
namespace {

using core::InvalidInput;

std::string markText(const std::string& file, const YAML::Mark& mark) {
  std::ostringstream os;
  os << file;
  if (mark.line >= 0) os << ':' << (mark.line + 1) << ':' << (mark.column + 1);
  return os.str();
}

std::string describe(const YAML::Node& n) {
  switch (n.Type()) {
    case YAML::NodeType::Null: return "null";
    case YAML::NodeType::Scalar: return "'" + n.Scalar() + "'";
    case YAML::NodeType::Sequence: return "a list of " + std::to_string(n.size()) + " items";
    case YAML::NodeType::Map: return "a map";
    default: return "nothing";
  }
}

// Finds the key node of `key` in a map (for its mark) — YAML::Node::operator[] gives the value.
std::optional<YAML::Node> keyNode(const YAML::Node& map, const std::string& key) {
  if (!map.IsMap()) return std::nullopt;
  for (auto it = map.begin(); it != map.end(); ++it)
    if (it->first.IsScalar() && it->first.Scalar() == key) return it->first;
  return std::nullopt;
}

// Rejects duplicate keys (yaml-cpp silently keeps one) and non-scalar keys. An alias (*a) is the
// anchored node itself: each map/list is checked once (by its position in the text), else nested
// aliases made a 400-byte file cost 10^9 visits (found by fuzzing the scenario loader).
void checkKeys(const YAML::Node& n, const std::string& file, std::set<int>& visited) {
  if ((n.IsMap() || n.IsSequence()) && n.Mark().pos >= 0 && !visited.insert(n.Mark().pos).second) return;
  if (n.IsMap()) {
    std::set<std::string> seen;
    for (auto it = n.begin(); it != n.end(); ++it) {
      if (!it->first.IsScalar())
        throw InvalidInput(markText(file, it->first.Mark()) + ": map keys must be plain names");
      if (!seen.insert(it->first.Scalar()).second)
        throw InvalidInput(markText(file, it->first.Mark()) + ": duplicate key '" + it->first.Scalar() + "'");
      checkKeys(it->second, file, visited);
    }
  } else if (n.IsSequence()) {
    for (const auto& e : n) checkKeys(e, file, visited);
  }
}

void checkKeys(const YAML::Node& n, const std::string& file) {
  std::set<int> visited;
  checkKeys(n, file, visited);
}

template <class T>
T convert(const YAML::Node& n, bool& ok) {
  ok = false;
  if (!n.IsScalar()) return T{};
  try {
    T v = n.as<T>();
    ok = true;
    return v;
  } catch (const YAML::Exception&) {
    return T{};
  }
}

// Key recorder: the type names of the reference and YAML text of defaults.
template <class T> const char* typeName();
template <> const char* typeName<bool>() { return "bool"; }
template <> const char* typeName<int>() { return "integer"; }
template <> const char* typeName<long long>() { return "integer"; }
template <> const char* typeName<unsigned>() { return "integer >= 0"; }
template <> const char* typeName<unsigned long>() { return "integer >= 0"; }
template <> const char* typeName<unsigned long long>() { return "integer >= 0"; }
template <> const char* typeName<double>() { return "number"; }
template <> const char* typeName<std::string>() { return "string"; }
template <> const char* typeName<std::vector<double>>() { return "list of numbers"; }
template <> const char* typeName<std::vector<int>>() { return "list of integers"; }
template <> const char* typeName<std::vector<std::string>>() { return "list of strings"; }
template <> const char* typeName<Eigen::VectorXd>() { return "list of numbers"; }
template <> const char* typeName<Eigen::Vector2d>() { return "[x, y]"; }
template <> const char* typeName<Eigen::Vector3d>() { return "[x, y, z]"; }
template <> const char* typeName<Eigen::Matrix3d>() { return "3x3 matrix, rows"; }

// The shortest decimal text that reads back as `v` with at most `digits` significant digits (an
// angle converted from radians, shown to 6 digits, reads "62", not "62.000000000000007"); YAML's
// .inf and .nan; -0 as 0.
std::string numberText(double v, int digits = 17) {
  if (v == 0.0) return "0";
  if (std::isnan(v)) return ".nan";
  if (std::isinf(v)) return v > 0 ? ".inf" : "-.inf";
  char buf[64];
  std::snprintf(buf, sizeof buf, "%.*g", digits, v);
  const double target = std::strtod(buf, nullptr);
  // At least the integer digits, so that 50 reads "50", not "5e+01".
  const int integer_digits = std::abs(v) >= 1.0 && std::abs(v) < 1e15 ? static_cast<int>(std::log10(std::abs(v))) + 1 : 1;
  for (int p = integer_digits; p < digits; ++p) {
    char shorter[64];
    std::snprintf(shorter, sizeof shorter, "%.*g", p, v);
    if (std::strtod(shorter, nullptr) == target) return shorter;
  }
  return buf;
}

std::string choiceType(const std::vector<std::string>& choices) {
  std::string t = "one of:";
  for (std::size_t i = 0; i < choices.size(); ++i) t += (i ? ", " : " ") + choices[i];
  return t;
}

template <class T>
std::string listText(const std::vector<T>& values) {
  std::string t = "[";
  for (std::size_t i = 0; i < values.size(); ++i) t += (i ? ", " : "") + ConfigNode::configValueText(values[i]);
  return t + "]";
}

std::string vectorText(const Eigen::VectorXd& v) {
  std::string t = "[";
  for (Eigen::Index i = 0; i < v.size(); ++i) t += (i ? ", " : "") + numberText(v(i));
  return t + "]";
}

}  // namespace

ConfigNode::ConfigNode(std::shared_ptr<Shared> shared, YAML::Node node, std::string path)
    : shared_(std::move(shared)), node_(std::move(node)), path_(std::move(path)) {}

ConfigNode ConfigNode::loadFile(const std::string& path) {
  std::error_code ec;  // the throwing overload raised filesystem_error on e.g. a name too long
  if (!std::filesystem::exists(path, ec)) throw InvalidInput(path + ": config file does not exist");
  // A directory opens as a stream on Linux and fails only when read ("basic_filebuf::underflow").
  if (std::filesystem::is_directory(path, ec)) throw InvalidInput(path + ": is a directory, expected a YAML config file");
  YAML::Node root;
  try {
    root = YAML::LoadFile(path);
  } catch (const YAML::BadFile&) {
    throw InvalidInput(path + ": cannot read the config file");
  } catch (const YAML::Exception& e) {
    throw InvalidInput(markText(path, e.mark) + ": YAML syntax error: " + e.msg);
  }
  if (!root.IsMap())
    throw InvalidInput(path + ": expected a YAML map of keys at the top level, got " + describe(root));
  checkKeys(root, path);
  auto shared = std::make_shared<Shared>();
  shared->file = path;
  shared->dir = std::filesystem::path(path).parent_path().string();
  return ConfigNode(shared, root, "");
}

ConfigNode ConfigNode::fromString(const std::string& text, const std::string& name, const std::string& base_dir) {
  YAML::Node root;
  try {
    root = YAML::Load(text);
  } catch (const YAML::Exception& e) {
    throw InvalidInput(markText(name, e.mark) + ": YAML syntax error: " + e.msg);
  }
  if (root.IsNull()) root = YAML::Node(YAML::NodeType::Map);
  if (!root.IsMap())
    throw InvalidInput(name + ": expected a YAML map of keys at the top level, got " + describe(root));
  checkKeys(root, name);
  auto shared = std::make_shared<Shared>();
  shared->file = name;
  shared->dir = base_dir;
  return ConfigNode(shared, root, "");
}

// A parsed tree read as it is: the checks fromString makes after parsing, on the same nodes (their
// marks are those of the file they were parsed from).
ConfigNode ConfigNode::fromTree(const YAML::Node& root, const std::string& name, const std::string& base_dir) {
  YAML::Node tree = root;
  if (!tree.IsDefined() || tree.IsNull()) tree = YAML::Node(YAML::NodeType::Map);
  if (!tree.IsMap())
    throw InvalidInput(name + ": expected a YAML map of keys at the top level, got " + describe(tree));
  checkKeys(tree, name);
  auto shared = std::make_shared<Shared>();
  shared->file = name;
  shared->dir = base_dir;
  return ConfigNode(shared, tree, "");
}

const std::string& ConfigNode::fileName() const { return shared_->file; }

std::string ConfigNode::keyPath(const std::string& key) const {
  if (key.empty()) return path_;
  return path_.empty() ? key : path_ + "." + key;
}

std::string ConfigNode::location(const std::string& key) const {
  if (!key.empty()) {
    const auto k = keyNode(node_, key);
    if (k) return markText(shared_->file, k->Mark());
  }
  return markText(shared_->file, node_.Mark());
}

bool ConfigNode::has(const std::string& key) const {
  if (shared_->recorder && !shared_->noting) shared_->probed.insert(ConfigRecorder::normalisePath(keyPath(key)));
  if (!node_.IsMap()) return false;
  return keyNode(node_, key).has_value();
}

void ConfigNode::fail(const std::string& key, const std::string& expected) const {
  std::string where = key.empty() ? path_ : keyPath(key);
  if (where.empty()) where = "<top level>";
  std::string got;
  if (!key.empty() && has(key)) got = ", got " + describe(node_[key]);
  throw InvalidInput(location(key) + ": key '" + where + "': expected " + expected + got);
}

YAML::Node ConfigNode::valueNode(const std::string& key, const char* expected) const {
  if (!has(key)) {
    std::string parent = path_.empty() ? "the top level" : "'" + path_ + "'";
    throw InvalidInput(location() + ": missing required key '" + keyPath(key) + "' in " + parent +
                       " (expected " + expected + ")");
  }
  shared_->consumed.insert(keyPath(key));
  return node_[key];
}

bool ConfigNode::isWord(const std::string& key, const std::string& word) const {
  if (!has(key)) return false;
  const YAML::Node n = node_[key];
  if (!n.IsScalar() || n.Scalar() != word) return false;
  shared_->consumed.insert(keyPath(key));
  return true;
}

void ConfigNode::ignore(const std::string& key) const {
  const KeyNote note = shared_->recorder ? noteWith(key, "ignored", "", false) : KeyNote();
  shared_->consumed.insert(keyPath(key));
}

// ---- scalars ---------------------------------------------------------------------------------

template <>
bool ConfigNode::get<bool>(const std::string& key) const {
  const KeyNote note = noteRead(key, typeName<bool>());
  const char* what = "a boolean (true/false)";
  bool ok = false;
  const bool v = convert<bool>(valueNode(key, what), ok);
  if (!ok) fail(key, what);
  return v;
}

template <>
long long ConfigNode::get<long long>(const std::string& key) const {
  const KeyNote note = noteRead(key, typeName<long long>());
  const char* what = "an integer";
  bool ok = false;
  const long long v = convert<long long>(valueNode(key, what), ok);
  if (!ok) fail(key, what);
  return v;
}

template <>
int ConfigNode::get<int>(const std::string& key) const {
  const KeyNote note = noteRead(key, typeName<int>());
  const long long v = get<long long>(key);
  if (v < std::numeric_limits<int>::min() || v > std::numeric_limits<int>::max())
    fail(key, "an integer in the range of int");
  return static_cast<int>(v);
}

template <>
unsigned long long ConfigNode::get<unsigned long long>(const std::string& key) const {
  const KeyNote note = noteRead(key, typeName<unsigned long long>());
  const char* what = "a non-negative integer";
  const YAML::Node n = valueNode(key, what);
  if (!n.IsScalar() || n.Scalar().empty() || n.Scalar()[0] == '-') fail(key, what);
  bool ok = false;
  const unsigned long long v = convert<unsigned long long>(n, ok);
  if (!ok) fail(key, what);
  return v;
}

template <>
unsigned long ConfigNode::get<unsigned long>(const std::string& key) const {
  const KeyNote note = noteRead(key, typeName<unsigned long>());
  const unsigned long long v = get<unsigned long long>(key);
  if (v > std::numeric_limits<unsigned long>::max()) fail(key, "a non-negative integer in range");
  return static_cast<unsigned long>(v);
}

template <>
unsigned ConfigNode::get<unsigned>(const std::string& key) const {
  const KeyNote note = noteRead(key, typeName<unsigned>());
  const unsigned long long v = get<unsigned long long>(key);
  if (v > std::numeric_limits<unsigned>::max()) fail(key, "a non-negative integer in the range of unsigned");
  return static_cast<unsigned>(v);
}

template <>
double ConfigNode::get<double>(const std::string& key) const {
  const KeyNote note = noteRead(key, typeName<double>());
  const char* what = "a finite number";
  bool ok = false;
  const double v = convert<double>(valueNode(key, what), ok);
  if (!ok || !std::isfinite(v)) fail(key, what);
  return v;
}

template <>
std::string ConfigNode::get<std::string>(const std::string& key) const {
  const KeyNote note = noteRead(key, typeName<std::string>());
  const char* what = "a string";
  const YAML::Node n = valueNode(key, what);
  if (!n.IsScalar()) fail(key, what);
  return n.Scalar();
}

// ---- lists -----------------------------------------------------------------------------------

namespace {
template <class T>
std::vector<T> readList(const ConfigNode& cfg, const YAML::Node& n, const std::string& key, const char* what,
                        const char* item_what) {
  if (!n.IsSequence()) cfg.fail(key, what);
  std::vector<T> out;
  out.reserve(n.size());
  for (std::size_t i = 0; i < n.size(); ++i) {
    bool ok = false;
    T v = convert<T>(n[i], ok);
    if constexpr (std::is_floating_point_v<T>) ok = ok && std::isfinite(v);
    if (!ok)
      throw InvalidInput(markText(cfg.fileName(), n[i].Mark()) + ": key '" + cfg.keyPath(key) + "[" +
                         std::to_string(i) + "]': expected " + item_what + ", got " + describe(n[i]));
    out.push_back(v);
  }
  return out;
}

Eigen::VectorXd toEigen(const std::vector<double>& v) {
  return Eigen::Map<const Eigen::VectorXd>(v.data(), static_cast<Eigen::Index>(v.size()));
}
}  // namespace

template <>
std::vector<double> ConfigNode::get<std::vector<double>>(const std::string& key) const {
  const KeyNote note = noteRead(key, typeName<std::vector<double>>());
  const char* what = "a list of numbers, e.g. [1.0, 2.0]";
  return readList<double>(*this, valueNode(key, what), key, what, "a finite number");
}

template <>
std::vector<int> ConfigNode::get<std::vector<int>>(const std::string& key) const {
  const KeyNote note = noteRead(key, typeName<std::vector<int>>());
  const char* what = "a list of integers, e.g. [1, 2]";
  return readList<int>(*this, valueNode(key, what), key, what, "an integer");
}

template <>
std::vector<std::string> ConfigNode::get<std::vector<std::string>>(const std::string& key) const {
  const KeyNote note = noteRead(key, typeName<std::vector<std::string>>());
  const char* what = "a list of strings, e.g. [a, b]";
  return readList<std::string>(*this, valueNode(key, what), key, what, "a string");
}

template <>
Eigen::VectorXd ConfigNode::get<Eigen::VectorXd>(const std::string& key) const {
  const KeyNote note = noteRead(key, typeName<Eigen::VectorXd>());
  return toEigen(get<std::vector<double>>(key));
}

template <>
Eigen::Vector2d ConfigNode::get<Eigen::Vector2d>(const std::string& key) const {
  const KeyNote note = noteRead(key, typeName<Eigen::Vector2d>());
  const std::vector<double> v = get<std::vector<double>>(key);
  if (v.size() != 2) fail(key, "a list of 2 numbers [x, y]");
  return {v[0], v[1]};
}

template <>
Eigen::Vector3d ConfigNode::get<Eigen::Vector3d>(const std::string& key) const {
  const KeyNote note = noteRead(key, typeName<Eigen::Vector3d>());
  const std::vector<double> v = get<std::vector<double>>(key);
  if (v.size() != 3) fail(key, "a list of 3 numbers [x, y, z]");
  return {v[0], v[1], v[2]};
}

template <>
Eigen::Matrix3d ConfigNode::get<Eigen::Matrix3d>(const std::string& key) const {
  const KeyNote note = noteRead(key, typeName<Eigen::Matrix3d>());
  const char* what = "a 3x3 matrix as 3 rows of 3 numbers, e.g. [[1,0,0],[0,1,0],[0,0,1]]";
  const YAML::Node n = valueNode(key, what);
  if (!n.IsSequence() || n.size() != 3) fail(key, what);
  Eigen::Matrix3d m;
  for (std::size_t r = 0; r < 3; ++r) {
    const auto row = readList<double>(*this, n[r], key, what, "a finite number");
    if (row.size() != 3) fail(key, what);
    for (std::size_t c = 0; c < 3; ++c) m(static_cast<Eigen::Index>(r), static_cast<Eigen::Index>(c)) = row[c];
  }
  return m;
}

// ---- helpers ---------------------------------------------------------------------------------

double ConfigNode::getAngle(const std::string& key) const {
  const KeyNote note = noteRead(key, "angle, degrees");
  if (key.size() < 4 || key.compare(key.size() - 4, 4, "_deg") != 0)
    throw core::Error("ConfigNode::getAngle('" + key + "'): angle keys must end in _deg");
  return core::deg2rad(get<double>(key));
}

double ConfigNode::getAngleOr(const std::string& key, double fallback_rad) const {
  const KeyNote note = noteDefault(key, [] { return std::string("angle, degrees"); },
                                   [&] { return numberText(core::rad2deg(fallback_rad), 6); });
  return has(key) ? getAngle(key) : fallback_rad;
}

std::string ConfigNode::getChoice(const std::string& key, const std::vector<std::string>& choices) const {
  const KeyNote note = shared_->recorder ? noteWith(key, choiceType(choices), "", false) : KeyNote();
  const std::string v = get<std::string>(key);
  if (std::find(choices.begin(), choices.end(), v) == choices.end()) {
    std::string list;
    for (const auto& c : choices) list += (list.empty() ? "" : ", ") + c;
    fail(key, "one of: " + list);
  }
  return v;
}

std::string ConfigNode::getChoiceOr(const std::string& key, const std::vector<std::string>& choices,
                                    const std::string& fallback) const {
  const KeyNote note = noteDefault(key, [&] { return choiceType(choices); }, [&] { return configValueText(fallback); });
  return has(key) ? getChoice(key, choices) : fallback;
}

std::string ConfigNode::getPath(const std::string& key) const {
  const KeyNote note = noteRead(key, "path (relative to the config file)");
  const std::string v = get<std::string>(key);
  if (v.empty()) fail(key, "a non-empty file path");
  const std::filesystem::path p(v);
  if (p.is_absolute() || shared_->dir.empty()) return v;
  return (std::filesystem::path(shared_->dir) / p).string();
}

ConfigNode ConfigNode::child(const std::string& key) const {
  const KeyNote note = noteRead(key, "section");
  const char* what = "a map of keys";
  if (!has(key)) {
    std::string parent = path_.empty() ? "the top level" : "'" + path_ + "'";
    throw InvalidInput(location() + ": missing required section '" + keyPath(key) + "' in " + parent +
                       " (expected " + what + ")");
  }
  const YAML::Node n = node_[key];
  if (n.IsNull()) {  // "section:" with nothing under it: an empty map
    shared_->consumed.insert(keyPath(key));
    return ConfigNode(shared_, YAML::Node(YAML::NodeType::Map), keyPath(key));
  }
  if (!n.IsMap()) fail(key, what);
  shared_->read.insert(keyPath(key));
  return ConfigNode(shared_, n, keyPath(key));
}

std::vector<ConfigNode> ConfigNode::childList(const std::string& key) const {
  const KeyNote note = noteRead(key, "list of sections");
  const char* what = "a list of maps";
  if (!has(key)) {
    std::string parent = path_.empty() ? "the top level" : "'" + path_ + "'";
    throw InvalidInput(location() + ": missing required list '" + keyPath(key) + "' in " + parent +
                       " (expected " + what + ")");
  }
  const YAML::Node n = node_[key];
  if (!n.IsSequence()) fail(key, what);
  shared_->read.insert(keyPath(key));
  std::vector<ConfigNode> out;
  for (std::size_t i = 0; i < n.size(); ++i) {
    const std::string p = keyPath(key) + "[" + std::to_string(i) + "]";
    if (!n[i].IsMap())
      throw InvalidInput(markText(shared_->file, n[i].Mark()) + ": key '" + p + "': expected a map of keys, got " +
                         describe(n[i]));
    shared_->read.insert(p);
    out.push_back(ConfigNode(shared_, n[i], p));
  }
  return out;
}

void ConfigNode::collectUnknown(const YAML::Node& node, const std::string& path,
                                std::vector<std::string>& errors) const {
  if (node.IsMap()) {
    std::vector<std::string> known;
    for (auto it = node.begin(); it != node.end(); ++it) {
      const std::string k = it->first.Scalar();
      const std::string p = path.empty() ? k : path + "." + k;
      if (shared_->consumed.count(p) || shared_->read.count(p)) known.push_back(k);
    }
    for (auto it = node.begin(); it != node.end(); ++it) {
      const std::string k = it->first.Scalar();
      const std::string p = path.empty() ? k : path + "." + k;
      if (shared_->consumed.count(p)) continue;
      if (shared_->read.count(p)) {
        collectUnknown(it->second, p, errors);
        continue;
      }
      std::string msg = markText(shared_->file, it->first.Mark()) + ": unknown key '" + p + "'";
      if (!known.empty()) {
        msg += " (keys used here: ";
        for (std::size_t i = 0; i < known.size(); ++i) msg += (i ? ", " : "") + known[i];
        msg += ")";
      }
      errors.push_back(msg);
    }
  } else if (node.IsSequence()) {
    for (std::size_t i = 0; i < node.size(); ++i) {
      const std::string p = path + "[" + std::to_string(i) + "]";
      if (shared_->read.count(p)) collectUnknown(node[i], p, errors);
    }
  }
}

void ConfigNode::finish() const {
  std::vector<std::string> errors;
  collectUnknown(node_, path_, errors);
  if (errors.empty()) return;
  std::string msg = errors.front();
  for (std::size_t i = 1; i < errors.size(); ++i) msg += "\n" + errors[i];
  throw InvalidInput(msg);
}

// ---- key recorder ----------------------------------------------------------------------------

void ConfigNode::recordTo(std::shared_ptr<ConfigRecorder> recorder) const {
  shared_->recorder = std::move(recorder);
  shared_->probed.clear();
  if (shared_->recorder) shared_->recorder->beginRead();
}

ConfigNode::KeyNote ConfigNode::noteRead(const std::string& key, const char* type) const {
  return noteWith(key, type, "", false);
}

ConfigNode::KeyNote ConfigNode::noteWith(const std::string& key, const std::string& type,
                                         const std::string& default_text, bool has_default) const {
  if (!shared_->recorder || shared_->noting) return KeyNote();
  const std::string path = ConfigRecorder::normalisePath(keyPath(key));
  // A read without a default is optional when the code asked has() first (absent keeps a value the
  // code chose), required otherwise.
  const ConfigRecorder::Presence presence = has_default ? ConfigRecorder::Presence::Default
                                            : shared_->probed.count(path) ? ConfigRecorder::Presence::Optional
                                                                          : ConfigRecorder::Presence::Required;
  shared_->recorder->note(path, type, presence, default_text);
  shared_->noting = true;
  return KeyNote(shared_.get());
}

#define VIEWLINE_CONFIG_TYPE(T)                                  \
  template <>                                                    \
  std::string ConfigNode::configTypeName<T>() {                  \
    return typeName<T>();                                        \
  }
VIEWLINE_CONFIG_TYPE(bool)
VIEWLINE_CONFIG_TYPE(int)
VIEWLINE_CONFIG_TYPE(unsigned)
VIEWLINE_CONFIG_TYPE(long long)
VIEWLINE_CONFIG_TYPE(unsigned long)
VIEWLINE_CONFIG_TYPE(unsigned long long)
VIEWLINE_CONFIG_TYPE(double)
VIEWLINE_CONFIG_TYPE(std::string)
VIEWLINE_CONFIG_TYPE(std::vector<double>)
VIEWLINE_CONFIG_TYPE(std::vector<int>)
VIEWLINE_CONFIG_TYPE(std::vector<std::string>)
VIEWLINE_CONFIG_TYPE(Eigen::Vector2d)
VIEWLINE_CONFIG_TYPE(Eigen::Vector3d)
VIEWLINE_CONFIG_TYPE(Eigen::VectorXd)
VIEWLINE_CONFIG_TYPE(Eigen::Matrix3d)
#undef VIEWLINE_CONFIG_TYPE

template <> std::string ConfigNode::configValueText<bool>(const bool& value) { return value ? "true" : "false"; }
template <> std::string ConfigNode::configValueText<int>(const int& value) { return std::to_string(value); }
template <> std::string ConfigNode::configValueText<unsigned>(const unsigned& value) { return std::to_string(value); }
template <> std::string ConfigNode::configValueText<long long>(const long long& value) { return std::to_string(value); }
template <>
std::string ConfigNode::configValueText<unsigned long>(const unsigned long& value) {
  return std::to_string(value);
}
template <>
std::string ConfigNode::configValueText<unsigned long long>(const unsigned long long& value) {
  return std::to_string(value);
}
template <> std::string ConfigNode::configValueText<double>(const double& value) { return numberText(value); }
template <>
std::string ConfigNode::configValueText<std::string>(const std::string& value) {
  // Plain when YAML reads it back as this string; quoted otherwise (empty, a number-like word).
  bool plain = !value.empty() && (std::isalpha(static_cast<unsigned char>(value[0])) || value[0] == '_' || value[0] == '/');
  for (const char c : value)
    if (!(std::isalnum(static_cast<unsigned char>(c)) || c == '_' || c == '-' || c == '.' || c == '/')) plain = false;
  for (const char* word : {"true", "false", "yes", "no", "on", "off", "null", "y", "n"})
    if (value == word) plain = false;
  if (plain) return value;
  std::string t = "\"";
  for (const char c : value) t += (c == '"' || c == '\\') ? std::string("\\") + c : std::string(1, c);
  return t + "\"";
}
template <>
std::string ConfigNode::configValueText<std::vector<double>>(const std::vector<double>& value) {
  return listText(value);
}
template <>
std::string ConfigNode::configValueText<std::vector<int>>(const std::vector<int>& value) {
  return listText(value);
}
template <>
std::string ConfigNode::configValueText<std::vector<std::string>>(const std::vector<std::string>& value) {
  return listText(value);
}
template <>
std::string ConfigNode::configValueText<Eigen::Vector2d>(const Eigen::Vector2d& value) {
  return vectorText(value);
}
template <>
std::string ConfigNode::configValueText<Eigen::Vector3d>(const Eigen::Vector3d& value) {
  return vectorText(value);
}
template <>
std::string ConfigNode::configValueText<Eigen::VectorXd>(const Eigen::VectorXd& value) {
  return vectorText(value);
}
template <>
std::string ConfigNode::configValueText<Eigen::Matrix3d>(const Eigen::Matrix3d& value) {
  std::string t = "[";
  for (Eigen::Index r = 0; r < 3; ++r) t += (r ? ", " : "") + vectorText(value.row(r).transpose());
  return t + "]";
}

std::string ConfigRecorder::normalisePath(const std::string& path) {
  std::string out;
  out.reserve(path.size());
  for (std::size_t i = 0; i < path.size(); ++i) {
    out += path[i];
    if (path[i] == '[') {
      while (i + 1 < path.size() && path[i + 1] != ']') ++i;
    }
  }
  return out;
}

const ConfigRecorder::Key* ConfigRecorder::find(const std::string& path) const {
  for (const Key& k : keys_)
    if (k.path == path) return &k;
  return nullptr;
}

void ConfigRecorder::note(const std::string& path, const std::string& type, Presence presence,
                          const std::string& default_text) {
  auto it = std::find_if(keys_.begin(), keys_.end(), [&](const Key& k) { return k.path == path; });
  if (it == keys_.end()) {
    it = keys_.insert(keys_.begin() + static_cast<std::ptrdiff_t>(std::min(cursor_, keys_.size())), Key{path, type, presence, {}});
  } else if (it->type != type && it->type.find(type) == std::string::npos) {
    it->type += " | " + type;  // read as two types on two paths of the code: both are documented
  }
  // A key read with a default anywhere has that default; optional beats required (some branch of
  // the code reads it only when present).
  if (static_cast<int>(presence) > static_cast<int>(it->presence)) it->presence = presence;
  if (presence == Presence::Default && std::find(it->defaults.begin(), it->defaults.end(), default_text) == it->defaults.end())
    it->defaults.push_back(default_text);
  cursor_ = static_cast<std::size_t>(it - keys_.begin()) + 1;
}

}  // namespace viewline::io
