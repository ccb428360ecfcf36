#include <gtest/gtest.h>

#include <Eigen/Eigenvalues>
#include <cmath>
#include <opencv2/imgproc.hpp>
#include <visp3/core/vpImageConvert.h>
#include <visp3/detection/vpDetectorAprilTag.h>

#include "viewline/core/error.h"
#include "viewline/core/frames.h"
#include "viewline/sim/renderer.h"

using namespace viewline;
using namespace viewline::sim;

namespace {

core::Camera makeCamera(bool distortion) {
  core::Camera c;
  c.name = distortion ? "distorted" : "pinhole";
  c.width = 656;
  c.height = 480;
  if (distortion) {
    c.intrinsics = vpCameraParameters(600.0, 605.0, 330.0, 236.0, -0.12, 0.13);
  } else {
    c.intrinsics = vpCameraParameters(600.0, 605.0, 330.0, 236.0);
  }
  c.c_M_w = core::lookAt({0.0, -3.0, 1.0}, {0.0, 0.0, 1.0}, Eigen::Vector3d::UnitZ());
  return c;
}

// Unlit ball on a uniform background: the image is coverage-weighted, so the coverage of each
// pixel is recovered exactly (up to 8-bit rounding) from one channel.
struct Moments {
  double area = 0.0;
  Eigen::Vector2d mean = Eigen::Vector2d::Zero();
  Eigen::Matrix2d cov = Eigen::Matrix2d::Zero();
};

Moments coverageMoments(const cv::Mat& img, double bg, double fg, int channel) {
  Moments m;
  for (int v = 0; v < img.rows; ++v) {
    for (int u = 0; u < img.cols; ++u) {
      const double a = (img.at<cv::Vec3b>(v, u)[channel] - bg) / (fg - bg);
      if (a <= 0.0) continue;
      m.area += a;
      m.mean += a * Eigen::Vector2d(u, v);
    }
  }
  m.mean /= m.area;
  for (int v = 0; v < img.rows; ++v) {
    for (int u = 0; u < img.cols; ++u) {
      const double a = (img.at<cv::Vec3b>(v, u)[channel] - bg) / (fg - bg);
      if (a <= 0.0) continue;
      const Eigen::Vector2d d = Eigen::Vector2d(u, v) - m.mean;
      m.cov += a * d * d.transpose();
    }
  }
  m.cov /= m.area;
  return m;
}

double polygonArea(const std::vector<Eigen::Vector2d>& p) {
  double a = 0.0;
  for (std::size_t i = 0; i < p.size(); ++i) {
    const auto& q = p[(i + 1) % p.size()];
    a += p[i].x() * q.y() - q.x() * p[i].y();
  }
  return 0.5 * std::abs(a);
}

Scene ballScene(const Eigen::Vector3d& c_w, double r) {
  Scene s;
  s.background_bgr = Eigen::Vector3d(0.2, 0.2, 0.2);  // 51 and 204: exact in 8 bits
  Primitive ball = makeSphere("ball", c_w, r, Eigen::Vector3d(0.8, 0.8, 0.8));
  ball.material.unlit = true;
  s.primitives.push_back(ball);
  return s;
}

}  // namespace

