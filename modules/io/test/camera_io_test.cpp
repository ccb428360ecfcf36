#include <gtest/gtest.h>

#include <filesystem>

#include "temp_dir.h"
#include "viewline/core/error.h"
#include "viewline/io/camera_io.h"

using namespace viewline::io;
using viewline::core::InvalidInput;
using viewline::io::test::TempDir;

namespace {
vpCameraParameters without() {
  vpCameraParameters c;
  c.initPersProjWithoutDistortion(600.5, 601.25, 320.125, 240.75);
  return c;
}
vpCameraParameters with() {
  vpCameraParameters c;
  c.initPersProjWithDistortion(598.0, 599.0, 321.0, 239.0, -0.25, 0.26);
  return c;
}
}  // namespace

TEST(CameraIo, VispXmlRoundTripBothModels) {
  TempDir dir;
  const auto path = dir.file("cam.xml");
  saveVispCameraXml(path, "left", without(), with(), 640, 480, "<rms_px>0.2</rms_px>");
  EXPECT_EQ(dir.count(), 1u);
  const auto a = loadVispCameraXml(path, "left", Projection::WithoutDistortion);
  EXPECT_NEAR(a.intrinsics.get_px(), 600.5, 1e-9);
  EXPECT_NEAR(a.intrinsics.get_py(), 601.25, 1e-9);
  EXPECT_NEAR(a.intrinsics.get_u0(), 320.125, 1e-9);
  EXPECT_NEAR(a.intrinsics.get_v0(), 240.75, 1e-9);
  EXPECT_EQ(a.width, 640u);
  EXPECT_EQ(a.height, 480u);
  const auto b = loadVispCameraXml(path, "left", Projection::WithDistortion, 640, 480);
  EXPECT_NEAR(b.intrinsics.get_px(), 598.0, 1e-9);
  EXPECT_NEAR(b.intrinsics.get_kud(), -0.25, 1e-12);
  EXPECT_NEAR(b.intrinsics.get_kdu(), 0.26, 1e-12);
  // Overwriting replaces the file rather than merging into it.
  saveVispCameraXml(path, "left", without(), std::nullopt, 640, 480);
  EXPECT_THROW(loadVispCameraXml(path, "left", Projection::WithDistortion), InvalidInput);
  EXPECT_NO_THROW(loadVispCameraXml(path, "left", Projection::WithoutDistortion));
}

TEST(CameraIo, VispXmlErrorsNameFileAndCamera) {
  TempDir dir;
  const auto path = dir.file("cam.xml");
  saveVispCameraXml(path, "left", without(), with(), 640, 480);
  try {
    loadVispCameraXml(path, "right", Projection::WithoutDistortion);
    FAIL();
  } catch (const InvalidInput& e) {
    const std::string m = e.what();
    EXPECT_NE(m.find(path), std::string::npos) << m;
    EXPECT_NE(m.find("'right'"), std::string::npos) << m;
  }
  EXPECT_THROW(loadVispCameraXml(path, "left", Projection::WithoutDistortion, 320, 240), InvalidInput);
  EXPECT_THROW(loadVispCameraXml(dir.file("none.xml"), "left", Projection::WithoutDistortion), InvalidInput);
  EXPECT_THROW(saveVispCameraXml(path, "x", with(), std::nullopt, 640, 480), InvalidInput);
}

TEST(CameraIo, OpenCvYamlRoundTripAndReadsOpenCvSampleFile) {
  TempDir dir;
  OpenCvIntrinsics o;
  o.camera_matrix << 530.5, 0, 340.25, 0, 531.0, 235.5, 0, 0, 1;
  o.distortion = Eigen::VectorXd(5);
  o.distortion << -0.27, 0.05, 0.001, -0.0002, 0.1;
  o.width = 640;
  o.height = 480;
  o.rms_px = 0.4;
  const auto path = dir.file("cam.yaml");
  saveOpenCvIntrinsics(path, o);
  const auto r = loadOpenCvIntrinsics(path);
  EXPECT_TRUE(r.camera_matrix.isApprox(o.camera_matrix, 1e-12));
  EXPECT_TRUE(r.distortion.isApprox(o.distortion, 1e-12));
  EXPECT_EQ(r.width, 640u);
  EXPECT_DOUBLE_EQ(r.rms_px, 0.4);
  EXPECT_THROW(toVispWithoutDistortion(r, "cam.yaml"), InvalidInput);
  o.distortion.setZero();
  EXPECT_NEAR(toVispWithoutDistortion(o, "x").get_px(), 530.5, 1e-12);

  const std::string sample = "/usr/share/doc/opencv-doc/examples/data/left_intrinsics.yml";
  if (!std::filesystem::exists(sample)) GTEST_SKIP() << "opencv-doc not installed: " << sample << " missing";
  const auto s = loadOpenCvIntrinsics(sample);
  EXPECT_NEAR(s.camera_matrix(0, 0), 535.9, 0.1);
  EXPECT_EQ(s.width, 640u);
  EXPECT_EQ(s.distortion.size(), 5);
}

TEST(CameraIo, OpenCvYamlMissingMatrixIsAnError) {
  TempDir dir;
  const auto p = dir.write("bad.yaml", "%YAML:1.0\n---\nimage_width: 640\n");
  try {
    loadOpenCvIntrinsics(p);
    FAIL();
  } catch (const InvalidInput& e) {
    EXPECT_NE(std::string(e.what()).find("camera_matrix"), std::string::npos);
  }
}
