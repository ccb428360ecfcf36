#include <gtest/gtest.h>

#include <filesystem>

#include "temp_dir.h"
#include "viewline/core/error.h"
#include "viewline/io/config_edit.h"

using namespace viewline;
using namespace viewline::io;

TEST(ConfigEdit, DottedKeysReachMapsAndListItems) {
  const YAML::Node tree = YAML::Load("cams:\n  - {f: 1}\n  - {f: 2}\nfilter: {q: 0.5}\n");
  const YAML::Node n = withValue(tree, "cams[1].f", YAML::Node("7"));
  EXPECT_EQ(n["cams"][1]["f"].as<int>(), 7);
  EXPECT_EQ(n["cams"][0]["f"].as<int>(), 1);
  EXPECT_EQ(tree["cams"][1]["f"].as<int>(), 2);  // a copy: the input is unchanged
  EXPECT_EQ(withValue(tree, "filter.model.name", YAML::Node("ct"))["filter"]["model"]["name"].as<std::string>(), "ct");
  ASSERT_TRUE(findKey(tree, "filter.q").has_value());
  EXPECT_DOUBLE_EQ(findKey(tree, "filter.q")->as<double>(), 0.5);
  EXPECT_FALSE(findKey(tree, "filter.r").has_value());
  EXPECT_FALSE(findKey(tree, "cams[2].f").has_value());
  EXPECT_THROW(withValue(tree, "cams[5].f", YAML::Node("1")), core::InvalidInput);
  EXPECT_THROW(withValue(tree, "filter.q.x", YAML::Node("1")), core::InvalidInput);  // q is not a map
  EXPECT_THROW(parseDottedKey("a..b"), core::InvalidInput);
  EXPECT_THROW(parseDottedKey("a[x]"), core::InvalidInput);
  EXPECT_THROW(parseDottedKey("a."), core::InvalidInput);
  const auto segs = parseDottedKey("a.b[3].c");
  ASSERT_EQ(segs.size(), 3u);
  EXPECT_EQ(segs[1].key, "b");
  EXPECT_EQ(segs[1].index, 3);
}

TEST(ConfigEdit, RewriteKeepsCommentsAndReplacesInPlace) {
  const std::string text = "# top\nq_true: 0.01   # truth\nfilter:\n  q: 0.5       # filter q\n  r: 2\n";
  const std::string out = rewriteYamlText(text, {{"filter.q", YAML::Node("0.25")}}, "tuned");
  EXPECT_NE(out.find("# tuned\n# top\n"), std::string::npos) << out;
  EXPECT_NE(out.find("  q: 0.25       # filter q\n"), std::string::npos) << out;
  EXPECT_EQ(YAML::Load(out)["filter"]["q"].as<double>(), 0.25);
  // A key absent from the file: re-emitted with the value.
  const std::string out2 = rewriteYamlText(text, {{"steps", YAML::Node("50")}}, "x");
  EXPECT_EQ(YAML::Load(out2)["steps"].as<int>(), 50);
  EXPECT_EQ(YAML::Load(out2)["filter"]["r"].as<int>(), 2);
}

TEST(ConfigEdit, SetValuesOnAFileKeepItsFolderAndRejectBadText) {
  namespace fs = std::filesystem;
  const test::TempDir dir;
  fs::create_directories(dir.path / "config");
  fs::create_directories(dir.path / "rigs/r");
  const std::string file = dir.write("config/s.yaml",
                                     "rig: ../rigs/r   # relative to this file\ncamera:\n  fps: 30\n  size: [640, 480]\nname: a\n");
  const ConfigNode c = loadConfigWithValues(file, {"camera.fps=60", "camera.size=[320, 240]", "noise=0.05"});
  EXPECT_EQ(c.child("camera").get<int>("fps"), 60);
  EXPECT_EQ(c.child("camera").get<std::vector<int>>("size"), (std::vector<int>{320, 240}));
  EXPECT_DOUBLE_EQ(c.get<double>("noise"), 0.05);  // a key the file lacks is added
  EXPECT_EQ(c.get<std::string>("name"), "a");      // the others as in the file
  EXPECT_EQ(fs::weakly_canonical(c.getPath("rig")), fs::weakly_canonical(dir.path / "rigs/r"));
  EXPECT_NE(c.fileName().find("with --set"), std::string::npos);
  // Nothing set: the file itself.
  EXPECT_EQ(loadConfigWithValues(file, {}).child("camera").get<int>("fps"), 30);
  for (const std::string bad : {"camera.fps", "=3", "camera.fps=", "camera..fps=3", "camera.fps=[1,"})
    EXPECT_THROW(loadConfigWithValues(file, {bad}), core::InvalidInput) << bad;
  EXPECT_THROW(loadConfigWithValues(file, {"camera.fps.x=1"}), core::InvalidInput);  // fps is not a map
  // A file that cannot be read is named.
  try {
    loadConfigWithValues(dir.file("config/absent.yaml"), {"camera.fps=60"});
    ADD_FAILURE() << "no error for a missing file";
  } catch (const core::InvalidInput& e) {
    EXPECT_NE(std::string(e.what()).find("absent.yaml"), std::string::npos) << e.what();
  }
}

TEST(ConfigEdit, AnUnknownKeySetFromTheCommandLineIsStillRefusedByTheStrictLoader) {
  const test::TempDir dir;
  const std::string file = dir.write("s.yaml", "camera:\n  fps: 30\n");
  const ConfigNode c = loadConfigWithValues(file, {"camera.fsp=60"});
  EXPECT_EQ(c.child("camera").get<int>("fps"), 30);
  try {
    c.finish();
    ADD_FAILURE() << "the mistyped key was accepted";
  } catch (const core::InvalidInput& e) {
    EXPECT_NE(std::string(e.what()).find("camera.fsp"), std::string::npos) << e.what();
  }
}
