#include <gtest/gtest.h>

#include <cmath>
#include <opencv2/imgproc.hpp>

#include "synthetic.h"
#include "viewline/core/error.h"
#include "viewline/core/frames.h"
#include "viewline/vision/table_detector.h"
#include "viewline/vision/color.h"
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


// The ball window as first written, OpenCV throughout (whole-window conversion and mask, its
// Gaussian and opening, contours of the whole mask, every ray sample read): the reference the
// fast version must reproduce bit for bit.
std::optional<Circle> referenceTrackBall(const cv::Mat& bgr, const Circle& previous, const TableDetectorConfig& det,
                                         const TableEdgeTrackerConfig& config) {
  const double half = config.ball_window_factor * previous.radius + config.ball_margin_px;
  const cv::Rect roi = squareRoi(previous.center.x(), previous.center.y(), half, bgr.size());
  if (roi.width < 8 || roi.height < 8) return std::nullopt;
  cv::Mat blurred, hls, mask;
  cv::GaussianBlur(bgr(roi), blurred, cv::Size(det.blur_ksize, det.blur_ksize), 0.0);
  cv::cvtColor(blurred, hls, cv::COLOR_BGR2HLS);
  thresholdColor(hls, det.green_hls, mask);
  const cv::Mat kernel =
      cv::getStructuringElement(cv::MORPH_ELLIPSE, cv::Size(det.ball_open_kernel_px, det.ball_open_kernel_px));
  cv::morphologyEx(mask, mask, cv::MORPH_OPEN, kernel);
  std::vector<std::vector<cv::Point>> contours;
  cv::findContours(mask, contours, cv::RETR_EXTERNAL, cv::CHAIN_APPROX_NONE, roi.tl());
  double best = 0.0;
  const std::vector<cv::Point>* ball = nullptr;
  for (const auto& c : contours) {
    const double a = cv::contourArea(c);
    if (a > best) {
      best = a;
      ball = &c;
    }
  }
  if (ball == nullptr || best < det.min_ball_area_px) return std::nullopt;
  if (touchesBorder(cv::boundingRect(*ball), roi)) return std::nullopt;
  cv::Point2f centre;
  float r = 0.0F;
  cv::minEnclosingCircle(*ball, centre, r);
  Circle c{Eigen::Vector2d(static_cast<double>(centre.x), static_cast<double>(centre.y)), static_cast<double>(r)};
  std::vector<cv::Point2f> edge;
  constexpr double kStep = 0.25;
  const double reach = 3.0;
  const int count = static_cast<int>(2.0 * reach / kStep) + 1;
  std::vector<double> prof(static_cast<std::size_t>(count));
  for (int ray = 0; ray < 32; ++ray) {
    const double ang = 2.0 * 3.14159265358979323846 * ray / 32.0;
    const Eigen::Vector2d dir(std::cos(ang), std::sin(ang));
    bool ok = true;
    for (int j = 0; j < count && ok; ++j) {
      const Eigen::Vector2d p = c.center + (c.radius - reach + j * kStep) * dir;
      const double u = p.x(), v = p.y();
      if (!(u >= 0.0 && v >= 0.0 && u < bgr.cols - 1.0 && v < bgr.rows - 1.0)) {
        ok = false;
        break;
      }
      const int x = static_cast<int>(u), y = static_cast<int>(v);
      const double fx = u - x, fy = v - y;
      const cv::Vec3b* r0 = bgr.ptr<cv::Vec3b>(y) + x;
      const cv::Vec3b* r1 = bgr.ptr<cv::Vec3b>(y + 1) + x;
      double f[3];
      for (int q = 0; q < 3; ++q) f[q] = (1 - fy) * ((1 - fx) * r0[0][q] + fx * r0[1][q]) + fy * ((1 - fx) * r1[0][q] + fx * r1[1][q]);
      prof[static_cast<std::size_t>(j)] = f[1] - std::max(f[0], f[2]);
    }
    if (!ok) continue;
    const double in = 0.5 * (prof[0] + prof[1]);
    const double out = 0.5 * (prof[static_cast<std::size_t>(count - 1)] + prof[static_cast<std::size_t>(count - 2)]);
    if (in - out < 0.5 * config.min_contrast) continue;
    auto crossing = [&](double level, int from, int to, double& s_out) {
      for (int j = std::max(from, 0); j + 1 < count && j < to; ++j) {
        const double f0 = prof[static_cast<std::size_t>(j)], f1 = prof[static_cast<std::size_t>(j + 1)];
        if (f0 >= level && f1 < level) {
          s_out = kStep * (j + (f0 - level) / (f0 - f1));
          return true;
        }
      }
      return false;
    };
    double s_edge = 0.0;
    if (!crossing(0.5 * (in + out), 0, count, s_edge)) continue;
    const int ie = static_cast<int>(std::lround(s_edge / kStep));
    constexpr int kGap = 5;
    if (ie - kGap >= 0 && ie + kGap < count) {
      const double in2 = prof[static_cast<std::size_t>(ie - kGap)], out2 = prof[static_cast<std::size_t>(ie + kGap)];
      double s2 = 0.0;
      if (in2 - out2 >= 0.5 * config.min_contrast && crossing(0.5 * (in2 + out2), ie - kGap, ie + kGap, s2)) s_edge = s2;
    }
    const Eigen::Vector2d p = c.center + (c.radius - reach + s_edge) * dir;
    edge.emplace_back(static_cast<float>(p.x()), static_cast<float>(p.y()));
  }
  if (edge.size() >= 12) {
    const cv::RotatedRect e = cv::fitEllipse(edge);
    c.center = Eigen::Vector2d(static_cast<double>(e.center.x), static_cast<double>(e.center.y));
    c.radius = 0.5 * static_cast<double>(std::max(e.size.width, e.size.height));
  }
  return c;
}

