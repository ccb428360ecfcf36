// viewline_config_reference: writes the scenario config reference (docs/config_reference.md)
// from the code that reads the configs. Each scenario's reader runs with a key recorder on an
// empty config and on every shipped file; units and meanings come from the key table next to
// each reader (modules/scenarios/<name>/config_keys.cpp). Refuses to write when a table and its
// reader disagree (a key read without an entry, an entry never read).
//
//   viewline_config_reference --config-dir config --output docs/config_reference.md
#include <CLI/CLI.hpp>
#include <cstdio>
#include <iostream>

#include "app_options.h"
#include "viewline/core/version.h"
#include "viewline/io/config_reference.h"
#include "viewline/io/files.h"
#include "viewline/scenarios/config_keys.h"

using namespace viewline;

namespace {
// The command the reference names in its header: run from the repository's top folder.
constexpr const char* kCommand = "viewline_config_reference --config-dir config --output docs/config_reference.md";
}  // namespace

int main(int argc, char** argv) {
  CLI::App cli{"viewline_config_reference: the reference of every scenario config key (type, unit, default, meaning),\n"
               "generated from the code that reads the configs."};
  cli.set_version_flag("--version", std::string("viewline ") + core::kVersion);
  std::string config_dir = "config";
  std::string output = "-";
  cli.add_option("--config-dir", config_dir,
                 "folder of the shipped scenario configs: config/ of the source tree, or share/viewline/config "
                 "of an installation");
  cli.add_option("--output", output, "the Markdown file to write; - for standard output");
  if (const auto code = apps::parseCommandLine(cli, argc, argv)) return *code;
  return apps::runGuarded("viewline_config_reference", [&] {
    const auto sections = scenarios::scenarioConfigReferences();
    std::vector<io::ConfigRecorder> keys;
    std::size_t problems = 0;
    for (const auto& section : sections) {
      keys.push_back(io::recordConfigKeys(section, config_dir));
      for (const auto& p : io::checkConfigKeys(section, keys.back())) {
        std::fprintf(stderr, "viewline_config_reference: %s\n", p.c_str());
        ++problems;
      }
    }
    if (problems > 0) {
      std::fprintf(stderr, "viewline_config_reference: %zu disagreements between the key tables and the readers: "
                           "nothing written\n", problems);
      return 1;
    }
    const std::string md = io::configReferenceMarkdown(sections, keys, kCommand);
    if (output == "-") {
      std::cout << md;
    } else {
      io::writeTextFileAtomic(output, md);
    }
    return 0;
  });
}
