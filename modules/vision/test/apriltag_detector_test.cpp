#include <gtest/gtest.h>

#include <cmath>

#include "synthetic.h"
#include "viewline/core/error.h"
#include "viewline/core/frames.h"
#include "viewline/vision/apriltag_detector.h"

namespace viewline::vision {
namespace {

core::Camera camera() {
  core::Camera cam;
  cam.width = 640;
  cam.height = 480;
  cam.intrinsics = core::intrinsicsFromFov(core::deg2rad(60.0), 640, 480);
  cam.c_M_w = core::lookAt({0.05, -0.30, 0.45}, {0.0, 0.0, 0.0}, {0.0, 0.0, 1.0});
  return cam;
}

TEST(AprilTagDetector, PoseOfARenderedTag) {
  const auto cam = camera();
  cv::Mat img(480, 640, CV_8UC3, cv::Scalar(200, 200, 200));
  Eigen::Isometry3d w_M_tag = Eigen::Isometry3d::Identity();
  w_M_tag.translation() = Eigen::Vector3d(0.02, 0.01, 0.0);
  w_M_tag.linear() = core::rotation(Eigen::Vector3d::UnitZ(), 0.3);
  test::renderTag36h11(img, cam, w_M_tag, 5, 0.08);
  AprilTagDetectorConfig cfg;
  cfg.tag_size_m = 0.08;
  AprilTagDetector det(cfg);
  const auto r = det.detect(img, cam, 1.5);
  ASSERT_TRUE(r.ok()) << r.failure().message;
  ASSERT_EQ(r->tags.size(), 1U);
  EXPECT_EQ(r->tags[0].id, 5);
  EXPECT_DOUBLE_EQ(r->stamp, 1.5);
  const Eigen::Isometry3d truth = cam.c_M_w * w_M_tag;
  EXPECT_LT((r->tags[0].c_M_o.translation() - truth.translation()).norm(), 0.002);
  EXPECT_LT(core::rad2deg(core::rotationAngle(r->tags[0].c_M_o.linear(), truth.linear())), 1.0);
  // Corners project where the 3D corners are.
  for (std::size_t k = 0; k < 4; ++k) {
    const auto uv = *cam.project(w_M_tag * r->tags[0].corners_3d[k]);
    EXPECT_LT((uv - r->tags[0].corners[k]).norm(), 0.25) << "corner " << k;
  }
}

TEST(AprilTagTableDetector, TablePoseFromFourTags) {
  const auto cam = camera();
  Eigen::Isometry3d w_M_t = Eigen::Isometry3d::Identity();
  w_M_t.linear() = core::rotation(Eigen::Vector3d::UnitX(), 0.12) * core::rotation(Eigen::Vector3d::UnitY(), -0.08);
  cv::Mat img(480, 640, CV_8UC3, cv::Scalar(200, 200, 200));
  std::vector<TagOnTable> layout;
  for (int k = 0; k < 4; ++k) {
    TagOnTable t;
    t.id = k;
    t.size_m = 0.05;
    t.t_M_tag.translation() = Eigen::Vector3d((k & 1) ? 0.1 : -0.1, (k & 2) ? 0.1 : -0.1, 0.0);
    layout.push_back(t);
    test::renderTag36h11(img, cam, w_M_t * t.t_M_tag, t.id, t.size_m);
  }
  AprilTagTableDetector det(cam, layout);
  const auto r = det.detect(img, 2.0);
  ASSERT_TRUE(r.ok()) << r.failure().message;
  ASSERT_TRUE(det.lastTags().ok());
  EXPECT_EQ(det.lastTags()->tags.size(), 4U);
  const Eigen::Isometry3d truth = cam.c_M_w * w_M_t;
  EXPECT_LT((r->c_M_t.translation() - truth.translation()).norm(), 0.001);
  EXPECT_LT(core::rad2deg(core::rotationAngle(r->c_M_t.linear(), truth.linear())), 0.3);
  EXPECT_LT(r->reprojection_rms_px, 0.5);
  // No tag: reason, not a pose.
  const auto none = det.detect(cv::Mat(480, 640, CV_8UC3, cv::Scalar(200, 200, 200)), 0.0);
  ASSERT_FALSE(none.ok());
  EXPECT_EQ(none.failure().reason, FailureReason::NotFound);
}

TEST(AprilTagDetector, RejectsBadInput) {
  AprilTagDetectorConfig cfg;
  cfg.tag_size_m = 0.0;
  EXPECT_THROW(AprilTagDetector{cfg}, core::InvalidInput);
  AprilTagDetector det;
  EXPECT_THROW(det.detect(cv::Mat(), camera(), 0.0), core::InvalidInput);
  EXPECT_THROW(AprilTagTableDetector(camera(), {}), core::InvalidInput);
}

}  // namespace
}  // namespace viewline::vision