TEST(TableEdgeTracker, TrackBallIsTheOpenCvPipelineBitForBit) {
  // Rendered tables and balls with sensor noise, the previous circle off by up to 3 px and 20 %
  // in radius, balls near the image edges too: the window search returns the reference's circle
  // (or its failure) exactly.
  const auto cam = mCamera();
  const TableDetectorConfig det;
  const TableEdgeTrackerConfig config;
  TableEdgeTracker tracker(det, config);
  core::Rng rng = core::makeRng(17);
  cv::RNG noise(99);
  int found = 0;
  const int n = 60;
  for (int i = 0; i < n; ++i) {
    const double tx = core::deg2rad(core::uniform(rng, -10.0, 10.0));
    const double ty = core::deg2rad(core::uniform(rng, -10.0, 10.0));
    const Eigen::Vector2d xy(core::uniform(rng, -0.12, 0.12), core::uniform(rng, -0.12, 0.12));
    Scene s = renderScene(cam, tx, ty, xy, 300 + static_cast<unsigned>(i));
    cv::Mat n16(s.image.size(), CV_16SC3);
    noise.fill(n16, cv::RNG::NORMAL, 0.0, 2.0 + (i % 3) * 3.0);
    cv::Mat noisy;
    cv::add(s.image, n16, noisy, cv::noArray(), CV_8UC3);
    const auto uv = cam.project(cam.c_M_w.inverse() * s.c_M_t * s.ball_t);
    ASSERT_TRUE(uv.has_value());
    const Circle previous{*uv + Eigen::Vector2d(core::uniform(rng, -3.0, 3.0), core::uniform(rng, -3.0, 3.0)),
                          9.0 * core::uniform(rng, 0.8, 1.2)};
    const auto expected = referenceTrackBall(noisy, previous, det, config);
    const auto ours = tracker.trackBall(noisy, previous);
    ASSERT_EQ(ours.has_value(), expected.has_value()) << "scene " << i;
    if (!expected) continue;
    ++found;
    EXPECT_EQ(ours->center.x(), expected->center.x()) << "scene " << i;
    EXPECT_EQ(ours->center.y(), expected->center.y()) << "scene " << i;
    EXPECT_EQ(ours->radius, expected->radius) << "scene " << i;
  }
  EXPECT_GE(found, n / 2);  // the comparison covered found balls, not only failures
}

}  // namespace
}  // namespace viewline::vision
