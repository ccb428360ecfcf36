#include <gtest/gtest.h>

#include <filesystem>
#include <fstream>
#include <sstream>

#include "toy_scenario.h"
#include "viewline/core/error.h"
#include "viewline/tuning/session.h"
#include "viewline/tuning/sweep_spec.h"
#include "viewline/tuning/yaml_edit.h"

using namespace viewline;
using namespace viewline::tuning;

namespace {

std::string errorOf(const std::string& yaml) {
  try {
    sweepSpecFromString(yaml, "s.yaml", toy::registry());
  } catch (const core::InvalidInput& e) {
    return e.what();
  }
  return "";
}

}  // namespace

TEST(SweepSpec, GridFromValuesAndRanges) {
  const SweepSpec s = sweepSpecFromString(
      "scenario: toy\nseeds: 2\nparameters:\n  - key: filter.q\n    range: [0.001, 0.1]\n    count: 3\n    scale: log\n"
      "  - key: steps\n    values: [100, 200]\n",
      "s.yaml", toy::registry());
  ASSERT_EQ(s.parameters.size(), 2u);
  EXPECT_EQ(s.metric, "rmse");
  ASSERT_EQ(s.parameters[0].values.size(), 3u);
  EXPECT_NEAR(s.parameters[0].values[1].as<double>(), 0.01, 1e-9);
  const auto settings = generateSettings(s);
  ASSERT_EQ(settings.size(), 6u);
  EXPECT_EQ(settingLabel(s, settings[1]), "filter.q=0.001, steps=200");
  EXPECT_EQ(settingLabel(s, settings[5]), "filter.q=0.1, steps=200");
}

TEST(SweepSpec, RandomModeIsSeeded) {
  const std::string y =
      "scenario: toy\nmode: random\nsamples: 5\nsample_seed: 3\nparameters:\n  - key: filter.r\n    range: [0.1, 10]\n"
      "    scale: log\n";
  const auto a = generateSettings(sweepSpecFromString(y, "s.yaml", toy::registry()));
  const auto b = generateSettings(sweepSpecFromString(y, "s.yaml", toy::registry()));
  ASSERT_EQ(a.size(), 5u);
  for (std::size_t i = 0; i < a.size(); ++i) {
    EXPECT_EQ(a[i].numeric[0], b[i].numeric[0]);
    EXPECT_GE(a[i].numeric[0], 0.1);
    EXPECT_LE(a[i].numeric[0], 10.0);
  }
}

TEST(SweepSpec, ErrorsNameLineAndKey) {
  // Unknown key in the sweep file.
  EXPECT_NE(errorOf("scenario: toy\nparameters:\n  - key: filter.q\n    values: [1]\n    scal: log\n")
                .find("s.yaml:5:5: unknown key 'parameters[0].scal'"),
            std::string::npos)
      << errorOf("scenario: toy\nparameters:\n  - key: filter.q\n    values: [1]\n    scal: log\n");
  // Empty range.
  const std::string empty = errorOf("scenario: toy\nparameters:\n  - key: filter.q\n    range: [1, 0.5]\n    count: 3\n");
  EXPECT_NE(empty.find("s.yaml:4:"), std::string::npos) << empty;
  EXPECT_NE(empty.find("parameters[0].range"), std::string::npos) << empty;
  EXPECT_NE(empty.find("empty range"), std::string::npos) << empty;
  const std::string empty_list = errorOf("scenario: toy\nparameters:\n  - key: filter.q\n    values: []\n");
  EXPECT_NE(empty_list.find("parameters[0].values"), std::string::npos) << empty_list;
  // Wrong type.
  const std::string type = errorOf("scenario: toy\nparameters:\n  - key: filter.q\n    range: [a, b]\n    count: 2\n");
  EXPECT_NE(type.find("s.yaml:4:"), std::string::npos) << type;
  EXPECT_NE(type.find("parameters[0].range"), std::string::npos) << type;
  const std::string seeds = errorOf("scenario: toy\nseeds: many\nparameters:\n  - key: filter.q\n    values: [1]\n");
  EXPECT_NE(seeds.find("s.yaml:2:"), std::string::npos) << seeds;
  // Unknown metric and scenario.
  EXPECT_NE(errorOf("scenario: toy\nmetric: speed\nparameters:\n  - key: filter.q\n    values: [1]\n").find("s.yaml:2:"),
            std::string::npos);
  EXPECT_NE(errorOf("scenario: nope\nparameters:\n  - key: filter.q\n    values: [1]\n").find("s.yaml:1:"),
            std::string::npos);
  // Duplicate parameter.
  EXPECT_NE(errorOf("scenario: toy\nparameters:\n  - key: filter.q\n    values: [1]\n  - key: filter.q\n    values: [2]\n")
                .find("listed twice"),
            std::string::npos);
}

TEST(SweepSpec, SizesNoSessionCouldRunAreRefusedBeforeAnythingIsGenerated) {
  // A huge count or sample number used to be generated in full (memory and time without bound).
  const std::string count = errorOf("scenario: toy\nparameters:\n  - key: filter.q\n    range: [1, 2]\n    count: 1000000000\n");
  EXPECT_NE(count.find("parameters[0].count"), std::string::npos) << count;
  const std::string samples =
      errorOf("scenario: toy\nmode: random\nsamples: 2000000000\nparameters:\n  - key: filter.q\n    range: [1, 2]\n");
  EXPECT_NE(samples.find("s.yaml:3:"), std::string::npos) << samples;
  // Two parameters of 1001 and 1000 points: just over 10^6 settings.
  const std::string product = errorOf(
      "scenario: toy\nparameters:\n  - key: filter.q\n    range: [1, 2]\n    count: 1001\n"
      "  - key: filter.r\n    range: [1, 2]\n    count: 1000\n");
  EXPECT_NE(product.find("at most 1000000 settings"), std::string::npos) << product;
}

