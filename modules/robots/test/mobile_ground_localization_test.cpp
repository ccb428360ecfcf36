#include "viewline/robots/mobile_ground_localization.h"

#include <gtest/gtest.h>

#include <cmath>
#include <limits>

#include "viewline/core/frames.h"
#include "viewline/core/random.h"
#include "viewline/robots/mobile_pan_tilt.h"

namespace viewline::robots {
namespace {

core::Camera headCamera(const PanTiltJoints& q, double x, double y, double theta) {
  core::Camera cam;
  cam.width = 320;
  cam.height = 240;
  cam.intrinsics = core::intrinsicsFromFov(core::deg2rad(50.0), 320, 240);
  cam.c_M_w = headCamera_c_M_w(MobilePanTilt{}, q, x, y, theta);
  return cam;
}

TEST(GroundLocalization, ExactBackProjectionInvertsTheProjection) {
  core::Rng rng = core::makeRng(4);
  for (int i = 0; i < 200; ++i) {
    const auto cam = headCamera({core::uniform(rng, 0.3, 1.2), core::uniform(rng, -0.8, 0.8)},
                                core::uniform(rng, -2, 2), core::uniform(rng, -2, 2), core::uniform(rng, -3, 3));
    const Eigen::Vector2d uv(core::uniform(rng, 0, 319), core::uniform(rng, 0, 239));
    const auto p = groundPointExact(cam, uv, 0.025);
    if (!p) continue;
    const auto back = cam.project(Eigen::Vector3d(p->x(), p->y(), 0.025));
    ASSERT_TRUE(back.has_value());
    EXPECT_LT((*back - uv).norm(), 1e-6);
  }
}

TEST(GroundLocalization, AnglePerPixelIsExactOnTheOpticalAxisWithHorizontalRange) {
  const auto cam = headCamera({0.5, 0.3}, 0.4, -0.2, 0.9);
  const AnglePerPixel model{core::deg2rad(50.0), 2.0 * std::atan(120.0 / cam.intrinsics.get_py()),
                            AngleRange::Horizontal};
  const Eigen::Vector2d centre(cam.intrinsics.get_u0(), cam.intrinsics.get_v0());
  const auto exact = groundPointExact(cam, centre);
  const auto approx = groundPointAnglePerPixel(cam, centre, model);
  ASSERT_TRUE(exact && approx);
  EXPECT_LT((*exact - *approx).norm(), 1e-9);
  // The printed (slant) range overshoots by h / sin δ - h / tan δ > 0 along the axis.
  AnglePerPixel printed = model;
  printed.range = AngleRange::PrintedSlant;
  const auto slant = groundPointAnglePerPixel(cam, centre, printed);
  ASSERT_TRUE(slant.has_value());
  const CameraAttitude att = cameraAttitude(cam);
  const double h = cam.center_w().z();
  EXPECT_NEAR((*slant - *exact).norm(), h / std::sin(att.depression) - h / std::tan(att.depression), 1e-9);
}

TEST(GroundLocalization, AnglePerPixelErrorGrowsTowardsTheImageBorder) {
  // Pan after tilt rolls the image; the roll is removed, so the approximation stays close near
  // the centre and degrades towards the borders (linear angle per pixel vs atan).
  const auto cam = headCamera({0.6, 0.5}, 0.0, 0.0, 0.0);
  EXPECT_GT(std::abs(cameraAttitude(cam).roll), 0.05);
  const AnglePerPixel model{core::deg2rad(50.0), 2.0 * std::atan(120.0 / cam.intrinsics.get_py()),
                            AngleRange::Horizontal};
  auto err = [&](double u, double v) {
    const auto e = groundPointExact(cam, {u, v}), a = groundPointAnglePerPixel(cam, {u, v}, model);
    return (e && a) ? (*e - *a).norm() : std::numeric_limits<double>::quiet_NaN();
  };
  const double centre = err(165, 125), border = err(300, 220);
  EXPECT_LT(centre, 0.01);
  EXPECT_GT(border, 2.0 * centre);
  EXPECT_TRUE(std::isfinite(border));
}

TEST(GroundLocalization, CovarianceFollowsTheJacobian) {
  const auto cam = headCamera({0.5, 0.0}, 0, 0, 0);
  const auto cov = groundPointCovariance(cam, {160, 150}, Eigen::Matrix2d::Identity());
  ASSERT_TRUE(cov.has_value());
  // Range (x) is more uncertain than the lateral position at an oblique view.
  EXPECT_GT((*cov)(0, 0), (*cov)(1, 1));
  EXPECT_FALSE(groundPointExact(cam, {160, 0}, 0.6).has_value());  // plane above the camera
}

}  // namespace
}  // namespace viewline::robots
