#include <gtest/gtest.h>

#include "temp_dir.h"
#include "viewline/core/error.h"
#include "viewline/core/frames.h"
#include "viewline/io/rig.h"

using namespace viewline;
using viewline::core::InvalidInput;
using viewline::io::test::TempDir;

namespace {
std::vector<core::Camera> twoCameras() {
  core::Camera a;
  a.name = "left";
  a.intrinsics.initPersProjWithDistortion(600, 602, 320, 240, -0.1, 0.11);
  a.c_M_w = core::lookAt({-0.5, -2, 1}, {0, 0, 1}, {0, 0, 1});
  core::Camera b = a;
  b.name = "right";
  b.intrinsics.initPersProjWithoutDistortion(500, 500, 330, 250);
  b.width = 800;
  b.height = 600;
  b.c_M_w = core::lookAt({0.5, -2, 1.2}, {0, 0, 1}, {0, 0, 1});
  return {a, b};
}
}  // namespace

TEST(Rig, SaveLoadRoundTrip) {
  TempDir dir;
  const auto cams = twoCameras();
  const auto written = io::saveRig(dir.file("rig.yaml"), cams, "test rig");
  EXPECT_EQ(written.size(), 3u);
  EXPECT_EQ(dir.count(), 3u);
  const auto r = io::loadRig(dir.file("rig.yaml"));
  ASSERT_EQ(r.size(), 2u);
  for (std::size_t i = 0; i < 2; ++i) {
    EXPECT_EQ(r[i].name, cams[i].name);
    EXPECT_EQ(r[i].width, cams[i].width);
    EXPECT_EQ(r[i].intrinsics.get_projModel(), cams[i].intrinsics.get_projModel());
    EXPECT_NEAR(r[i].intrinsics.get_px(), cams[i].intrinsics.get_px(), 1e-9);
    EXPECT_NEAR(r[i].intrinsics.get_kdu(), cams[i].intrinsics.get_kdu(), 1e-12);
    EXPECT_TRUE(r[i].c_M_w.matrix().isApprox(cams[i].c_M_w.matrix(), 1e-12));
  }
}

TEST(Rig, HandWrittenRigWithWmcAndThetaU) {
  TempDir dir;
  io::saveVispCameraXml(dir.file("cam.xml"), "cam", twoCameras()[1].intrinsics, std::nullopt, 800, 600);
  dir.write("rig.yaml",
            "cameras:\n"
            "  - name: top\n"
            "    intrinsics: cam.xml\n"
            "    camera_name: cam\n"
            "    projection: without_distortion\n"
            "    w_M_c:\n"
            "      translation: [0, 0, 2]\n"
            "      theta_u_deg: [180, 0, 0]\n");
  const auto r = io::loadRig(dir.file("rig.yaml"));
  ASSERT_EQ(r.size(), 1u);
  EXPECT_EQ(r[0].width, 800u);
  // Camera 2 m above the origin looking down: the origin is 2 m in front of it.
  EXPECT_TRUE(r[0].toCamera({0, 0, 0}).isApprox(Eigen::Vector3d(0, 0, 2), 1e-12));
}

TEST(Rig, ErrorsNameFileLineAndKey) {
  TempDir dir;
  io::saveVispCameraXml(dir.file("cam.xml"), "cam", twoCameras()[1].intrinsics, std::nullopt, 800, 600);
  auto check = [&](const std::string& body, const std::string& expect) {
    const auto p = dir.write("rig.yaml", "cameras:\n  - name: cam\n" + body);
    try {
      io::loadRig(p);
      ADD_FAILURE() << "accepted: " << body;
    } catch (const InvalidInput& e) {
      EXPECT_NE(std::string(e.what()).find(expect), std::string::npos) << e.what();
    }
  };
  const std::string pose = "    c_M_w: {translation: [0, 0, 1], theta_u_deg: [0, 0, 0]}\n";
  check("    intrinsics: cam.xml\n    projection: without_distortion\n    lens: wide\n" + pose,
        "rig.yaml:5:5: unknown key 'cameras[0].lens'");
  check("    intrinsics: missing.xml\n    projection: without_distortion\n" + pose, "missing.xml");
  check("    intrinsics: cam.xml\n" + pose, "with_distortion");  // file has no distortion model
  check("    intrinsics: cam.xml\n    projection: without_distortion\n    width: 640\n" + pose, "cameras[0].width");
  check("    intrinsics: cam.xml\n    projection: without_distortion\n", "exactly one of 'c_M_w'");
  check("    intrinsics: cam.xml\n    projection: without_distortion\n"
        "    c_M_w: {translation: [0, 0, 1], rotation: [[1,0,0],[0,1,0],[0,0,2]]}\n",
        "cameras[0].c_M_w.rotation': expected an orthonormal");
  check("    intrinsics: cam.xml\n    projection: sideways\n" + pose, "cameras[0].projection");
}
