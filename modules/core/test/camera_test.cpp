#include <gtest/gtest.h>

#include "viewline/core/camera.h"
#include "viewline/core/frames.h"

using namespace viewline::core;

TEST(Camera, FovIntrinsicsMatchSpecTableScene) {
  // SPEC §3: 320x240, 90 deg horizontal field of view -> fx = fy = 160, cx = 160, cy = 120.
  const vpCameraParameters k = intrinsicsFromFov(deg2rad(90.0), 320, 240);
  EXPECT_NEAR(k.get_px(), 160.0, 1e-9);
  EXPECT_NEAR(k.get_py(), 160.0, 1e-9);
  EXPECT_NEAR(k.get_u0(), 160.0, 1e-12);
  EXPECT_NEAR(k.get_v0(), 120.0, 1e-12);
}

TEST(Camera, ProjectionAndBackProjectionAgree) {
  Camera cam;
  cam.intrinsics = vpCameraParameters(800, 790, 320, 240, -0.1, 0.1);  // with distortion
  cam.c_M_w = lookAt({1.0, -2.0, 1.5}, {0.0, 0.0, 1.0}, Eigen::Vector3d::UnitZ());
  const Eigen::Vector3d p_w(0.2, 0.1, 1.1);
  const auto uv = cam.project(p_w);
  ASSERT_TRUE(uv.has_value());
  // The distortion-free projection matrix maps p_w to the undistorted normalised point.
  const Eigen::Vector3d h = cam.normalizedProjection() * p_w.homogeneous();
  const Eigen::Vector2d xy = h.hnormalized();
  const Eigen::Vector3d p_c = cam.toCamera(p_w);
  EXPECT_NEAR(xy.x(), p_c.x() / p_c.z(), 1e-12);
  // Ray through the pixel passes close to the point (kud/kdu are ViSP's two approximations).
  const Eigen::Vector3d ray = cam.rayThroughPixel_w(*uv);
  const Eigen::Vector3d d = p_w - cam.center_w();
  const double miss = (d - d.dot(ray) * ray).norm();
  EXPECT_LT(miss, 2e-3);
  EXPECT_FALSE(cam.project(cam.center_w() - 2.0 * ray).has_value());
}
