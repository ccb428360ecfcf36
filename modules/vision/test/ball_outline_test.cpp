#include <gtest/gtest.h>

#include <cmath>
#include <opencv2/imgproc.hpp>

#include "synthetic.h"
#include "viewline/core/error.h"
#include "viewline/core/frames.h"
#include "viewline/vision/ball_outline.h"

namespace viewline::vision {
namespace {

/// [M]'s camera: 320x240, 90° horizontal field of view, no distortion (f = 160).
core::Camera mCamera() {
  core::Camera cam;
  cam.width = 320;
  cam.height = 240;
  cam.intrinsics = core::intrinsicsFromFov(core::deg2rad(90.0), 320, 240);
  cam.c_M_w = core::lookAt({0.0, -0.32, 0.40}, {0.0, 0.0, 0.0}, {0.0, 0.0, 1.0});
  return cam;
}

SphereCone trueCone(const core::Camera& cam, const Eigen::Vector3d& c_w, double r) {
  const Eigen::Vector3d c_c = cam.c_M_w * c_w;
  SphereCone cone;
  cone.axis = c_c.normalized();
  cone.alpha = std::asin(r / c_c.norm());
  return cone;
}

/// Pixels of the cone's outline at n evenly spread azimuths (exact, no noise).
std::vector<Eigen::Vector2d> conePixels(const core::Camera& cam, const SphereCone& cone, int n, double from = 0.0,
                                        double span = 2.0 * core::kPi) {
  const Eigen::Vector3d e1 = cone.axis.unitOrthogonal(), e2 = cone.axis.cross(e1);
  std::vector<Eigen::Vector2d> out;
  for (int i = 0; i < n; ++i) {
    const double phi = from + span * i / n;
    const Eigen::Vector3d w =
        std::cos(cone.alpha) * cone.axis + std::sin(cone.alpha) * (std::cos(phi) * e1 + std::sin(phi) * e2);
    out.push_back(cam.normalizedToPixel(w.head<2>() / w.z()));
  }
  return out;
}

TEST(BallOutline, CircleFromConeGivesTheConeBackThroughMsConstruction) {
  const core::Camera cam = mCamera();
  for (const Eigen::Vector3d& c_w : {Eigen::Vector3d(0.0, 0.0, 0.025), Eigen::Vector3d(0.12, -0.1, 0.025),
                                     Eigen::Vector3d(-0.12, 0.12, 0.025)}) {
    const SphereCone cone = trueCone(cam, c_w, 0.025);
    const Circle c = circleFromSphereCone(cam, cone);
    const BallOnTableGeometry g = ballViewingCone(cam, c);
    EXPECT_NEAR(g.alpha, cone.alpha, 1e-12);
    EXPECT_LT((g.ray_c - cone.axis).norm(), 1e-12);
  }
  // On the optical axis: a circle of radius f tan α around the principal point.
  SphereCone on_axis;
  on_axis.alpha = 0.05;
  const Circle c = circleFromSphereCone(cam, on_axis);
  EXPECT_NEAR(c.radius, 160.0 * std::tan(0.05), 1e-9);
  EXPECT_LT((c.center - Eigen::Vector2d(160.0, 120.0)).norm(), 1e-9);
}

TEST(BallOutline, ConeFitIsExactOnExactPointsAndDropsOutliers) {
  const core::Camera cam = mCamera();
  const SphereCone truth = trueCone(cam, {0.08, 0.05, 0.025}, 0.025);
  auto pts = conePixels(cam, truth, 40);
  auto fit = fitSphereCone(cam, pts);
  ASSERT_TRUE(fit.has_value());
  EXPECT_NEAR(fit->alpha, truth.alpha, 1e-10);
  EXPECT_LT((fit->axis - truth.axis).norm(), 1e-10);
  EXPECT_EQ(fit->inliers, 40);
  EXPECT_NEAR(fit->max_gap_rad, 2.0 * core::kPi / 40, 1e-6);
  // Three points pushed 1 px outwards: dropped, the fit stays exact.
  const Eigen::Vector2d centre = circleFromSphereCone(cam, truth).center;
  for (int i : {3, 17, 30}) pts[static_cast<std::size_t>(i)] += (pts[static_cast<std::size_t>(i)] - centre).normalized();
  fit = fitSphereCone(cam, pts);
  ASSERT_TRUE(fit.has_value());
  EXPECT_EQ(fit->inliers, 37);
  EXPECT_NEAR(160.0 * (fit->alpha - truth.alpha), 0.0, 1e-8);
  // Half an outline: still the three parameters, and the gap says how much is missing.
  fit = fitSphereCone(cam, conePixels(cam, truth, 20, 0.3, core::kPi));
  ASSERT_TRUE(fit.has_value());
  EXPECT_NEAR(fit->alpha, truth.alpha, 1e-10);
  EXPECT_GT(core::rad2deg(fit->max_gap_rad), 180.0);
  // Too few points: no fit.
  EXPECT_FALSE(fitSphereCone(cam, conePixels(cam, truth, 10)).has_value());
}

/// A shaded green ball (brightness 0.55..1 by Lambert from the upper left) on a uniform
/// background, anti-aliased by 4x4 supersampling.
cv::Mat ballImage(const core::Camera& cam, const Eigen::Vector3d& c_w, const cv::Scalar& background) {
  cv::Mat img(240, 320, CV_8UC3, background);
  test::renderSphere(img, cam, c_w, 0.025, {40, 190, 40});
  return img;
}

TEST(BallOutline, ApparentSizeOfAShadedBallToAHundredthOfAPixel) {
  const core::Camera cam = mCamera();
  for (const Eigen::Vector3d& c_w : {Eigen::Vector3d(0.0, 0.0, 0.025), Eigen::Vector3d(0.1, -0.08, 0.025),
                                     Eigen::Vector3d(-0.11, 0.1, 0.025)}) {
    const Circle truth = circleFromSphereCone(cam, trueCone(cam, c_w, 0.025));
    const cv::Mat img = ballImage(cam, c_w, cv::Scalar(30, 30, 200));  // red table
    // Start 1 px off, as [M]'s minimum enclosing circle of a thresholded mask may be.
    const Circle rough{truth.center + Eigen::Vector2d(0.6, -0.5), truth.radius - 0.7};
    const auto c = refineBallBySphereCone(img, cam, rough, {}, 1.0);
    ASSERT_TRUE(c.has_value()) << c_w.transpose();
    EXPECT_NEAR(c->radius, truth.radius, 0.01) << c_w.transpose();  // 1 mm of d is 0.016 px here
    EXPECT_LT((c->center - truth.center).norm(), 0.02) << c_w.transpose();
  }
}

TEST(BallOutline, RefusesWhenTheBackgroundCannotBeToldFromADarkBall) {
  const core::Camera cam = mCamera();
  const Eigen::Vector3d c_w(0.05, 0.0, 0.025);
  const Circle truth = circleFromSphereCone(cam, trueCone(cam, c_w, 0.025));
  // Black behind the ball: coverage and brightness cannot be separated -> no circle (the caller
  // keeps its own), never a wrong one.
  EXPECT_FALSE(refineBallBySphereCone(ballImage(cam, c_w, cv::Scalar(10, 10, 10)), cam, truth, {}, 1.0).has_value());
  // Half of the background black: a partial outline with a gap above 180° -> refused.
  cv::Mat img = ballImage(cam, c_w, cv::Scalar(30, 30, 200));
  cv::Mat half(240, 320, CV_8UC3, cv::Scalar(10, 10, 10));
  test::renderSphere(half, cam, c_w, 0.025, {40, 190, 40});
  const int split = static_cast<int>(truth.center.x() - 2.0);
  half(cv::Rect(split, 0, 320 - split, 240)).copyTo(img(cv::Rect(split, 0, 320 - split, 240)));
  const auto pts = ballOutlinePoints(img, truth);
  EXPECT_GT(pts.size(), 16u);  // the red half is measured
  for (const auto& p : pts) EXPECT_LT(p.x(), truth.center.x() + 0.5);  // none on the black side
  EXPECT_FALSE(refineBallBySphereCone(img, cam, truth, {}, 1.0).has_value());
}

TEST(BallOutline, RejectsBadParams) {
  BallOutlineParams p;
  p.rays = 4;
  EXPECT_THROW(p.validate(), core::InvalidInput);
  p = {};
  p.clean_margin_px = p.reach_px;
  EXPECT_THROW(p.validate(), core::InvalidInput);
  p = {};
  p.min_ball_level = 1.5;
  EXPECT_THROW(p.validate(), core::InvalidInput);
  EXPECT_NO_THROW(BallOutlineParams{}.validate());
}

}  // namespace
}  // namespace viewline::vision
