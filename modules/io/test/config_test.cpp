#include <gtest/gtest.h>

#include <filesystem>

#include "temp_dir.h"
#include "viewline/core/error.h"
#include "viewline/io/config.h"

using viewline::core::InvalidInput;
using viewline::io::ConfigNode;
using viewline::io::test::TempDir;

namespace {
// Runs f, expects InvalidInput, returns its message.
template <class F>
std::string errorOf(F&& f) {
  try {
    f();
  } catch (const InvalidInput& e) {
    return e.what();
  }
  ADD_FAILURE() << "no InvalidInput thrown";
  return {};
}

const char* kScenario =
    "rate_hz: 50\n"                    // line 1
    "name: catching\n"                 // line 2
    "seed: 42\n"                       // line 3
    "pan_limit_deg: 90\n"              // line 4
    "p0: [0, 0, 3]\n"                  // line 5
    "tracker:\n"                       // line 6
    "  sigma_px: 0.5\n"                // line 7
    "  gate: mahalanobis\n"            // line 8
    "cameras:\n"                       // line 9
    "  - name: left\n"                 // line 10
    "    fps: 50\n"                    // line 11
    "  - name: right\n"                // line 12
    "    fps: 40\n";                   // line 13
}  // namespace

TEST(Config, ReadsTypedValuesAndFinishesWhenAllUsed) {
  TempDir dir;
  const auto path = dir.write("s.yaml", kScenario);
  const auto cfg = ConfigNode::loadFile(path);
  EXPECT_DOUBLE_EQ(cfg.get<double>("rate_hz"), 50.0);
  EXPECT_EQ(cfg.get<int>("rate_hz"), 50);
  EXPECT_EQ(cfg.get<std::string>("name"), "catching");
  EXPECT_EQ(cfg.get<std::uint64_t>("seed"), 42u);
  EXPECT_NEAR(cfg.getAngle("pan_limit_deg"), 3.14159265358979 / 2, 1e-12);
  EXPECT_EQ(cfg.get<Eigen::Vector3d>("p0"), Eigen::Vector3d(0, 0, 3));
  EXPECT_EQ(cfg.getOr<double>("absent", 7.5), 7.5);
  const auto tracker = cfg.child("tracker");
  EXPECT_EQ(tracker.path(), "tracker");
  EXPECT_DOUBLE_EQ(tracker.get<double>("sigma_px"), 0.5);
  EXPECT_EQ(tracker.getChoice("gate", {"norm", "mahalanobis"}), "mahalanobis");
  const auto cams = cfg.childList("cameras");
  ASSERT_EQ(cams.size(), 2u);
  EXPECT_EQ(cams[1].get<std::string>("name"), "right");
  EXPECT_EQ(cams[0].get<unsigned>("fps"), 50u);
  EXPECT_EQ(cams[0].get<std::string>("name"), "left");
  cams[1].ignore("fps");
  EXPECT_NO_THROW(cfg.finish());
}

TEST(Config, UnknownKeyNamesFileLineAndKeyPath) {
  TempDir dir;
  const auto path = dir.write("s.yaml", kScenario);
  const auto cfg = ConfigNode::loadFile(path);
  cfg.get<double>("rate_hz");
  cfg.get<std::string>("name");
  cfg.get<int>("seed");
  cfg.getAngle("pan_limit_deg");
  cfg.get<Eigen::Vector3d>("p0");
  cfg.child("tracker").get<double>("sigma_px");  // "gate" never read
  for (const auto& c : cfg.childList("cameras")) c.get<std::string>("name");  // "fps" never read
  const std::string msg = errorOf([&] { cfg.finish(); });
  EXPECT_NE(msg.find(path + ":8:3: unknown key 'tracker.gate'"), std::string::npos) << msg;
  EXPECT_NE(msg.find(path + ":11:5: unknown key 'cameras[0].fps'"), std::string::npos) << msg;
  EXPECT_NE(msg.find(path + ":13:5: unknown key 'cameras[1].fps'"), std::string::npos) << msg;
  EXPECT_NE(msg.find("keys used here: sigma_px"), std::string::npos) << msg;
}

TEST(Config, UnreadTopLevelSectionIsUnknown) {
  const auto cfg = ConfigNode::fromString("a: 1\nrate_hx: 3\n", "typo.yaml");
  cfg.get<int>("a");
  const std::string msg = errorOf([&] { cfg.finish(); });
  EXPECT_NE(msg.find("typo.yaml:2:1: unknown key 'rate_hx'"), std::string::npos) << msg;
}

