#include <gtest/gtest.h>

#include <memory>

#include "viewline/core/error.h"
#include "viewline/core/frames.h"
#include "viewline/io/config.h"

using viewline::io::ConfigNode;
using viewline::io::ConfigRecorder;
using Presence = ConfigRecorder::Presence;

namespace {

// A reader like the scenario readers: defaults, required keys, a key read only when present,
// angles, choices, a section and a list of sections.
void readExample(const ConfigNode& root) {
  root.getOr<double>("rate_hz", 50.0);
  root.get<std::string>("name");
  root.getAngleOr("pan_limit_deg", viewline::core::deg2rad(62.0));
  root.getAngleOr("margin_deg", 0.02);
  root.getChoiceOr("gate", {"none", "mahalanobis"}, "mahalanobis");
  if (root.has("seed")) root.get<unsigned>("seed");
  root.getOr<Eigen::Vector3d>("p0", Eigen::Vector3d(0.0, 0.5, -1.25));
  root.getOr<double>("max_coast_s", std::numeric_limits<double>::infinity());
  root.getOr<std::string>("label", "");
  if (root.has("tracker")) root.child("tracker").getOr<int>("history", 64);
  if (root.has("cameras"))
    for (const ConfigNode& c : root.childList("cameras")) c.getOr<bool>("enabled", true);
}

const ConfigRecorder::Key& keyOf(const ConfigRecorder& r, const std::string& path) {
  const ConfigRecorder::Key* k = r.find(path);
  if (!k) throw std::runtime_error("not recorded: " + path);
  return *k;
}

}  // namespace

TEST(ConfigRecorder, RecordsTypeDefaultAndPresenceOfEveryKeyRead) {
  auto rec = std::make_shared<ConfigRecorder>();
  const ConfigNode cfg = ConfigNode::fromString("name: a\n");
  cfg.recordTo(rec);
  readExample(cfg);
  const auto& rate = keyOf(*rec, "rate_hz");
  EXPECT_EQ(rate.type, "number");
  EXPECT_EQ(rate.presence, Presence::Default);
  ASSERT_EQ(rate.defaults.size(), 1u);
  EXPECT_EQ(rate.defaults[0], "50");
  EXPECT_EQ(keyOf(*rec, "name").presence, Presence::Required);
  EXPECT_EQ(keyOf(*rec, "name").type, "string");
  // Degrees in the file, radians in the code: the default is shown in degrees, without the
  // round-off of the conversion.
  EXPECT_EQ(keyOf(*rec, "pan_limit_deg").type, "angle, degrees");
  EXPECT_EQ(keyOf(*rec, "pan_limit_deg").defaults.at(0), "62");
  EXPECT_EQ(keyOf(*rec, "margin_deg").defaults.at(0), "1.14592");  // 0.02 rad, to 6 digits
  EXPECT_EQ(keyOf(*rec, "gate").type, "one of: none, mahalanobis");
  EXPECT_EQ(keyOf(*rec, "gate").defaults.at(0), "mahalanobis");
  EXPECT_EQ(keyOf(*rec, "p0").type, "[x, y, z]");
  EXPECT_EQ(keyOf(*rec, "p0").defaults.at(0), "[0, 0.5, -1.25]");
  EXPECT_EQ(keyOf(*rec, "max_coast_s").defaults.at(0), ".inf");
  EXPECT_EQ(keyOf(*rec, "label").defaults.at(0), "\"\"");
  // Absent and guarded by has(): never read, so not recorded from this file.
  EXPECT_EQ(rec->find("seed"), nullptr);
  EXPECT_EQ(rec->find("tracker"), nullptr);
  // A getOr reads the key through get<T>: one record, not two.
  EXPECT_EQ(rec->keys().size(), 8u);
}

