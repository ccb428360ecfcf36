#include "viewline/tuning/yaml_edit.h"

#include <algorithm>
#include <filesystem>
#include <sstream>

namespace viewline::tuning {

std::string scalarText(const YAML::Node& value) {
  if (value.IsScalar()) return value.Scalar();
  YAML::Emitter e;
  e << YAML::Flow << value;
  return e.c_str();
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
