#include "viewline/io/camera_fields.h"

#include <gtest/gtest.h>

#include <cmath>
#include <string>

#include "viewline/core/error.h"

using namespace viewline;

namespace {
io::ConfigNode parse(const std::string& text) { return io::ConfigNode::fromString(text, "cam.yaml"); }
std::string errorOf(const std::string& text) {
  try {
    io::PinholeFields f;
    io::readPinholeFields(parse(text).child("camera"), f);
  } catch (const core::InvalidInput& e) {
    return e.what();
  }
  return {};
}
}  // namespace

TEST(CameraFields, KeysPresentOverrideTheDefaults) {
  io::PinholeFields f;
  f.width = 656;
  f.height = 480;
  const auto root = parse("camera: {hfov_deg: 60, cx: 320.5, position: [1, 2, 3], look_at: [0, 0, 0]}\n");
  io::readPinholeFields(root.child("camera"), f);
  EXPECT_EQ(f.width, 656u);
  EXPECT_NEAR(f.hfov_rad, std::acos(-1.0) / 3.0, 1e-15);
  ASSERT_TRUE(f.cx);
  EXPECT_DOUBLE_EQ(*f.cx, 320.5);
  EXPECT_FALSE(f.cy);
  EXPECT_EQ(*f.position, Eigen::Vector3d(1, 2, 3));
  EXPECT_NO_THROW(root.finish());
}

TEST(CameraFields, BadValuesAreNamedWithTheirLine) {
  EXPECT_NE(errorOf("camera: {hfov_deg: 190}\n").find("cam.yaml:1"), std::string::npos);
  EXPECT_NE(errorOf("camera: {hfov_deg: 190}\n").find("camera.hfov_deg"), std::string::npos);
  EXPECT_NE(errorOf("camera: {width: 8}\n").find("16x16"), std::string::npos);
  EXPECT_NE(errorOf("camera: {kud: 3}\n").find("[-1, 1]"), std::string::npos);
  EXPECT_NE(errorOf("camera: {position: [0, 0, 1]}\n").find("look_at"), std::string::npos);
  EXPECT_NE(errorOf("camera: {position: [0, 0, 1], look_at: [0, 0, 1]}\n").find("other than"), std::string::npos);
  EXPECT_NE(errorOf("camera: {width: wide}\n"), "");
}

TEST(CameraFields, GeometryIsRefusedWhenARigSetsTheCamera) {
  const auto root = parse("camera:\n  rate_hz: 30\n  hfov_deg: 60\n");
  try {
    io::refuseGeometryWithRig(root.child("camera"), "calib/rigs/catch");
    FAIL();
  } catch (const core::InvalidInput& e) {
    const std::string m = e.what();
    EXPECT_NE(m.find("cam.yaml:3"), std::string::npos) << m;
    EXPECT_NE(m.find("camera.hfov_deg"), std::string::npos) << m;
    EXPECT_NE(m.find("calib/rigs/catch"), std::string::npos) << m;
  }
  EXPECT_NO_THROW(io::refuseGeometryWithRig(parse("camera: {rate_hz: 30}\n").child("camera"), "r"));
}
