#include <gtest/gtest.h>

#include <algorithm>
#include <string>

#include "viewline/io/config_reference.h"
#include "viewline/scenarios/config_keys.h"

using namespace viewline;

namespace {

std::string joined(const std::vector<std::string>& lines) {
  std::string all;
  for (const auto& l : lines) all += l + "\n";
  return all;
}

}  // namespace

// Tests run in the source folder: the shipped configs are config/*.yaml.
TEST(ScenarioConfigKeys, EveryKeyReadHasAnEntryAndEveryEntryIsRead) {
  for (const auto& section : scenarios::scenarioConfigReferences()) {
    const io::ConfigRecorder keys = io::recordConfigKeys(section, "config");
    EXPECT_GE(keys.keys().size(), 10u) << section.name;
    const auto problems = io::checkConfigKeys(section, keys);
    EXPECT_TRUE(problems.empty()) << joined(problems);
  }
}

TEST(ScenarioConfigKeys, CheckNamesAKeyWithoutEntryAndAnEntryNeverRead) {
  io::ConfigReferenceSection dart = scenarios::dartConfigReference();
  const io::ConfigRecorder keys = io::recordConfigKeys(dart, "config");
  auto it = std::find_if(dart.keys.begin(), dart.keys.end(), [](const io::ConfigKeyDoc& d) { return d.key == "outlier_rate"; });
  ASSERT_NE(it, dart.keys.end());
  dart.keys.erase(it);
  dart.keys.push_back({"tracker.sigma_px", "px", "a key no reader reads"});
  const std::string problems = joined(io::checkConfigKeys(dart, keys));
  EXPECT_NE(problems.find("key 'outlier_rate' (number) is read but has no entry"), std::string::npos) << problems;
  EXPECT_NE(problems.find("key 'tracker.sigma_px' has an entry but the reader never reads it"), std::string::npos)
      << problems;
}

TEST(ScenarioConfigKeys, ReferenceHasOneRowPerKeyWithItsDefault) {
  const io::ConfigReferenceSection dart = scenarios::dartConfigReference();
  const io::ConfigRecorder keys = io::recordConfigKeys(dart, "config");
  const std::string md = io::configReferenceMarkdown({dart}, {keys}, "viewline_config_reference");
  EXPECT_NE(md.find("    viewline_config_reference\n"), std::string::npos);
  // A default read from the code (DartScenarioConfig: 5 % gross outliers) and a required key.
  EXPECT_NE(md.find("| `outlier_rate` | number |  | `0.05` |"), std::string::npos) << md;
  EXPECT_NE(md.find("| `cameras[].eye` | [x, y, z] | m | required |"), std::string::npos) << md;
  std::size_t rows = 0;
  for (std::size_t p = md.find("\n| `"); p != std::string::npos; p = md.find("\n| `", p + 1)) ++rows;
  EXPECT_EQ(rows, keys.keys().size());
}
