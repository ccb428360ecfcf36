#include "viewline/io/config_edit.h"

#include <algorithm>
#include <cctype>
#include <filesystem>
#include <fstream>
#include <sstream>

#include "viewline/core/error.h"

namespace viewline::io {

using core::InvalidInput;

std::vector<KeySegment> parseDottedKey(const std::string& dotted) {
  std::vector<KeySegment> out;
  std::string part;
  std::istringstream is(dotted);
  if (dotted.empty()) throw InvalidInput("empty parameter key");
  while (std::getline(is, part, '.')) {
    KeySegment s;
    const auto br = part.find('[');
    if (br == std::string::npos) {
      s.key = part;
    } else {
      if (part.back() != ']' || br + 2 > part.size() - 1)
        throw InvalidInput("parameter key '" + dotted + "': malformed list index in '" + part + "'");
      s.key = part.substr(0, br);
      const std::string idx = part.substr(br + 1, part.size() - br - 2);
      if (idx.empty() || !std::all_of(idx.begin(), idx.end(), [](char c) { return std::isdigit(static_cast<unsigned char>(c)) != 0; }))
        throw InvalidInput("parameter key '" + dotted + "': list index must be a number in '" + part + "'");
      if (idx.size() > 9)  // std::stoi would throw std::out_of_range past INT_MAX (found by fuzz_config_set)
        throw InvalidInput("parameter key '" + dotted + "': list index too large in '" + part + "'");
      s.index = std::stoi(idx);
    }
    if (s.key.empty()) throw InvalidInput("parameter key '" + dotted + "': empty segment");
    out.push_back(s);
  }
  if (out.empty() || dotted.back() == '.') throw InvalidInput("parameter key '" + dotted + "': empty segment");
  return out;
}

std::pair<std::string, YAML::Node> parseKeyValue(const std::string& text) {
  const auto eq = text.find('=');
  if (eq == std::string::npos || eq == 0) throw InvalidInput("'" + text + "': expected key=value (e.g. camera.fps=60)");
  const std::string key = text.substr(0, eq);
  parseDottedKey(key);  // throws on a malformed key
  YAML::Node value;
  try {
    value = YAML::Load(text.substr(eq + 1));
  } catch (const YAML::Exception& e) {
    throw InvalidInput("'" + text + "': the value is not YAML (" + e.msg + ")");
  }
  if (!value.IsDefined() || value.IsNull()) throw InvalidInput("'" + text + "': empty value");
  return {key, value};
}

ConfigNode loadConfigWithValues(const std::string& path, const std::vector<std::string>& key_values) {
  if (key_values.empty()) return ConfigNode::loadFile(path);
  const std::string base = std::filesystem::absolute(path).parent_path().string();
  return ConfigNode::fromString(configTextWithValues(path, key_values), path + " (with --set)", base);
}

std::optional<YAML::Node> findKey(const YAML::Node& root, const std::string& dotted) {
  YAML::Node cur = root;
  for (const KeySegment& s : parseDottedKey(dotted)) {
    if (!cur.IsMap()) return std::nullopt;
    const YAML::Node& cc = cur;
    YAML::Node next = cc[s.key];
    if (!next.IsDefined()) return std::nullopt;
    if (s.index >= 0) {
      if (!next.IsSequence() || static_cast<std::size_t>(s.index) >= next.size()) return std::nullopt;
      const YAML::Node& cn = next;
      YAML::Node item = cn[static_cast<std::size_t>(s.index)];
      next.reset(item);
    }
    cur.reset(next);
  }
  return cur;
}

YAML::Node withValue(const YAML::Node& root, const std::string& dotted, const YAML::Node& value) {
  YAML::Node copy = YAML::Clone(root);
  const std::vector<KeySegment> segs = parseDottedKey(dotted);
  YAML::Node cur = copy;
  for (std::size_t i = 0; i < segs.size(); ++i) {
    const KeySegment& s = segs[i];
    const bool last = i + 1 == segs.size();
    if (!cur.IsMap() && !cur.IsNull())
      throw InvalidInput("parameter key '" + dotted + "': '" + s.key + "' is under a value that is not a map");
    if (last && s.index < 0) {
      cur[s.key] = YAML::Clone(value);
      break;
    }
    YAML::Node next = cur[s.key];
    if (s.index >= 0) {
      if (!next.IsSequence() || static_cast<std::size_t>(s.index) >= next.size())
        throw InvalidInput("parameter key '" + dotted + "': '" + s.key + "' has no item " + std::to_string(s.index));
      if (last) {
        next[static_cast<std::size_t>(s.index)] = YAML::Clone(value);
        break;
      }
      YAML::Node item = next[static_cast<std::size_t>(s.index)];
      cur.reset(item);
    } else {
      if (!next.IsDefined() || next.IsNull()) {
        cur[s.key] = YAML::Node(YAML::NodeType::Map);
        next.reset(cur[s.key]);
      }
      cur.reset(next);
    }
  }
  return copy;
}

YAML::Node withValues(const YAML::Node& root, const std::vector<std::pair<std::string, YAML::Node>>& values) {
  YAML::Node out = YAML::Clone(root);
  for (const auto& [k, v] : values) out = withValue(out, k, v);
  return out;
}

std::string emitYaml(const YAML::Node& node) {
  YAML::Emitter e;
  e << node;
  return std::string(e.c_str()) + "\n";
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
    const std::optional<YAML::Node> n = findKey(root, key);
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
  return head + "# (re-emitted: comments of the original file are not kept)\n" +
         emitYaml(withValues(root, values));
}

std::string configTextWithValues(const std::string& path, const std::vector<std::string>& key_values) {
  std::vector<std::pair<std::string, YAML::Node>> kv;
  for (const std::string& s : key_values) kv.push_back(parseKeyValue(s));
  std::error_code ec;
  if (std::filesystem::is_directory(path, ec))  // else yaml-cpp's read fails with "basic_filebuf::underflow", unnamed
    throw core::InvalidInput(path + ": is a directory (expected a YAML config file)");
  ConfigNode::loadFile(path);  // the file's own errors (missing, syntax, duplicate keys) with its own line numbers
  std::ifstream in(path);
  std::ostringstream text;
  text << in.rdbuf();
  return kv.empty() ? text.str() : rewriteYamlText(text.str(), kv, "");
}

}  // namespace viewline::io
