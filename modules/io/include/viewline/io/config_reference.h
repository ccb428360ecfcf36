#pragma once
// The config reference (docs/config_reference.md), generated from the code that reads the configs
// so that it cannot drift from it.
//
// The reader of a config runs with a ConfigRecorder attached (io/config.h): every key it reads is
// recorded with its type, whether it is required and the default the code falls back to. Reading
// an empty config, a few probes and every shipped file reaches the keys of every branch; the unit
// and the one-line meaning of each key come from a table kept next to the reader
// (modules/scenarios/<name>/config_keys.cpp). checkConfigKeys() refuses a key that is read but
// has no entry, and an entry that no read reaches.
//
//   const io::ConfigRecorder keys = io::recordConfigKeys(section, "config");
//   for (const auto& problem : io::checkConfigKeys(section, keys)) std::cerr << problem << "\n";
//   std::cout << io::configReferenceMarkdown({section}, {keys}, "viewline_config_reference ...");

#include <functional>
#include <string>
#include <vector>

#include "viewline/io/config.h"

namespace viewline::io {

/// Unit and one-line meaning of one config key, kept next to the code that reads it.
struct ConfigKeyDoc {
  std::string key;      ///< dotted path as recorded: "tracker.gate", a list item's key "cameras[].name"
  std::string unit;     ///< unit of the value in the file ("m", "s", "deg", "px", "Hz", "m/s"); "" when none
  std::string meaning;  ///< one line: what the value does (and what absent means for an optional key)
  /// Shown instead of the recorded default when that default is computed from other keys (the
  /// recorder then sees different defaults in different files), e.g. "home + [-0.1, -0.6, -0.5]".
  std::string default_text = {};
};

/// One config format: the function that reads it, the files that exercise it and its key table.
struct ConfigReferenceSection {
  std::string name;                     ///< short name and anchor ("dart")
  std::string title;                    ///< section heading ("Dart tracking (dart_tracking)")
  std::string summary;                  ///< one paragraph above the table
  std::vector<std::string> shipped;     ///< files under the config folder that use this format
  std::vector<std::string> probes = {}; ///< YAML texts that take branches no shipped file takes
  std::function<void(const ConfigNode&)> read;  ///< the reader (reads, finishes and validates)
  std::vector<ConfigKeyDoc> keys;       ///< unit and meaning of every key the reader reads
};

/// Records the keys `section.read` visits reading an empty config, each probe (both may stop at a
/// missing required key or a validation error: what was read before is kept) and each shipped file
/// under `config_dir` (which must read without error: their errors are thrown).
ConfigRecorder recordConfigKeys(const ConfigReferenceSection& section, const std::string& config_dir);

/// Disagreements between the key table and the recorded reads, one line each: a key read without
/// an entry, an entry no read reaches, a default that differs between files without default_text.
/// Empty when the table and the code agree.
std::vector<std::string> checkConfigKeys(const ConfigReferenceSection& section, const ConfigRecorder& keys);

/// The Markdown reference: a header saying it is generated and by `command`, then one section per
/// config with one table row per key (key, type, unit, default, meaning) in reading order.
/// `keys[i]` are the recorded keys of `sections[i]`.
std::string configReferenceMarkdown(const std::vector<ConfigReferenceSection>& sections,
                                    const std::vector<ConfigRecorder>& keys, const std::string& command);

}  // namespace viewline::io
