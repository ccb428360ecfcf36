#pragma once
// YAML (config/dart_tracking.yaml) <-> DartScenarioConfig, and the summary as JSON.
// Keys are strict (io::ConfigNode): an unknown key is an error naming file:line and key path.

#include <nlohmann/json.hpp>
#include <string>
#include <vector>

#include "viewline/tracking/dart_scenario.h"

namespace viewline::apps {

/// Defaults of tracking::defaultDartScenario() overridden by the file's keys (every key optional).
/// With `key_values` ("key=value", the app's --set) applied to the file first (io::loadConfigWithValues).
tracking::DartScenarioConfig loadDartScenario(const std::string& path, const std::vector<std::string>& key_values = {});
/// Same from YAML text (`name` stands for the file in messages).
tracking::DartScenarioConfig dartScenarioFromString(const std::string& yaml, const std::string& name);

nlohmann::json summaryToJson(const tracking::DartSummary& s, const tracking::DartScenarioConfig& cfg);

}  // namespace viewline::apps
