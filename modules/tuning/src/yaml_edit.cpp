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

std::string rewriteYamlText(const std::string& original_text,
                            const std::vector<std::pair<std::string, YAML::Node>>& values,
                            const std::string& header) {
  std::string head;
  {
    std::istringstream hs(header);
    std::string l;
    while (std::getline(hs, l)) head += "# " + l + "\n";
  }
  YAML::Node root = YAML::Load(original_text);
  std::vector<std::string> lines;
  {
    std::istringstream is(original_text);
    std::string l;
    while (std::getline(is, l)) lines.push_back(l);
  }
  struct Edit {
    int line, col;
    std::size_t len;
    std::string text;
  };
  std::vector<Edit> edits;
  bool in_place = true;
  for (const auto& [key, value] : values) {
    const std::optional<YAML::Node> n = io::findKey(root, key);
    if (!n || !n->IsScalar() || !value.IsScalar()) {
      in_place = false;
      break;
    }
    const YAML::Mark m = n->Mark();
    const std::string raw = n->Scalar();
    if (m.line < 0 || static_cast<std::size_t>(m.line) >= lines.size() || raw.empty() ||
        lines[static_cast<std::size_t>(m.line)].compare(static_cast<std::size_t>(m.column), raw.size(), raw) != 0) {
      in_place = false;
      break;
    }
    std::string text = value.Scalar();
    // Quote text that YAML would not read back as the same plain scalar.
    if (text.empty() || text.find_first_of(":#{}[],&*!|>'\"%@`") != std::string::npos) text = "\"" + text + "\"";
    edits.push_back({m.line, m.column, raw.size(), text});
  }
  if (in_place) {
    std::sort(edits.begin(), edits.end(), [](const Edit& a, const Edit& b) {
      return a.line != b.line ? a.line > b.line : a.col > b.col;
    });
    for (const Edit& e : edits)
      lines[static_cast<std::size_t>(e.line)].replace(static_cast<std::size_t>(e.col), e.len, e.text);
    std::string out = head;
    for (const std::string& l : lines) out += l + "\n";
    return out;
  }
  return head + "# (re-emitted by viewline_tune: comments of the original file are not kept)\n" +
         io::emitYaml(io::withValues(root, values));
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
