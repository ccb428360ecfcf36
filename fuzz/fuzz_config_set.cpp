// --set KEY=VALUE on a scenario file (io::loadConfigWithValues, config_edit.h): the edits are
// parsed (parseKeyValue), written into the file's text in place or by re-emitting the tree
// (rewriteYamlText) and the result is read back through ConfigNode.
//
// Input layout: up to 4 lines of KEY=VALUE items, a line "%%", then the scenario file's text
// (no "%%" line: the whole input is one KEY=VALUE item applied to a fixed small config).

#include <sstream>
#include <string>
#include <vector>

#include "fuzz_util.h"
#include "viewline/io/config_edit.h"

namespace {
const char* const kDefaultConfig =
    "camera:\n  fps: 30   # frames per second\n  hfov_deg: 60\nfilter:\n  model: cv\n  q: [1, 2, 3]\n"
    "cameras:\n  - name: left\n    sigma_px: 0.5\n  - name: right\n    sigma_px: 0.7\n";
}

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  using viewline::fuzz::rejectOk;
  namespace io = viewline::io;
  const std::string input = viewline::fuzz::asText(data, size);
  std::vector<std::string> sets;
  std::string config = kDefaultConfig;
  const auto sep = input.find("\n%%\n");
  if (sep == std::string::npos) {
    sets.push_back(input);
  } else {
    std::istringstream is(input.substr(0, sep));
    for (std::string line; std::getline(is, line) && sets.size() < 4;) sets.push_back(line);
    config = input.substr(sep + 4);
  }
  for (const std::string& s : sets) rejectOk([&] { io::parseKeyValue(s); });
  const std::string path = viewline::fuzz::scratchFile("config.yaml", config);
  rejectOk([&] {
    const io::ConfigNode cfg = io::loadConfigWithValues(path, sets);
    cfg.finish();
  });
  // The re-emitting path of rewriteYamlText, on the parsed tree.
  rejectOk([&] {
    std::vector<std::pair<std::string, YAML::Node>> kv;
    for (const std::string& s : sets) kv.push_back(io::parseKeyValue(s));
    const io::ConfigNode cfg = io::ConfigNode::fromString(config, "fuzz.yaml");
    for (const auto& [k, v] : kv) io::findKey(cfg.yaml(), k);
    io::emitYaml(io::withValues(cfg.yaml(), kv));
  });
  return 0;
}