TEST(Renderer, BallCentroidAndAreaMatchTheExactProjection) {
  Renderer renderer;
  for (bool distortion : {false, true}) {
    const core::Camera cam = makeCamera(distortion);
    // On axis, off axis (elongated) and near a corner.
    for (const Eigen::Vector3d& c_w : {Eigen::Vector3d(0.013, 0.0, 1.007), Eigen::Vector3d(0.9, 0.2, 1.5),
                                       Eigen::Vector3d(-1.2, 0.4, 0.25)}) {
      const Scene scene = ballScene(c_w, 0.05);
      const cv::Mat img = renderer.renderScene(scene, cam);
      ASSERT_EQ(img.type(), CV_8UC3);
      ASSERT_EQ(img.cols, 656);
      ASSERT_EQ(img.rows, 480);
      const ObjectTruth t = describe(scene.primitives[0], cam);
      ASSERT_EQ(t.outline_px.size(), 120u);
      const Moments m = coverageMoments(img, 51.0, 204.0, 1);
      EXPECT_LT((m.mean - t.outline_centroid_px).norm(), 0.02) << "distortion " << distortion << " at " << c_w.transpose();
      EXPECT_NEAR(m.area / polygonArea(t.outline_px), 1.0, 0.003);
      // The sphere centre projects where the camera model says.
      EXPECT_LT((t.center_px - *cam.project(c_w)).norm(), 1e-9);
      // Second moments of a uniform ellipse: eigenvalues a²/4, b²/4 (no distortion only).
      if (!distortion) {
        Eigen::SelfAdjointEigenSolver<Eigen::Matrix2d> es(m.cov);
        EXPECT_NEAR(2.0 * std::sqrt(es.eigenvalues()[1]), t.semi_major_px, 0.01 * t.semi_major_px);
        EXPECT_NEAR(2.0 * std::sqrt(es.eigenvalues()[0]), t.semi_minor_px, 0.01 * t.semi_minor_px);
      }
    }
  }
  // Off-axis elongation is real: the corner ball's silhouette is an ellipse, not a circle.
  const core::Camera cam = makeCamera(false);
  const ObjectTruth corner = describe(ballScene({-1.2, 0.4, 0.25}, 0.05).primitives[0], cam);
  EXPECT_GT(corner.semi_major_px / corner.semi_minor_px, 1.05);
  EXPECT_GT((corner.outline_centroid_px - corner.center_px).norm(), 0.02);
}

TEST(Renderer, LambertShadingIsBrightestTowardsTheLight) {
  Renderer renderer;
  const core::Camera cam = makeCamera(false);
  Scene scene;
  scene.background_bgr.setZero();
  scene.primitives.push_back(makeSphere("ball", {0.0, 0.0, 1.0}, 0.3, Eigen::Vector3d(0.8, 0.8, 0.8)));
  Lighting light;
  light.direction_w = Eigen::Vector3d(1.0, 0.0, 0.0);  // from +x: the right of the image
  const cv::Mat img = renderer.renderScene(scene, cam, light);
  const auto c = cam.project({0.0, 0.0, 1.0});
  const int u = static_cast<int>(c->x()), v = static_cast<int>(c->y());
  const int right = img.at<cv::Vec3b>(v, u + 40)[0], left = img.at<cv::Vec3b>(v, u - 40)[0];
  EXPECT_GT(right, left + 50);
  EXPECT_NEAR(left, 255 * 0.8 * 0.35, 2.0);  // unlit side: ambient only
}

TEST(Renderer, RendersPrimitivesWhereTheyProject) {
  Renderer renderer;
  const core::Camera cam = makeCamera(true);
  Scene scene;
  scene.background_bgr.setZero();
  Eigen::Isometry3d pose = Eigen::Isometry3d::Identity();
  pose.translation() = Eigen::Vector3d(-0.5, 0.0, 1.0);
  scene.primitives.push_back(makeBox("box", pose, Eigen::Vector3d(0.2, 0.2, 0.2), Eigen::Vector3d(0.0, 0.0, 1.0)));
  Primitive cyl;
  cyl.shape = Shape::Cylinder;
  cyl.w_M_o.translation() = Eigen::Vector3d(0.0, 0.0, 0.8);
  cyl.size = Eigen::Vector3d(0.05, 0.0, 0.4);
  cyl.material.albedo_bgr = Eigen::Vector3d(0.0, 1.0, 0.0);
  scene.primitives.push_back(cyl);
  Primitive cone = cyl;
  cone.shape = Shape::Cone;
  cone.w_M_o.translation() = Eigen::Vector3d(0.5, 0.0, 0.8);
  cone.material.albedo_bgr = Eigen::Vector3d(1.0, 0.0, 0.0);
  scene.primitives.push_back(cone);
  pose.translation() = Eigen::Vector3d(0.0, 0.5, 1.6);
  pose.linear() = core::rotation(Eigen::Vector3d::UnitX(), M_PI / 2);
  scene.primitives.push_back(makeDisc("disc", pose, 0.1, Eigen::Vector3d(1.0, 1.0, 0.0)));
  const cv::Mat img = renderer.renderScene(scene, cam);
  auto at = [&](const Eigen::Vector3d& p) {
    const auto uv = cam.project(p);
    return img.at<cv::Vec3b>(static_cast<int>(std::lround(uv->y())), static_cast<int>(std::lround(uv->x())));
  };
  const cv::Vec3b box = at({-0.5, -0.1, 1.0});  // centre of the front face
  EXPECT_GT(box[2], 60);
  EXPECT_EQ(box[0], 0);
  EXPECT_GT(at({0.0, -0.05, 1.0})[1], 60);   // cylinder side
  EXPECT_EQ(at({0.0, -0.05, 1.0})[2], 0);
  EXPECT_GT(at({0.5, -0.02, 0.85})[0], 30);  // cone near its base
  EXPECT_EQ(at({0.5, 0.0, 1.25})[0], 0);     // above the apex: nothing
  EXPECT_GT(at({0.0, 0.5, 1.6})[0], 60);     // disc
  EXPECT_EQ(at({0.0, 0.5, 1.75})[0], 0);     // outside the disc
}