TEST(ConfigRecorder, UnitesReadsInReadingOrderWithListItemsOnce) {
  auto rec = std::make_shared<ConfigRecorder>();
  const ConfigNode empty = ConfigNode::fromString("name: a\n");
  empty.recordTo(rec);
  readExample(empty);
  const ConfigNode full = ConfigNode::fromString(
      "name: b\nseed: 3\ntracker:\n  history: 8\ncameras:\n  - enabled: false\n  - {}\n");
  full.recordTo(rec);
  readExample(full);
  full.finish();
  // A key present only in the second file: optional (has() asked first), placed where it is read.
  const auto& seed = keyOf(*rec, "seed");
  EXPECT_EQ(seed.presence, Presence::Optional);
  EXPECT_EQ(seed.type, "integer >= 0");
  EXPECT_EQ(keyOf(*rec, "tracker").type, "section");
  EXPECT_EQ(keyOf(*rec, "tracker").presence, Presence::Optional);
  EXPECT_EQ(keyOf(*rec, "tracker.history").defaults.at(0), "64");
  EXPECT_EQ(keyOf(*rec, "cameras").type, "list of sections");
  EXPECT_EQ(keyOf(*rec, "cameras[].enabled").defaults.at(0), "true");
  std::vector<std::string> order;
  for (const auto& k : rec->keys()) order.push_back(k.path);
  const std::vector<std::string> expected = {"rate_hz", "name", "pan_limit_deg", "margin_deg", "gate", "seed", "p0", "max_coast_s",
                                             "label", "tracker", "tracker.history", "cameras", "cameras[].enabled"};
  EXPECT_EQ(order, expected);
}

TEST(ConfigRecorder, ReadingWithoutARecorderRecordsNothingAndBehavesTheSame) {
  const char* text = "name: a\nrate_hz: 20\npan_limit_deg: 10\n";
  const ConfigNode plain = ConfigNode::fromString(text);
  auto rec = std::make_shared<ConfigRecorder>();
  const ConfigNode recorded = ConfigNode::fromString(text);
  recorded.recordTo(rec);
  EXPECT_EQ(plain.getOr<double>("rate_hz", 1.0), recorded.getOr<double>("rate_hz", 1.0));
  EXPECT_EQ(plain.getAngle("pan_limit_deg"), recorded.getAngle("pan_limit_deg"));
  EXPECT_THROW(recorded.get<double>("name"), viewline::core::InvalidInput);
  // The failed read is still recorded (with the type the code asked for) and ends its note: the
  // next read is recorded too.
  EXPECT_EQ(keyOf(*rec, "name").type, "number");
  recorded.getOr<int>("count", 3);
  EXPECT_EQ(keyOf(*rec, "count").defaults.at(0), "3");
}

TEST(ConfigRecorder, DefaultsAreYamlThatReadsBackAsTheDefault) {
  EXPECT_EQ(ConfigNode::configValueText(0.1), "0.1");
  EXPECT_EQ(ConfigNode::configValueText(1e-9), "1e-09");
  EXPECT_EQ(ConfigNode::configValueText(-std::numeric_limits<double>::infinity()), "-.inf");
  EXPECT_EQ(ConfigNode::configValueText(-0.0), "0");
  EXPECT_EQ(ConfigNode::configValueText(std::string("true")), "\"true\"");
  EXPECT_EQ(ConfigNode::configValueText(std::string("known_radius")), "known_radius");
  EXPECT_EQ(ConfigNode::configValueText(std::vector<int>{0, 0, 4}), "[0, 0, 4]");
  EXPECT_EQ(ConfigNode::configValueText(Eigen::Matrix3d(Eigen::Matrix3d::Identity())),
            "[[1, 0, 0], [0, 1, 0], [0, 0, 1]]");
  // Each default parses back (as YAML) to the value it came from.
  const double values[] = {0.1, 1.0 / 3.0, 2.5e-7, 1234567.0, -0.0001};
  for (const double v : values) {
    const ConfigNode n = ConfigNode::fromString("x: " + ConfigNode::configValueText(v));
    EXPECT_EQ(n.get<double>("x"), v);
  }
  EXPECT_EQ(ConfigRecorder::normalisePath("cameras[12].rig[0].name"), "cameras[].rig[].name");
}
