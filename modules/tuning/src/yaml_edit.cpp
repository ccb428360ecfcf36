#include "viewline/tuning/yaml_edit.h"

#include <algorithm>
#include <filesystem>
#include <sstream>

#include "viewline/core/error.h"

namespace viewline::tuning {

std::string scalarText(const YAML::Node& value) {
  if (value.IsScalar()) return value.Scalar();
  YAML::Emitter e;
  e << YAML::Flow << value;
  return e.c_str();
}

namespace {

// A copy of a value that carries no parser mark (its messages name the file, not a line of another).
YAML::Node unmarkedCopy(const YAML::Node& n) {
  if (n.IsScalar()) return YAML::Node(n.Scalar());
  if (n.IsSequence()) {
    YAML::Node c(YAML::NodeType::Sequence);
    for (const auto& e : n) c.push_back(unmarkedCopy(e));
    return c;
  }
  if (n.IsMap()) {
    YAML::Node c(YAML::NodeType::Map);
    for (auto it = n.begin(); it != n.end(); ++it) c.force_insert(unmarkedCopy(it->first), unmarkedCopy(it->second));
    return c;
  }
  return YAML::Node(YAML::NodeType::Null);
}

// A new map with the entries of `map` (the same key and value nodes), `key` set to `value`.
// (Assigning through yaml-cpp's operator[] would write into the shared value node instead.)
YAML::Node withEntry(const YAML::Node& map, const std::string& key, const YAML::Node& value) {
  YAML::Node out(YAML::NodeType::Map);
  bool found = false;
  if (map.IsDefined() && map.IsMap()) {
    for (auto it = map.begin(); it != map.end(); ++it) {
      const bool here = it->first.IsScalar() && it->first.Scalar() == key;
      out.force_insert(it->first, here ? value : it->second);
      found = found || here;
    }
  }
  if (!found) out.force_insert(YAML::Node(key), value);
  return out;
}

YAML::Node editAt(const YAML::Node& node, const std::vector<io::KeySegment>& segs, std::size_t i, const YAML::Node& value,
                  const std::string& dotted) {
  const io::KeySegment& s = segs[i];
  const bool is_map = node.IsDefined() && node.IsMap();
  if (node.IsDefined() && !is_map && !node.IsNull())
    throw core::InvalidInput("parameter key '" + dotted + "': '" + s.key + "' is under a value that is not a map");
  const bool last = i + 1 == segs.size();
  const YAML::Node child = is_map ? node[s.key] : YAML::Node();
  if (s.index < 0) return withEntry(node, s.key, last ? unmarkedCopy(value) : editAt(child, segs, i + 1, value, dotted));
  const std::size_t k = static_cast<std::size_t>(s.index);
  if (!child.IsDefined() || !child.IsSequence() || k >= child.size())
    throw core::InvalidInput("parameter key '" + dotted + "': '" + s.key + "' has no item " + std::to_string(s.index));
  YAML::Node list(YAML::NodeType::Sequence);
  for (std::size_t j = 0; j < child.size(); ++j)
    list.push_back(j != k ? child[j] : last ? unmarkedCopy(value) : editAt(child[j], segs, i + 1, value, dotted));
  return withEntry(node, s.key, list);
}

}  // namespace

YAML::Node editedTree(const YAML::Node& root, const std::vector<std::pair<std::string, YAML::Node>>& values) {
  YAML::Node out = root;
  for (const auto& [key, value] : values) out.reset(editAt(out, io::parseDottedKey(key), 0, value, key));
  return out;
}

}  // namespace viewline::tuning

namespace viewline::tuning {

namespace {

void collectRelocated(const YAML::Node& node, const std::string& key, const std::filesystem::path& from,
                      const std::filesystem::path& to, std::vector<std::pair<std::string, YAML::Node>>& out) {
  namespace fs = std::filesystem;
  if (node.IsMap()) {
    for (const auto& kv : node) {
      const std::string k = kv.first.as<std::string>();
      collectRelocated(kv.second, key.empty() ? k : key + "." + k, from, to, out);
    }
  } else if (node.IsSequence()) {
    for (std::size_t i = 0; i < node.size(); ++i)
      collectRelocated(node[i], key + "[" + std::to_string(i) + "]", from, to, out);
  } else if (node.IsScalar() && !key.empty()) {
    const std::string v = node.Scalar();
    if (v.empty() || v.find_first_of("/.") == std::string::npos) return;
    const fs::path p(v);
    if (p.is_absolute()) return;
    std::error_code ec;
    const fs::path target = fs::weakly_canonical(from / p, ec);
    if (ec || !fs::exists(target, ec)) return;
    fs::path moved = fs::relative(target, fs::weakly_canonical(to, ec), ec);
    if (ec || moved.empty()) moved = target;
    if (moved == p) return;  // already right from to_dir
    out.emplace_back(key, YAML::Node(moved.generic_string()));
  }
}

}  // namespace

std::vector<std::pair<std::string, YAML::Node>> relocatedPaths(const YAML::Node& root, const std::string& from_dir,
                                                                 const std::string& to_dir) {
  std::vector<std::pair<std::string, YAML::Node>> out;
  const std::filesystem::path from = from_dir.empty() ? std::filesystem::path(".") : std::filesystem::path(from_dir);
  const std::filesystem::path to = to_dir.empty() ? std::filesystem::path(".") : std::filesystem::path(to_dir);
  collectRelocated(root, "", from, to, out);
  return out;
}

}  // namespace viewline::tuning
