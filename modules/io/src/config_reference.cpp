#include "viewline/io/config_reference.h"

#include <filesystem>
#include <memory>
#include <set>
#include <sstream>

#include "viewline/core/error.h"

namespace viewline::io {
namespace {

// Reads one config with the recorder attached; `expect_ok` files must read without error.
void readRecorded(const ConfigReferenceSection& section, const ConfigNode& node,
                  const std::shared_ptr<ConfigRecorder>& recorder, bool expect_ok) {
  node.recordTo(recorder);
  try {
    section.read(node);
  } catch (const core::InvalidInput&) {
    if (expect_ok) throw;
    // An empty config or a probe stops at the first missing required key or failed check; the
    // keys read up to there are recorded, the rest come from the shipped files.
  }
  node.recordTo(nullptr);
}

// Markdown table cells: a '|' would end the cell.
std::string cell(const std::string& text) {
  std::string out;
  for (const char c : text) out += c == '|' ? std::string("\\|") : std::string(1, c);
  return out;
}

std::string defaultCell(const ConfigRecorder::Key& key, const ConfigKeyDoc* doc) {
  if (doc && !doc->default_text.empty()) return cell(doc->default_text);
  switch (key.presence) {
    case ConfigRecorder::Presence::Required: return "required";
    case ConfigRecorder::Presence::Optional: return "optional";
    case ConfigRecorder::Presence::Default: break;
  }
  return "`" + cell(key.defaults.front()) + "`";
}

const ConfigKeyDoc* docOf(const ConfigReferenceSection& section, const std::string& key) {
  for (const auto& d : section.keys)
    if (d.key == key) return &d;
  return nullptr;
}

}  // namespace

ConfigRecorder recordConfigKeys(const ConfigReferenceSection& section, const std::string& config_dir) {
  auto recorder = std::make_shared<ConfigRecorder>();
  // Nothing set first: the reader's own order and every default it visits before a required key.
  readRecorded(section, ConfigNode::fromString("", "<empty " + section.name + " config>", config_dir), recorder, false);
  for (std::size_t i = 0; i < section.probes.size(); ++i) {
    const std::string name = "<" + section.name + " probe " + std::to_string(i) + ">";
    readRecorded(section, ConfigNode::fromString(section.probes[i], name, config_dir), recorder, false);
  }
  for (const std::string& file : section.shipped) {
    const std::string path = (std::filesystem::path(config_dir) / file).string();
    readRecorded(section, ConfigNode::loadFile(path), recorder, true);
  }
  return *recorder;
}

std::vector<std::string> checkConfigKeys(const ConfigReferenceSection& section, const ConfigRecorder& keys) {
  std::vector<std::string> problems;
  const std::string where = section.name + " config: ";
  std::set<std::string> documented;
  for (const auto& d : section.keys) {
    if (!documented.insert(d.key).second) problems.push_back(where + "key '" + d.key + "' has two entries");
    if (!keys.find(d.key)) problems.push_back(where + "key '" + d.key + "' has an entry but the reader never reads it");
    if (d.meaning.empty()) problems.push_back(where + "key '" + d.key + "' has no meaning");
  }
  for (const auto& k : keys.keys()) {
    const ConfigKeyDoc* d = docOf(section, k.path);
    if (!d) {
      problems.push_back(where + "key '" + k.path + "' (" + k.type + ") is read but has no entry in the key table");
      continue;
    }
    if (k.defaults.size() > 1 && d->default_text.empty()) {
      std::string seen;
      for (const auto& v : k.defaults) seen += (seen.empty() ? "" : ", ") + v;
      problems.push_back(where + "key '" + k.path + "' has different defaults in different files (" + seen +
                         "): give default_text saying what it is derived from");
    }
  }
  return problems;
}

std::string configReferenceMarkdown(const std::vector<ConfigReferenceSection>& sections,
                                    const std::vector<ConfigRecorder>& keys, const std::string& command) {
  if (sections.size() != keys.size()) throw core::Error("configReferenceMarkdown: one key record per section");
  std::ostringstream os;
  os << "# Scenario config reference\n\n"
     << "Generated from the code that reads the configs by\n\n"
     << "    " << command << "\n\n"
     << "Do not edit it by hand: the test `docs.config_reference_current` fails when this copy differs from\n"
     << "what the code reads. Each table lists every key the scenario's reader reads, in reading order,\n"
     << "found by reading an empty config and every shipped file with a key recorder attached\n"
     << "(`io::ConfigRecorder`); units and meanings come from the table next to each reader\n"
     << "(`modules/scenarios/<name>/config_keys.cpp`).\n\n"
     << "- `a.b` is key `b` of section `a`; `cameras[].name` is key `name` of each item of the list `cameras`.\n"
     << "- default: the value used when the key is absent; `required`: the file (or the enclosing section\n"
     << "  or list item, when that is present) must have the key; `optional`: absent has the meaning given.\n"
     << "- Angles are in degrees in the file (keys end in `_deg`), radians in the code; every other value\n"
     << "  is in SI units unless the unit column says otherwise.\n"
     << "- A key that no code reads is refused with its file and line, and so is a value of the wrong type.\n"
     << "- Any key can be changed on the command line with `--set KEY=VALUE` (e.g. `--set tracker.gate=none`).\n\n";
  for (const auto& s : sections) os << "- [" << s.title << "](#" << s.name << ")\n";
  for (std::size_t i = 0; i < sections.size(); ++i) {
    const auto& s = sections[i];
    os << "\n<a id=\"" << s.name << "\"></a>\n\n## " << s.title << "\n\n" << s.summary << "\n\nShipped:";
    for (std::size_t f = 0; f < s.shipped.size(); ++f) os << (f ? ", " : " ") << "`config/" << s.shipped[f] << "`";
    os << ".\n\n| key | type | unit | default | meaning |\n|---|---|---|---|---|\n";
    for (const auto& k : keys[i].keys()) {
      const ConfigKeyDoc* d = docOf(s, k.path);
      os << "| `" << k.path << "` | " << cell(k.type) << " | " << (d ? cell(d->unit) : "") << " | " << defaultCell(k, d)
         << " | " << (d ? cell(d->meaning) : "") << " |\n";
    }
  }
  return os.str();
}

}  // namespace viewline::io