TEST(Config, WrongTypeNamesFileLineKeyAndExpectation) {
  const auto cfg = ConfigNode::fromString("a: 1\ntracker:\n  sigma_px: abc\n  n: 2.5\n  v: [1, x, 3]\n  u: -3\n",
                                          "bad.yaml");
  const auto t = cfg.child("tracker");
  std::string msg = errorOf([&] { t.get<double>("sigma_px"); });
  EXPECT_NE(msg.find("bad.yaml:3:3: key 'tracker.sigma_px': expected a finite number, got 'abc'"),
            std::string::npos)
      << msg;
  msg = errorOf([&] { t.get<int>("n"); });
  EXPECT_NE(msg.find("bad.yaml:4:3: key 'tracker.n': expected an integer"), std::string::npos) << msg;
  msg = errorOf([&] { t.get<std::vector<double>>("v"); });
  EXPECT_NE(msg.find("bad.yaml:5:10: key 'tracker.v[1]': expected a finite number, got 'x'"), std::string::npos)
      << msg;
  msg = errorOf([&] { t.get<unsigned>("u"); });
  EXPECT_NE(msg.find("key 'tracker.u': expected a non-negative integer"), std::string::npos) << msg;
  msg = errorOf([&] { t.get<Eigen::Vector2d>("v"); });
  EXPECT_NE(msg.find("tracker.v"), std::string::npos) << msg;
  msg = errorOf([&] { cfg.child("a"); });
  EXPECT_NE(msg.find("bad.yaml:1:1: key 'a': expected a map of keys, got '1'"), std::string::npos) << msg;
  msg = errorOf([&] { cfg.childList("tracker"); });
  EXPECT_NE(msg.find("key 'tracker': expected a list of maps"), std::string::npos) << msg;
}

TEST(Config, MissingKeyNamesParentLineAndExpectation) {
  const auto cfg = ConfigNode::fromString("a: 1\ntracker:\n  sigma_px: 1\n", "m.yaml");
  const auto t = cfg.child("tracker");
  const std::string msg = errorOf([&] { t.get<double>("gate_p"); });
  EXPECT_NE(msg.find("m.yaml:3:3: missing required key 'tracker.gate_p' in 'tracker' (expected a finite number)"),
            std::string::npos)
      << msg;
  const std::string msg2 = errorOf([&] { cfg.child("robot"); });
  EXPECT_NE(msg2.find("missing required section 'robot' in the top level"), std::string::npos) << msg2;
}

TEST(Config, RejectsNonFiniteDuplicatesSyntaxAndBadChoices) {
  auto cfg = ConfigNode::fromString("x: .nan\ny: .inf\nmode: fast\n", "n.yaml");
  EXPECT_THROW(cfg.get<double>("x"), InvalidInput);
  EXPECT_THROW(cfg.get<double>("y"), InvalidInput);
  const std::string msg = errorOf([&] { cfg.getChoice("mode", {"slow", "exact"}); });
  EXPECT_NE(msg.find("expected one of: slow, exact, got 'fast'"), std::string::npos) << msg;
  const std::string dup = errorOf([] { ConfigNode::fromString("a: 1\nb: 2\na: 3\n", "d.yaml"); });
  EXPECT_NE(dup.find("d.yaml:3:1: duplicate key 'a'"), std::string::npos) << dup;
  const std::string syn = errorOf([] { ConfigNode::fromString("a: [1, 2\nb: 3\n", "syn.yaml"); });
  EXPECT_NE(syn.find("syn.yaml:"), std::string::npos) << syn;
  EXPECT_NE(syn.find("YAML syntax error"), std::string::npos) << syn;
  EXPECT_THROW(ConfigNode::fromString("- 1\n- 2\n", "list.yaml"), InvalidInput);
  EXPECT_THROW(ConfigNode::loadFile("/nonexistent/dir/x.yaml"), InvalidInput);
}

TEST(Config, FailAndPathsResolveAgainstConfigDirectory) {
  TempDir dir;
  const auto path = dir.write("c.yaml", "rate_hz: -5\nrig: rigs/a.yaml\nabs: /etc/x\n");
  const auto cfg = ConfigNode::loadFile(path);
  const double r = cfg.get<double>("rate_hz");
  ASSERT_LT(r, 0.0);
  const std::string msg = errorOf([&] { cfg.fail("rate_hz", "a positive number"); });
  EXPECT_NE(msg.find(path + ":1:1: key 'rate_hz': expected a positive number, got '-5'"), std::string::npos) << msg;
  EXPECT_EQ(cfg.getPath("rig"), (dir.path / "rigs/a.yaml").string());
  EXPECT_EQ(cfg.getPath("abs"), "/etc/x");
  EXPECT_NO_THROW(cfg.finish());
}

TEST(Config, MatrixAndEmptySection) {
  const auto cfg = ConfigNode::fromString("R: [[1,0,0],[0,1,0],[0,0,1]]\nbad: [[1,0],[0,1]]\nempty:\n", "m.yaml");
  EXPECT_TRUE(cfg.get<Eigen::Matrix3d>("R").isIdentity());
  EXPECT_THROW(cfg.get<Eigen::Matrix3d>("bad"), InvalidInput);
  const auto e = cfg.child("empty");
  EXPECT_FALSE(e.has("x"));
  EXPECT_EQ(e.getOr<int>("x", 3), 3);
  EXPECT_NO_THROW(cfg.finish());
}

