// Scenario configs (io::ConfigNode, modules/io/include/viewline/io/config.h): the strict YAML
// reader every scenario loader uses. The input is a config file; it is loaded from a file
// (loadFile, as the apps do) and from memory (fromString), then every key is read with every typed
// getter the loaders use (each either returns or throws core::InvalidInput), nested maps and lists
// of maps are walked, and finish() checks for unknown keys. The scenario-specific loaders live in
// modules/scenarios and are not linked here (fuzz/README.md).

#include <Eigen/Core>
#include <string>
#include <vector>

#include "fuzz_util.h"
#include "viewline/io/config.h"

namespace {

using viewline::fuzz::rejectOk;
using viewline::io::ConfigNode;

void walk(const ConfigNode& node, int depth) {
  if (depth > 8 || !node.yaml().IsMap()) return;
  std::vector<std::string> keys;
  for (auto it = node.yaml().begin(); it != node.yaml().end(); ++it)
    if (it->first.IsScalar()) keys.push_back(it->first.Scalar());
  for (const std::string& k : keys) {
    rejectOk([&] { node.get<bool>(k); });
    rejectOk([&] { node.get<int>(k); });
    rejectOk([&] { node.get<unsigned>(k); });
    rejectOk([&] { node.get<long long>(k); });
    rejectOk([&] { node.get<std::uint64_t>(k); });
    rejectOk([&] { node.get<double>(k); });
    rejectOk([&] { node.get<std::string>(k); });
    rejectOk([&] { node.get<std::vector<double>>(k); });
    rejectOk([&] { node.get<std::vector<int>>(k); });
    rejectOk([&] { node.get<std::vector<std::string>>(k); });
    rejectOk([&] { node.get<Eigen::Vector2d>(k); });
    rejectOk([&] { node.get<Eigen::Vector3d>(k); });
    rejectOk([&] { node.get<Eigen::VectorXd>(k); });
    rejectOk([&] { node.get<Eigen::Matrix3d>(k); });
    rejectOk([&] { node.getOrAuto<double>(k, 1.0, "a number"); });
    rejectOk([&] { node.getChoice(k, {"ct", "cv", "auto"}); });
    rejectOk([&] { node.getPath(k); });
    rejectOk([&] { node.location(k); });
    if (k.size() >= 4 && k.compare(k.size() - 4, 4, "_deg") == 0) rejectOk([&] { node.getAngle(k); });
    rejectOk([&] { walk(node.child(k), depth + 1); });
    rejectOk([&] {
      for (const ConfigNode& c : node.childList(k)) walk(c, depth + 1);
    });
  }
  rejectOk([&] { node.fail("", "anything"); });
}

void exercise(const ConfigNode& root) {
  // First a strict pass that reads nothing (every key unknown), then the full walk.
  rejectOk([&] { root.finish(); });
  walk(root, 0);
  rejectOk([&] { root.finish(); });
}

}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  const std::string text = viewline::fuzz::asText(data, size);
  rejectOk([&] { exercise(ConfigNode::fromString(text, "fuzz.yaml", "/base")); });
  const std::string path = viewline::fuzz::scratchFile("scenario.yaml", text);
  rejectOk([&] { ConfigNode::loadFile(path).finish(); });
  return 0;
}