TEST(Renderer, AprilTagsAreReadByVispWithTheirCorners) {
  Renderer renderer;
  core::Camera cam = makeCamera(true);
  Scene scene;
  scene.background_bgr = Eigen::Vector3d(0.5, 0.5, 0.5);
  // Tag facing the camera (its z into the surface, away from the camera), tilted 25 deg.
  const Eigen::Isometry3d w_M_c = cam.c_M_w.inverse();
  Eigen::Isometry3d c_M_tag = Eigen::Isometry3d::Identity();
  c_M_tag.linear() = core::rotation(Eigen::Vector3d::UnitY(), core::deg2rad(25.0)) *
                     core::rotation(Eigen::Vector3d::UnitZ(), core::deg2rad(10.0));
  c_M_tag.translation() = Eigen::Vector3d(0.1, -0.05, 1.2);
  scene.primitives.push_back(makeTag36h11("tag7", 7, 0.12, w_M_c * c_M_tag));
  const cv::Mat img = renderer.renderScene(scene, cam);
  cv::Mat grey;
  cv::cvtColor(img, grey, cv::COLOR_BGR2GRAY);
  vpImage<unsigned char> I;
  vpImageConvert::convert(grey, I);
  vpDetectorAprilTag detector(vpDetectorAprilTag::TAG_36h11);
  ASSERT_TRUE(detector.detect(I));
  ASSERT_EQ(detector.getNbObjects(), 1u);
  EXPECT_EQ(detector.getMessage(0), "36h11 id: 7");
  const ObjectTruth t = describe(scene.primitives[0], cam);
  ASSERT_EQ(t.corners_px.size(), 4u);
  EXPECT_EQ(t.tag_id, 7);
  const auto pts = detector.getPolygon(0);
  ASSERT_EQ(pts.size(), 4u);
  // Every detected corner is one of the true corners. The AprilTag library puts pixel centres at
  // (i + 0.5, j + 0.5); ViSP, OpenCV and this renderer at (i, j): its corners are 0.5 px further.
  for (const auto& ip : pts) {
    double best = 1e9;
    for (const auto& c : t.corners_px) {
      best = std::min(best, std::hypot(ip.get_u() - 0.5 - c.x(), ip.get_v() - 0.5 - c.y()));
    }
    EXPECT_LT(best, 0.2) << ip.get_u() << " " << ip.get_v();
  }
}

