#include <gtest/gtest.h>

#include "viewline/core/frames.h"

using namespace viewline::core;

TEST(Frames, VispEigenRoundTrip) {
  vpHomogeneousMatrix M(0.1, -0.2, 0.3, 0.4, -0.5, 0.6);
  const Eigen::Isometry3d T = toEigen(M);
  const vpHomogeneousMatrix M2 = toVisp(T);
  for (unsigned i = 0; i < 4; ++i)
    for (unsigned j = 0; j < 4; ++j) EXPECT_NEAR(M[i][j], M2[i][j], 1e-15);
  vpColVector p(4, 1.0);
  p[0] = 1.0; p[1] = 2.0; p[2] = 3.0;
  const vpColVector q = M * p;
  const Eigen::Vector3d qe = T * Eigen::Vector3d(1.0, 2.0, 3.0);
  for (unsigned i = 0; i < 3; ++i) EXPECT_NEAR(q[i], qe[i], 1e-12);
}

TEST(Frames, LookAtPutsTargetOnTheOpticalAxis) {
  const Eigen::Vector3d eye(2, 1, 1.5), target(0, 0, 1);
  const Eigen::Isometry3d c_M_w = lookAt(eye, target, Eigen::Vector3d::UnitZ());
  const Eigen::Vector3d p_c = c_M_w * target;
  EXPECT_NEAR(p_c.x(), 0.0, 1e-12);
  EXPECT_NEAR(p_c.y(), 0.0, 1e-12);
  EXPECT_NEAR(p_c.z(), (eye - target).norm(), 1e-12);
  // World up appears as image up (negative camera y).
  const Eigen::Vector3d up_c = c_M_w.linear() * Eigen::Vector3d::UnitZ();
  EXPECT_LT(up_c.y(), 0.0);
  EXPECT_NEAR(c_M_w.linear().determinant(), 1.0, 1e-12);
}
