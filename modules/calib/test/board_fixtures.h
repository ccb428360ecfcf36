// Shared fixtures of the board tests: the true camera and the intrinsics poses, for every board type.
#pragma once

#include <gtest/gtest.h>

#include <Eigen/Geometry>
#include <vector>

#include "viewline/calib/board.h"
#include "viewline/calib/intrinsics.h"
#include "viewline/core/camera.h"
#include "viewline/core/frames.h"

namespace viewline::calib::test {

/// 640x480, px 600, py 605, u0 318, v0 243; with distortion ViSP kud -0.08 (kdu 0.0815).
inline core::Camera trueCamera(bool distortion) {
  core::Camera c;
  c.width = 640;
  c.height = 480;
  if (distortion)
    c.intrinsics.initPersProjWithDistortion(600, 605, 318, 243, -0.08, 0.0815);
  else
    c.intrinsics.initPersProjWithoutDistortion(600, 605, 318, 243);
  return c;
}

/// Board pose: the centre of its points (corners, circles, or a charuco board's inner corners) at
/// distance d, tilted by (ax, ay) about the board's x and y axes, shifted by (dx, dy).
inline Eigen::Isometry3d boardPose(const BoardSpec& b, double d, double ax_deg, double ay_deg, double dx = 0,
                                   double dy = 0) {
  const int points_per_row = b.type == BoardType::ChArUco ? b.cols - 1 : b.cols;
  const int points_per_col = b.type == BoardType::ChArUco ? b.rows - 1 : b.rows;
  const double w = (points_per_row - 1) * b.spacing, h = (points_per_col - 1) * b.spacing;
  Eigen::Isometry3d c_M_o = Eigen::Isometry3d::Identity();
  c_M_o.linear() = (Eigen::AngleAxisd(core::deg2rad(ax_deg), Eigen::Vector3d::UnitX()) *
                    Eigen::AngleAxisd(core::deg2rad(ay_deg), Eigen::Vector3d::UnitY()))
                       .toRotationMatrix();
  c_M_o.translation() = Eigen::Vector3d(dx, dy, d) - c_M_o.linear() * Eigen::Vector3d(w / 2, h / 2, 0);
  return c_M_o;
}

/// The seven poses of the intrinsics tests.
inline std::vector<Eigen::Isometry3d> intrinsicsPoses(const BoardSpec& b) {
  return {boardPose(b, 0.45, 0, 0),        boardPose(b, 0.5, 25, 0, 0.03),   boardPose(b, 0.5, -25, 10, -0.03),
          boardPose(b, 0.5, 5, 30, 0, 0.03), boardPose(b, 0.55, -10, -30),    boardPose(b, 0.6, 20, 20, 0.05, 0.04),
          boardPose(b, 0.4, -15, 20, -0.05, -0.04)};
}

/// The bounds every intrinsics test holds against trueCamera(true): RMS < 0.3 px (OpenCV and ViSP
/// with distortion), focal lengths within 1 %, principal point within 3 px, kud within 0.02, and
/// the model without distortion worse than the one with it.
inline void expectRecoversTrueCamera(const IntrinsicsResult& r) {
  EXPECT_LT(r.rms_px, 0.3);
  EXPECT_LT(r.visp_with_rms_px, 0.3);
  EXPECT_NEAR(r.visp_with.get_px(), 600, 600 * 0.01);
  EXPECT_NEAR(r.visp_with.get_py(), 605, 605 * 0.01);
  EXPECT_NEAR(r.visp_with.get_u0(), 318, 3.0);
  EXPECT_NEAR(r.visp_with.get_v0(), 243, 3.0);
  EXPECT_NEAR(r.visp_with.get_kud(), -0.08, 0.02);
  EXPECT_GT(r.visp_without_rms_px, r.visp_with_rms_px);
}

}  // namespace viewline::calib::test
