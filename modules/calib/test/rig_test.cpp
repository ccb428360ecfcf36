#include <gtest/gtest.h>

#include "viewline/calib/extrinsics.h"
#include "viewline/calib/render.h"
#include "viewline/core/error.h"
#include "viewline/core/frames.h"

using namespace viewline;
using namespace viewline::calib;

TEST(Rig, TwoRenderedCamerasRecoverTheirRelativePose) {
  core::Camera left;
  left.intrinsics.initPersProjWithoutDistortion(500, 500, 320, 240);
  core::Camera right = left;
  // Right camera 0.2 m to the right, toed in by 5 degrees.
  Eigen::Isometry3d r_M_l = Eigen::Isometry3d::Identity();
  r_M_l.linear() = Eigen::AngleAxisd(core::deg2rad(-5), Eigen::Vector3d::UnitY()).toRotationMatrix();
  r_M_l.translation() = r_M_l.linear() * Eigen::Vector3d(-0.2, 0, 0);
  const BoardSpec b{BoardType::Chessboard, 9, 6, 0.03, "36h11", 0, 0, {}};
  core::Rng rng = core::makeRng(9);
  RigObservations obs;
  obs.cameras = {PoseCamera::fromVisp(left.intrinsics), PoseCamera::fromVisp(right.intrinsics)};
  for (int k = 0; k < 5; ++k) {
    Eigen::Isometry3d l_M_o = Eigen::Isometry3d::Identity();
    l_M_o.linear() = (Eigen::AngleAxisd(core::deg2rad(-15 + 8 * k), Eigen::Vector3d::UnitY()) *
                      Eigen::AngleAxisd(core::deg2rad(10 - 5 * k), Eigen::Vector3d::UnitX())).toRotationMatrix();
    l_M_o.translation() = Eigen::Vector3d(0.1, 0.0, 0.9 + 0.05 * k) - l_M_o.linear() * Eigen::Vector3d(0.12, 0.075, 0);
    std::vector<std::optional<BoardObservation>> v;
    for (const auto& T : {l_M_o, r_M_l * l_M_o}) {
      const Detection d = detectBoard(renderBoard(left, T, b, rng), b);
      ASSERT_TRUE(d.observation) << d.reason;
      v.push_back(d.observation);
    }
    obs.views.push_back(v);
  }
  const RigResult r = calibrateRig(obs);
  EXPECT_LT((r.c_M_ref[1].translation() - r_M_l.translation()).norm(), 0.002);
  EXPECT_LT(core::rad2deg(core::rotationAngle(r.c_M_ref[1].linear(), r_M_l.linear())), 0.2);
  EXPECT_LT(r.rms_px, 0.3) << r.camera_rms_px[0] << " " << r.camera_rms_px[1] << " iterations " << r.iterations;
  EXPECT_TRUE(r.c_M_ref[0].isApprox(Eigen::Isometry3d::Identity()));
  // Too few shared views: a clear error.
  obs.views.resize(2);
  EXPECT_THROW(calibrateRig(obs), core::InvalidInput);
}