TEST(YamlEdit, RelativePathsAreRelocatedForACopyWrittenElsewhere) {
  namespace fs = std::filesystem;
  const fs::path root = fs::temp_directory_path() / "viewline_relocated_paths_test";
  fs::remove_all(root);
  fs::create_directories(root / "config");
  fs::create_directories(root / "calib/rigs/r");
  fs::create_directories(root / "out/session");
  const YAML::Node tree = YAML::Load(
      "rig: ../calib/rigs/r\nname: pan.tilt\nmode: stage\nlist: [../calib, absent/dir]\nabs: /tmp\n");
  const auto moved = relocatedPaths(tree, (root / "config").string(), (root / "out/session").string());
  ASSERT_EQ(moved.size(), 2u);  // 'rig' and 'list[0]'; plain words, missing and absolute paths stay
  EXPECT_EQ(moved[0].first, "rig");
  EXPECT_EQ(moved[0].second.as<std::string>(), "../../calib/rigs/r");
  EXPECT_EQ(moved[1].first, "list[0]");
  EXPECT_EQ(moved[1].second.as<std::string>(), "../../calib");
  // Written into the same folder as the config: nothing to change.
  EXPECT_TRUE(relocatedPaths(tree, (root / "config").string(), (root / "config").string()).empty());
  fs::remove_all(root);
}

TEST(YamlEdit, SetValuesReachTheRunsTheSummaryAndTheBestConfig) {
  // --set on a sweep session: the edited config is what every setting runs, what the summary lists
  // (config_set) and what best_config.yaml keeps, with the file's comments.
  namespace fs = std::filesystem;
  const fs::path root = fs::temp_directory_path() / "viewline_session_set_test";
  fs::remove_all(root);
  fs::create_directories(root);
  std::ofstream(root / "toy.yaml") << "steps: 400   # samples\nfilter:\n  q: 0.01\n  r: 1.0\n";
  std::ofstream(root / "sweep.yaml") << "scenario: toy\nconfig: toy.yaml\nseeds: 1\nparameters:\n"
                                        "  - key: filter.q\n    values: [0.001, 0.1]\n";
  SessionOptions o;
  o.out_dir = (root / "out").string();
  o.workers = 1;
  o.quiet = true;
  o.set = {"steps=60", "filter.r=2.5"};
  const nlohmann::json j = runSweepSession(toy::registry(), (root / "sweep.yaml").string(), o);
  EXPECT_EQ(j.at("config_set"), nlohmann::json({"steps=60", "filter.r=2.5"}));
  std::ostringstream best;
  best << std::ifstream(root / "out" / "best_config.yaml").rdbuf();
  const YAML::Node b = YAML::Load(best.str());
  EXPECT_EQ(b["steps"].as<int>(), 60);
  EXPECT_DOUBLE_EQ(b["filter"]["r"].as<double>(), 2.5);
  EXPECT_NE(best.str().find("# samples"), std::string::npos) << best.str();  // edited in place
  // A mistyped key is refused by the scenario's strict loader, before any run.
  o.set = {"filter.rr=2"};
  o.out_dir = (root / "bad").string();
  try {
    runSweepSession(toy::registry(), (root / "sweep.yaml").string(), o);
    ADD_FAILURE() << "filter.rr accepted";
  } catch (const core::InvalidInput& e) {
    EXPECT_NE(std::string(e.what()).find("filter.rr"), std::string::npos) << e.what();
  }
  fs::remove_all(root);
}

// A setting's tree is read as it is (no text round trip): a value the scenario refuses is named in
// the file, and keys the setting did not touch keep their lines; the parsed tree is not changed.
TEST(SweepSpec, EditedTreeKeepsTheFileLines) {
  const YAML::Node file = YAML::Load("steps: 400\nfilter:\n  q: 0.01\n  r: 1.0\n  rr: 2\n");
  const YAML::Node edited = editedTree(file, {{"filter.q", YAML::Node("-1")}, {"extra.k", YAML::Node("3")}});
  EXPECT_EQ(edited["filter"]["q"].as<std::string>(), "-1");
  EXPECT_EQ(edited["extra"]["k"].as<int>(), 3);
  EXPECT_EQ(edited["filter"]["r"].Mark().line, 3);  // the file's node, shared
  EXPECT_EQ(file["filter"]["q"].as<std::string>(), "0.01");
  EXPECT_FALSE(file["extra"].IsDefined());
  std::string error;
  try {
    toy::registry().get("toy").load(editedTree(file, {{"filter.q", YAML::Node("0.5")}}), "toy.yaml", {});
  } catch (const core::InvalidInput& e) {
    error = e.what();
  }
  EXPECT_NE(error.find("toy.yaml:5:3: unknown key 'filter.rr'"), std::string::npos) << error;
  try {
    toy::registry().get("toy").load(editedTree(YAML::Load("steps: 4\n"), {{"filter.q", YAML::Node("-1")}}), "toy.yaml",
                                    {});
    error.clear();
  } catch (const core::InvalidInput& e) {
    error = e.what();
  }
  EXPECT_EQ(error.rfind("toy.yaml: key 'filter.q': expected a positive number", 0), 0u) << error;  // no made-up line
  EXPECT_THROW(editedTree(file, {{"steps.x", YAML::Node("1")}}), core::InvalidInput);  // under a scalar
  EXPECT_THROW(editedTree(file, {{"filter[2]", YAML::Node("1")}}), core::InvalidInput);  // not a list
}
