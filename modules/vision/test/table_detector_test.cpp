#include <gtest/gtest.h>

#include <cmath>
#include <opencv2/imgproc.hpp>

#include "synthetic.h"
#include "viewline/core/error.h"
#include "viewline/core/frames.h"
#include "viewline/vision/table_detector.h"
#include "viewline/vision/table_edge_tracker.h"

namespace viewline::vision {
namespace {

constexpr double kSide = 0.3;
constexpr double kBall = 0.025;
const cv::Vec3b kGreen{40, 190, 40};

/// [M]'s camera: 320x240, 90° horizontal field of view, no distortion (f = 160).
core::Camera mCamera() {
  core::Camera cam;
  cam.width = 320;
  cam.height = 240;
  cam.intrinsics = core::intrinsicsFromFov(core::deg2rad(90.0), 320, 240);
  cam.c_M_w = core::lookAt({0.0, -0.32, 0.40}, {0.0, 0.0, 0.0}, {0.0, 0.0, 1.0});
  return cam;
}

struct Scene {
  cv::Mat image;
  Eigen::Isometry3d c_M_t;
  Eigen::Vector3d ball_t;
};

Scene renderScene(const core::Camera& cam, double tilt_x, double tilt_y, const Eigen::Vector2d& ball_xy,
                  std::uint64_t seed, bool with_ball = true) {
  Eigen::Isometry3d w_M_t = Eigen::Isometry3d::Identity();
  w_M_t.linear() = core::rotation(Eigen::Vector3d::UnitX(), tilt_x) * core::rotation(Eigen::Vector3d::UnitY(), tilt_y);
  Scene s;
  s.image = test::texturedBackground(320, 240, seed);
  test::renderTable(s.image, cam, w_M_t, kSide, 0.02);
  s.ball_t = {ball_xy.x(), ball_xy.y(), kBall};
  if (with_ball) test::renderSphere(s.image, cam, w_M_t * s.ball_t, kBall, kGreen);
  s.c_M_t = cam.c_M_w * w_M_t;
  return s;
}

TEST(BallOnTableGeometry, ExactConeGivesExactCentreAndShowsTheErratum) {
  const auto cam = mCamera();
  const Eigen::Isometry3d c_M_t = cam.c_M_w;  // table frame = world
  const Eigen::Vector3d p_t(0.05, -0.03, kBall);
  const Eigen::Vector3d p_c = c_M_t * p_t;
  const double D = p_c.norm(), alpha = std::asin(kBall / D);
  // Major-axis end points: the sphere centre ray turned by ±α in the plane through the optical axis.
  const Eigen::Vector3d axis = Eigen::Vector3d::UnitZ().cross(p_c).normalized();
  const Eigen::Vector3d va = Eigen::AngleAxisd(alpha, axis) * p_c.normalized();
  const Eigen::Vector3d vb = Eigen::AngleAxisd(-alpha, axis) * p_c.normalized();
  const Eigen::Vector2d a = cam.normalizedToPixel(va.head<2>() / va.z());
  const Eigen::Vector2d b = cam.normalizedToPixel(vb.head<2>() / vb.z());
  const Circle circle{0.5 * (a + b), 0.5 * (a - b).norm()};

  const auto known = ballOnTableKnownRadius(cam, circle, c_M_t, kBall);
  EXPECT_NEAR(known.alpha, alpha, 1e-9);
  EXPECT_NEAR(known.distance_m, D, 1e-9);           // d = r / sin α
  EXPECT_NEAR((known.p_t - p_t).norm(), 0.0, 1e-9);
  // [M]'s printed eq 4.12, d = r sqrt(1 + 1/tan α), is off by centimetres here.
  const double printed = kBall * std::sqrt(1.0 + 1.0 / std::tan(alpha));
  EXPECT_GT(std::abs(printed - D), 0.05);

  const auto unknown = ballOnTableUnknownRadius(cam, circle, c_M_t);
  ASSERT_TRUE(unknown.has_value());
  EXPECT_NEAR(unknown->radius_m, kBall, 1e-9);
  EXPECT_NEAR((unknown->p_t - p_t).norm(), 0.0, 1e-9);
}

TEST(TableGeometry, QuarterTurnsAlignASquare) {
  const auto cam = mCamera();
  const Eigen::Isometry3d truth = cam.c_M_w;
  for (int k = 0; k < 4; ++k) {
    const auto turned = turnTableFrame(truth, k);
    const int back = yawQuarterTurnsTo(turned, truth);
    EXPECT_NEAR(core::rotationAngle(turnTableFrame(turned, back).linear(), truth.linear()), 0.0, 1e-9);
  }
}

TEST(TableDetector, TablePoseAndBallOnTableFromRenderedScenes) {
  const auto cam = mCamera();
  TableDetector det(cam);
  core::Rng rng = core::makeRng(5);
  double rot_sq = 0.0, known_sq = 0.0, unknown_sq = 0.0;
  const int n = 8;
  for (int i = 0; i < n; ++i) {
    const double tx = core::deg2rad(core::uniform(rng, -10.0, 10.0));
    const double ty = core::deg2rad(core::uniform(rng, -10.0, 10.0));
    const Eigen::Vector2d xy(core::uniform(rng, -0.09, 0.09), core::uniform(rng, -0.09, 0.09));
    const Scene s = renderScene(cam, tx, ty, xy, 50 + static_cast<unsigned>(i));
    det.setPrior(s.c_M_t);  // resolve the square's quarter-turn symmetry
    const auto scene = det.detect(s.image, 0.02 * i);
    ASSERT_TRUE(scene.table.ok()) << scene.table.failure().message;
    ASSERT_TRUE(scene.ball.ok()) << scene.ball.failure().message;
    const double rot = core::rotationAngle(scene.table->c_M_t.linear(), s.c_M_t.linear());
    rot_sq += rot * rot;
    EXPECT_LT((scene.table->c_M_t.translation() - s.c_M_t.translation()).norm(), 0.01);
    known_sq += (scene.ball->known_radius.p_t - s.ball_t).squaredNorm();
    ASSERT_TRUE(scene.ball->unknown_radius.has_value());
    unknown_sq += (scene.ball->unknown_radius->p_t - s.ball_t).squaredNorm();
    EXPECT_NEAR(scene.ball->unknown_radius->radius_m, kBall, 0.004);
    EXPECT_DOUBLE_EQ(scene.ball->stamp, 0.02 * i);
  }
  const double rot_rms = core::rad2deg(std::sqrt(rot_sq / n));
  const double known_rms = std::sqrt(known_sq / n), unknown_rms = std::sqrt(unknown_sq / n);
  RecordProperty("rotation_rms_deg", std::to_string(rot_rms));
  RecordProperty("ball_known_rms_mm", std::to_string(1e3 * known_rms));
  RecordProperty("ball_unknown_rms_mm", std::to_string(1e3 * unknown_rms));
  std::printf("table rotation RMS %.3f deg, ball known-r RMS %.2f mm, unknown-r RMS %.2f mm\n", rot_rms,
              1e3 * known_rms, 1e3 * unknown_rms);
  EXPECT_LT(rot_rms, 0.5);
  EXPECT_LT(unknown_rms, 0.002);
  EXPECT_LT(known_rms, 0.003);
}

TEST(TableDetector, ProductionWithoutRefinementMatchesTheReference) {
  const auto cam = mCamera();
  TableDetectorConfig cfg;
  cfg.refine = false;
  TableDetector det(cam, cfg);
  for (int i = 0; i < 3; ++i) {  // frame 0 full frame, then in the window around the last table
    const Scene s = renderScene(cam, core::deg2rad(4.0 * i), core::deg2rad(-3.0), {0.03 * i, -0.05}, 9);
    const auto ours = det.detect(s.image, 0.0);
    const auto ref = referenceTableScene(s.image, 0.0, cam, cfg, det.config().refine ? std::nullopt : std::optional<Eigen::Isometry3d>(ours.table ? std::optional<Eigen::Isometry3d>(ours.table->c_M_t) : std::nullopt));
    ASSERT_TRUE(ours.table.ok());
    ASSERT_TRUE(ref.table.ok());
    EXPECT_EQ(ours.table->used_roi, i > 0);
    for (std::size_t k = 0; k < 4; ++k)
      EXPECT_NEAR((ours.table->corners[k] - ref.table->corners[k]).norm(), 0.0, 1e-6) << "corner " << k;
    EXPECT_NEAR(core::rotationAngle(ours.table->c_M_t.linear(), ref.table->c_M_t.linear()), 0.0, 1e-6);
    ASSERT_TRUE(ours.ball.ok());
    ASSERT_TRUE(ref.ball.ok());
    EXPECT_NEAR((ours.ball->circle.center - ref.ball->circle.center).norm(), 0.0, 1e-6);
    EXPECT_NEAR(ours.ball->circle.radius, ref.ball->circle.radius, 1e-6);
  }
}

TEST(TableDetector, SaysSoWhenTheTableIsClippedOrMissing) {
  auto cam = mCamera();
  // Camera close above a corner: part of the table is out of the image.
  cam.c_M_w = core::lookAt({0.12, -0.05, 0.18}, {0.15, 0.05, 0.0}, {0.0, 0.0, 1.0});
  TableDetector det(cam);
  const Scene s = renderScene(cam, 0.0, 0.0, {0.0, 0.0}, 3);
  auto scene = det.detect(s.image, 0.0);
  ASSERT_FALSE(scene.table.ok());
  EXPECT_TRUE(scene.table.failure().reason == FailureReason::Clipped ||
              scene.table.failure().reason == FailureReason::TooFewCorners);
  // No table at all.
  TableDetector det2(mCamera());
  scene = det2.detect(test::texturedBackground(320, 240, 1), 0.0);
  ASSERT_FALSE(scene.table.ok());
  EXPECT_EQ(scene.table.failure().reason, FailureReason::NotFound);
  EXPECT_FALSE(scene.ball.ok());
  // Table without ball: table fine, ball not found.
  const Scene nb = renderScene(mCamera(), 0.05, 0.0, {0.0, 0.0}, 4, false);
  scene = det2.detect(nb.image, 0.0);
  EXPECT_TRUE(scene.table.ok());
  ASSERT_FALSE(scene.ball.ok());
  EXPECT_EQ(scene.ball.failure().reason, FailureReason::NotFound);
}

TEST(TableDetector, RejectsBadInput) {
  TableDetector det(mCamera());
  EXPECT_THROW(det.detect(cv::Mat(), 0.0), core::InvalidInput);
  EXPECT_THROW(det.detect(cv::Mat(240, 320, CV_8UC1), 0.0), core::InvalidInput);
  EXPECT_THROW(det.detect(cv::Mat(480, 640, CV_8UC3), 0.0), core::InvalidInput);
  TableDetectorConfig cfg;
  cfg.side_m = -1.0;
  EXPECT_THROW(TableDetector(mCamera(), cfg), core::InvalidInput);
  cfg = {};
  cfg.blur_ksize = 4;
  EXPECT_THROW(TableDetector(mCamera(), cfg), core::InvalidInput);
  cfg = {};
  cfg.red_hls.c1_lo = 300;
  EXPECT_THROW(TableDetector(mCamera(), cfg), core::InvalidInput);
}


TEST(TableEdgeTracker, WindowBlurIsOpenCvsGaussianBlur) {
  // The fast path's window blur against cv::GaussianBlur on the same submatrix, value for value:
  // windows inside the image, at each edge and corner, the whole image, one-pixel strips, and
  // an image one pixel high; random pixels (seeded) so every rounding case occurs.
  cv::RNG rng(12345);
  for (const cv::Size size : {cv::Size(320, 240), cv::Size(37, 23), cv::Size(9, 1)}) {
    cv::Mat bgr(size, CV_8UC3);
    rng.fill(bgr, cv::RNG::UNIFORM, 0, 256);
    std::vector<cv::Rect> windows{{0, 0, size.width, size.height}};
    if (size.height > 1) {
      windows.insert(windows.end(), {cv::Rect(0, 0, 5, 1), cv::Rect(size.width - 1, size.height - 1, 1, 1),
                                     cv::Rect(1, 1, size.width - 2, size.height - 2), cv::Rect(0, size.height / 2, size.width, 1)});
      for (int k = 0; k < 40; ++k) {
        const int x = rng.uniform(0, size.width), y = rng.uniform(0, size.height);
        windows.emplace_back(x, y, rng.uniform(1, size.width - x + 1), rng.uniform(1, size.height - y + 1));
      }
    }
    for (const int ksize : {3, 5}) {
      for (const cv::Rect& roi : windows) {
        cv::Mat expected, ours;
        cv::GaussianBlur(bgr(roi), expected, cv::Size(ksize, ksize), 0.0);
        gaussianBlurWindow(bgr, roi, ksize, ours);
        ASSERT_EQ(ours.size(), expected.size());
        EXPECT_EQ(cv::norm(ours, expected, cv::NORM_INF), 0.0)
            << "ksize " << ksize << ", window " << roi << " of " << size;
      }
    }
  }
}

}  // namespace
}  // namespace viewline::vision