TEST(Config, AValueOrAuto) {
  const ConfigNode c = ConfigNode::fromString("samples: auto\nsigma: 0.01\nbad: atuo\nquoted: \"auto\"\n", "f.yaml");
  EXPECT_EQ(c.getOrAuto<int>("samples", 4, "an integer"), std::nullopt);
  EXPECT_EQ(c.getOrAuto<double>("sigma", std::nullopt, "a length"), 0.01);
  EXPECT_EQ(c.getOrAuto<int>("absent", 4, "an integer"), 4);
  EXPECT_EQ(c.getOrAuto<int>("quoted", 4, "an integer"), std::nullopt);
  const std::string e = errorOf([&] { c.getOrAuto<int>("bad", 4, "an integer >= 2"); });
  EXPECT_NE(e.find("f.yaml:3:"), std::string::npos) << e;
  EXPECT_NE(e.find("expected an integer >= 2 or auto, got 'atuo'"), std::string::npos) << e;
  c.finish();  // every key was read, "auto" ones included
}

// A tree parsed once and edited in code is read as it is: values from the file keep their lines in
// messages, values set in code name the file alone, paths resolve against the given folder.
TEST(Config, FromTreeKeepsTheFileLines) {
  const YAML::Node parsed = YAML::Load("rate_hz: 50\ntracker:\n  sigma_px: abc\n  gate: 9\nrig: rigs/a\n");
  YAML::Node edited(YAML::NodeType::Map);  // shares the parsed nodes, one value replaced
  for (auto it = parsed.begin(); it != parsed.end(); ++it)
    edited.force_insert(it->first, it->first.Scalar() == "rate_hz" ? YAML::Node("-3") : it->second);
  const ConfigNode cfg = ConfigNode::fromTree(edited, "s.yaml", "/cfg");
  EXPECT_EQ(cfg.fileName(), "s.yaml");
  EXPECT_EQ(cfg.get<int>("rate_hz"), -3);
  EXPECT_EQ(cfg.getPath("rig"), "/cfg/rigs/a");
  const ConfigNode tracker = cfg.child("tracker");
  const std::string bad = errorOf([&] { tracker.get<double>("sigma_px"); });
  EXPECT_EQ(bad.rfind("s.yaml:3:3: key 'tracker.sigma_px'", 0), 0u) << bad;
  const std::string range = errorOf([&] { cfg.fail("rate_hz", "a positive rate"); });
  EXPECT_EQ(range.rfind("s.yaml:1:1: key 'rate_hz'", 0), 0u) << range;  // the key is the file's
  const std::string unknown = errorOf([&] { cfg.finish(); });
  EXPECT_NE(unknown.find("s.yaml:4:3: unknown key 'tracker.gate'"), std::string::npos) << unknown;
  EXPECT_EQ(parsed["rate_hz"].as<int>(), 50);  // the parsed tree is not changed

  // New nodes have no mark: the message names the file without a made-up line.
  YAML::Node built(YAML::NodeType::Map);
  built["n"] = "x";
  const std::string no_line = errorOf([&] { ConfigNode::fromTree(built, "b.yaml").get<int>("n"); });
  EXPECT_EQ(no_line.rfind("b.yaml: key 'n'", 0), 0u) << no_line;
}

TEST(Config, FromTreeRefusesWhatTheParserWould) {
  EXPECT_FALSE(ConfigNode::fromTree(YAML::Node(), "e.yaml").has("a"));  // null: an empty map
  const std::string list = errorOf([] { ConfigNode::fromTree(YAML::Load("[1, 2]"), "l.yaml"); });
  EXPECT_NE(list.find("l.yaml: expected a YAML map"), std::string::npos) << list;
  YAML::Node dup(YAML::NodeType::Map);
  dup.force_insert("a", 1);
  dup.force_insert("a", 2);
  const std::string twice = errorOf([&] { ConfigNode::fromTree(dup, "d.yaml"); });
  EXPECT_NE(twice.find("duplicate key 'a'"), std::string::npos) << twice;
  EXPECT_EQ(twice.rfind("d.yaml", 0), 0u) << twice;
}

TEST(Config, ADirectoryGivenAsTheConfigFileIsNamed) {
  const std::string dir = ::testing::TempDir() + "config_test_a_directory";
  std::filesystem::create_directories(dir);
  try {
    ConfigNode::loadFile(dir);
    ADD_FAILURE() << "a directory was read as a config";
  } catch (const InvalidInput& e) {
    EXPECT_NE(std::string(e.what()).find(dir + ": is a directory"), std::string::npos) << e.what();
  }
  std::filesystem::remove(dir);
}
