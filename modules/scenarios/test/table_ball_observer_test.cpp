#include "viewline/scenarios/table_ball_observer.h"

#include <gtest/gtest.h>

#include <cmath>

#include "viewline/core/frames.h"
#include "viewline/core/random.h"

using namespace viewline;

namespace {
core::Camera headCamera() {
  core::Camera cam;
  cam.width = 320;
  cam.height = 240;
  cam.intrinsics = core::intrinsicsFromFov(core::deg2rad(90.0), 320, 240);
  cam.c_M_w = core::lookAt({0.0, -0.30, 0.42}, {0.0, 0.0, 0.0}, {0.0, 0.0, 1.0});
  return cam;
}
}  // namespace

TEST(TableBallObserver, TiltAnglesRoundTrip) {
  for (double ax : {-0.3, -0.05, 0.0, 0.2}) {
    for (double ay : {-0.25, 0.0, 0.1}) {
      const Eigen::Matrix3d R = core::rotation(Eigen::Vector3d::UnitX(), ax) * core::rotation(Eigen::Vector3d::UnitY(), ay);
      const Eigen::Vector2d t = scenarios::tiltFromTableRotation(R);
      EXPECT_NEAR(t.x(), ax, 1e-12);
      EXPECT_NEAR(t.y(), ay, 1e-12);
    }
  }
}

// The corners of the visible red quadrilateral (border occlusion included) are projected exactly;
// the plain PnP against (±L/2, ±L/2, 0) is then tilted, the border-aware one recovers the pose.
TEST(TableBallObserver, BorderAwarePnpRemovesTheOcclusionBias) {
  const core::Camera cam = headCamera();
  const double L = 0.3, h = 0.02, half = 0.5 * L;
  Eigen::Isometry3d w_M_t = Eigen::Isometry3d::Identity();
  w_M_t.linear() = core::rotation(Eigen::Vector3d::UnitX(), 0.05) * core::rotation(Eigen::Vector3d::UnitY(), -0.03);
  const Eigen::Isometry3d c_M_t = cam.c_M_w * w_M_t;
  // Visible strip: camera centre in the table frame, shadow of each border's top inner edge.
  const Eigen::Vector3d ct = c_M_t.inverse().translation();
  ASSERT_LT(ct.y(), -half);  // the camera is behind the near (-y) side: that border hides red
  auto shift = [&](double c) { return h * std::max(0.0, c - half) / (ct.z() - h); };
  const std::array<Eigen::Vector3d, 4> visible = {
      Eigen::Vector3d(-half + shift(-ct.x()), -half + shift(-ct.y()), 0.0),
      Eigen::Vector3d(half - shift(ct.x()), -half + shift(-ct.y()), 0.0),
      Eigen::Vector3d(half - shift(ct.x()), half - shift(ct.y()), 0.0),
      Eigen::Vector3d(-half + shift(-ct.x()), half - shift(ct.y()), 0.0)};
  EXPECT_GT(shift(-ct.y()), 0.005);  // several millimetres hidden
  std::array<Eigen::Vector2d, 4> px;
  for (int i = 0; i < 4; ++i) {
    const Eigen::Vector3d pc = c_M_t * visible[static_cast<std::size_t>(i)];
    px[static_cast<std::size_t>(i)] = cam.normalizedToPixel(pc.head<2>() / pc.z());
  }
  // Plain PnP = border height 0 started from the truth: converges to the biased pose.
  const Eigen::Isometry3d plain = scenarios::borderAwareTablePose(cam, px, c_M_t, L, 1e-9, 3);
  const Eigen::Isometry3d fixed = scenarios::borderAwareTablePose(cam, px, plain, L, h, 3);
  const double plain_err = core::rotationAngle(plain.linear(), c_M_t.linear());
  const double fixed_err = core::rotationAngle(fixed.linear(), c_M_t.linear());
  EXPECT_GT(core::rad2deg(plain_err), 0.3);
  EXPECT_LT(core::rad2deg(fixed_err), 0.01);
  EXPECT_LT((fixed.translation() - c_M_t.translation()).norm(), 1e-4);
}

TEST(TableBallObserver, TrackerPredictsThroughMissedDetectionsAndClampsAtTheBorder) {
  scenarios::RollingBallTrackerConfig cfg;
  scenarios::RollingBallTracker trk(cfg);
  const double dt = 0.02;
  const Eigen::Vector2d a(0.5, 0.0);  // rolling towards +x
  // Nothing before the first detection.
  trk.step(0.0, a, std::nullopt);
  EXPECT_FALSE(trk.initialized());
  // Measurements of a ball accelerating at a along x from rest at x = 0.
  double t = 0.0;
  for (int k = 0; k < 25; ++k) {
    t = k * dt;
    trk.step(t, a, Eigen::Vector2d(0.5 * a.x() * t * t, 0.0));
  }
  ASSERT_TRUE(trk.initialized());
  EXPECT_EQ(static_cast<int>(trk.predictions().size()), 10);
  EXPECT_GT(trk.predictions().back().x(), trk.position().x());
  // Missed detections: keeps predicting, moving along x.
  const double x_before = trk.position().x();
  for (int k = 25; k < 30; ++k) trk.step(k * dt, a, std::nullopt);
  EXPECT_EQ(trk.missedStreak(), 5);
  EXPECT_GT(trk.position().x(), x_before + 0.005);
  // Long enough without measurements: stops at the border L/2 - r with zero velocity along x.
  for (int k = 30; k < 200; ++k) trk.step(k * dt, a, std::nullopt);
  EXPECT_NEAR(trk.position().x(), 0.125, 1e-12);
  EXPECT_EQ(trk.velocity().x(), 0.0);
  for (const auto& p : trk.predictions()) EXPECT_LE(p.x(), 0.125 + 1e-12);
}

TEST(TableBallObserver, StationaryGainMatchesTheTimeVaryingFilterInSteadyState) {
  scenarios::RollingBallTrackerConfig tv, st;
  st.stationary_gain = true;
  scenarios::RollingBallTracker a(tv), b(st);
  core::Rng rng = core::makeRng(3);
  for (int k = 0; k < 400; ++k) {
    const Eigen::Vector2d y(0.05 * std::sin(0.02 * k) + core::gaussian(rng, 0.002), core::gaussian(rng, 0.002));
    a.step(k * 0.02, Eigen::Vector2d::Zero(), y);
    b.step(k * 0.02, Eigen::Vector2d::Zero(), y);
  }
  EXPECT_LT((a.position() - b.position()).norm(), 1e-5);
  EXPECT_LT((a.P() - b.P()).cwiseAbs().maxCoeff(), 1e-6);
}