TEST(Renderer, MotionBlurAveragesTheExposureAndCacheIsReused) {
  core::Camera cam = makeCamera(false);
  Scene scene;
  scene.background_bgr = Eigen::Vector3d(0.2, 0.2, 0.2);
  const SceneWorld world(scene, [](double t, std::vector<Primitive>& out) {
    Primitive b = makeSphere("ball", {4.0 * t, 0.0, 1.0}, 0.05, Eigen::Vector3d(0.8, 0.8, 0.8));
    b.material.unlit = true;
    out.push_back(b);
  });
  Renderer renderer;
  std::vector<ObjectTruth> truth;
  const cv::Mat sharp = renderer.render(world, cam, {0.0, 0.0, 1}, &truth);
  ASSERT_EQ(truth.size(), 1u);
  EXPECT_NEAR(truth[0].visible_fraction, 1.0, 1e-12);
  EXPECT_GT(truth[0].footprint_px, 100);
  const cv::Mat blurred = renderer.render(world, cam, {0.0, 0.02, 9});  // 8 cm of motion
  const Moments ms = coverageMoments(sharp, 51.0, 204.0, 0);
  const Moments mb = coverageMoments(blurred, 51.0, 204.0, 0);
  EXPECT_LT((ms.mean - mb.mean).norm(), 0.05);            // symmetric exposure: same centroid
  EXPECT_NEAR(mb.area / ms.area, 1.0, 0.01);               // same energy
  // Streak along x: 9 instants evenly spread over L = 8 cm of motion add L²(n²-1)/(12 n²).
  const double L_px = 0.08 * 600.0 / 3.0;
  EXPECT_NEAR(mb.cov(0, 0), ms.cov(0, 0) + L_px * L_px * 80.0 / (12.0 * 81.0), 0.5);
  EXPECT_NEAR(mb.cov(1, 1), ms.cov(1, 1), 0.05 * ms.cov(1, 1));
  // Same inputs, same pixels.
  const cv::Mat again = renderer.render(world, cam, {0.0, 0.0, 1});
  EXPECT_EQ(cv::norm(sharp, again, cv::NORM_INF), 0.0);
}

TEST(Renderer, DistortionRayMapInvertsTheCameraModel) {
  const core::Camera cam = makeCamera(true);
  for (const Eigen::Vector2d& xy : {Eigen::Vector2d(0.0, 0.0), Eigen::Vector2d(0.4, -0.3), Eigen::Vector2d(-0.55, 0.38)}) {
    const Eigen::Vector2d uv = cam.normalizedToPixel(xy);
    EXPECT_LT((undistortExact(cam, uv) - xy).norm(), 1e-12);
  }
}

TEST(Renderer, BadInputThrows) {
  Renderer renderer;
  core::Camera cam = makeCamera(false);
  cam.width = 0;
  EXPECT_THROW(renderer.renderScene(Scene{}, cam), core::InvalidInput);
  EXPECT_THROW(makeSphere("b", {0, 0, 0}, -1.0, Eigen::Vector3d::Ones()), core::InvalidInput);
  EXPECT_THROW(makeSphere("b", {0, 0, 0}, 1.0, Eigen::Vector3d(2, 0, 0)), core::InvalidInput);
  EXPECT_THROW(tag36h11Texture(100000), core::InvalidInput);
  const SceneWorld world(Scene{});
  EXPECT_THROW(renderer.render(world, makeCamera(false), {std::nan(""), 0.0, 1}), core::InvalidInput);
  EXPECT_THROW(renderer.render(world, makeCamera(false), {0.0, -1.0, 1}), core::InvalidInput);
  EXPECT_THROW(renderer.render(world, makeCamera(false), {0.0, 0.01, 0}), core::InvalidInput);
  RenderSettings bad;
  bad.supersampling = 0;
  EXPECT_THROW(Renderer{bad}, core::InvalidInput);
}

TEST(Renderer, StaticCacheFollowsSceneChanges) {
  const core::Camera cam = makeCamera(false);
  Renderer renderer;
  SceneWorld world(ballScene({0.0, 0.0, 1.0}, 0.2));
  const cv::Mat a = renderer.render(world, cam, {0.0, 0.0, 1});
  world.scene().primitives[0].material.albedo_bgr = Eigen::Vector3d(0.1, 0.9, 0.1);
  const cv::Mat b = renderer.render(world, cam, {0.0, 0.0, 1});
  const auto c = cam.project({0.0, 0.0, 1.0});
  EXPECT_EQ(a.at<cv::Vec3b>(static_cast<int>(c->y()), static_cast<int>(c->x()))[0], 204);
  EXPECT_EQ(b.at<cv::Vec3b>(static_cast<int>(c->y()), static_cast<int>(c->x()))[0], 26);
  // A different world with the same content renders the same pixels.
  const SceneWorld other(ballScene({0.0, 0.0, 1.0}, 0.2));
  EXPECT_EQ(cv::norm(renderer.render(other, cam, {0.0, 0.0, 1}), a, cv::NORM_INF), 0.0);
}
