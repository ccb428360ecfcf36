// Synthetic views rendered with calib::renderBoard, so the true camera is known.
#include <gtest/gtest.h>

#include "viewline/calib/board.h"
#include "viewline/calib/extrinsics.h"
#include "viewline/calib/intrinsics.h"
#include "viewline/calib/render.h"
#include "viewline/core/error.h"
#include "viewline/core/frames.h"
#include "board_fixtures.h"

using namespace viewline;
using namespace viewline::calib;
using viewline::calib::test::boardPose;
using viewline::calib::test::trueCamera;

TEST(Board, ReadsBoardFilesStrictly) {
  const auto cfg = io::ConfigNode::fromString("type: chessboard\ncols: 9\nrows: 6\nspacing: 0.025\ncolor: red\n", "b.yaml");
  const BoardSpec b = readBoard(cfg);
  EXPECT_EQ(b.cols, 9);
  EXPECT_EQ(b.objectPoints().size(), 54u);
  EXPECT_NEAR(b.objectPoints()[10].x, 0.025, 1e-7);
  EXPECT_THROW(cfg.finish(), core::InvalidInput);  // "color" is unknown
  EXPECT_THROW(readBoard(io::ConfigNode::fromString("type: chessboard\ncols: 1\nrows: 6\nspacing: 0.02\n", "b.yaml")),
               core::InvalidInput);
  EXPECT_THROW(readBoard(io::ConfigNode::fromString("type: hexagons\n", "b.yaml")), core::InvalidInput);
  EXPECT_THROW(readBoard(io::ConfigNode::fromString(
                   "type: apriltag_grid\ncols: 3\nrows: 3\nspacing: 0.05\ntag_size: 0.06\n", "b.yaml")),
               core::InvalidInput);  // tags overlap
}

TEST(Board, DetectsEveryRenderedBoardTypeAndRecoversItsPose) {
  const core::Camera cam = trueCamera(false);
  core::Rng rng = core::makeRng(3);
  std::vector<BoardSpec> boards(4);
  boards[0] = BoardSpec{BoardType::Chessboard, 9, 6, 0.025, "36h11", 0, 0, {}};
  boards[1] = BoardSpec{BoardType::CirclesGrid, 6, 6, 0.03, "36h11", 0, 0, {}};
  boards[2] = BoardSpec{BoardType::AsymmetricCirclesGrid, 4, 11, 0.02, "36h11", 0, 0, {}};
  boards[3] = BoardSpec{BoardType::AprilTagGrid, 4, 3, 0.05, "36h11", 0.035, 0, {}};
  for (const auto& b : boards) {
    const Eigen::Isometry3d truth = boardPose(b, 0.5, 15, -10);
    const cv::Mat img = renderBoard(cam, truth, b, rng);
    const Detection d = detectBoard(img, b);
    ASSERT_TRUE(d.observation) << b.describe() << ": " << d.reason;
    const BoardPose p = estimatePose(PoseCamera::fromVisp(cam.intrinsics), d.observation->object_points,
                                     d.observation->image_points);
    EXPECT_LT((p.c_M_o.translation() - truth.translation()).norm(), 0.002) << b.describe();
    EXPECT_LT(core::rad2deg(core::rotationAngle(p.c_M_o.linear(), truth.linear())), 0.5) << b.describe();
    EXPECT_LT(p.rms_px, 0.5) << b.describe();
  }
}

TEST(Board, SingleAprilTagPoseInViSPTagFrame) {
  const core::Camera cam = trueCamera(false);
  core::Rng rng = core::makeRng(4);
  BoardSpec b;
  b.type = BoardType::AprilTag;
  b.tag_size = 0.08;
  b.tag_ids = {7};
  // Tag frame z points towards the camera: a frontal tag has c_M_o = half turn about x.
  Eigen::Isometry3d truth = Eigen::Isometry3d::Identity();
  truth.linear() = (Eigen::AngleAxisd(core::kPi, Eigen::Vector3d::UnitX()) *
                    Eigen::AngleAxisd(core::deg2rad(20), Eigen::Vector3d::UnitY())).toRotationMatrix();
  truth.translation() = Eigen::Vector3d(0.02, -0.01, 0.6);
  const auto poses = estimateTagPoses(PoseCamera::fromVisp(cam.intrinsics), renderBoard(cam, truth, b, rng), b);
  ASSERT_EQ(poses.count(7), 1u);
  EXPECT_LT((poses.at(7).c_M_o.translation() - truth.translation()).norm(), 0.002);
  EXPECT_LT(core::rad2deg(core::rotationAngle(poses.at(7).c_M_o.linear(), truth.linear())), 1.0);
}

TEST(Board, NotFoundGivesAReason) {
  const cv::Mat blank(480, 640, CV_8UC1, cv::Scalar(128));
  const BoardSpec b;
  const Detection d = detectBoard(blank, b);
  EXPECT_FALSE(d.observation);
  EXPECT_NE(d.reason.find("chessboard 9x6 inner corners not found"), std::string::npos) << d.reason;
}

TEST(Intrinsics, RecoversRenderedCameraWithViSPDistortion) {
  const core::Camera cam = trueCamera(true);
  core::Rng rng = core::makeRng(11);
  const BoardSpec b{BoardType::Chessboard, 9, 6, 0.025, "36h11", 0, 0, {}};
  std::vector<ViewInput> views;
  for (const auto& p : test::intrinsicsPoses(b)) {
    const Detection d = detectBoard(renderBoard(cam, p, b, rng), b);
    ASSERT_TRUE(d.observation) << d.reason;
    views.push_back({"view" + std::to_string(views.size()), *d.observation});
  }
  const IntrinsicsResult r = calibrateIntrinsics(views, cv::Size(640, 480));
  test::expectRecoversTrueCamera(r);
  ASSERT_EQ(r.std_dev.size(), 18);
  EXPECT_GT(r.std_dev(0), 0.0);
  EXPECT_LT(r.std_dev(0), 10.0);
}

TEST(Intrinsics, TooFewViewsListsRejections) {
  std::vector<ViewInput> views(2);
  views[0].name = "a.png";
  views[1].name = "b.png";
  try {
    calibrateIntrinsics(views, cv::Size(640, 480));
    FAIL();
  } catch (const core::InvalidInput& e) {
    const std::string m = e.what();
    EXPECT_NE(m.find("too few usable views: 0, need at least 3"), std::string::npos) << m;
    EXPECT_NE(m.find("rejected a.png: fewer than 4 matched points"), std::string::npos) << m;
  }
}

TEST(Ground, CameraHeightPitchAndRollFromAFloorBoard) {
  // Camera 1.2 m above the floor, looking 30 deg below the horizontal, no roll.
  const Eigen::Isometry3d c_M_g = core::lookAt({0, -2, 1.2}, {0, -2 + 1.2 / std::tan(core::deg2rad(30)), 0}, {0, 0, 1});
  const Eigen::Isometry3d c_M_board = c_M_g * groundFromBoard(BoardType::Chessboard).inverse();
  const GroundResult g = cameraToGround({c_M_board}, BoardType::Chessboard);
  EXPECT_NEAR(g.height_m, 1.2, 1e-9);
  EXPECT_NEAR(core::rad2deg(g.pitch_rad), 30.0, 1e-6);
  EXPECT_NEAR(g.roll_rad, 0.0, 1e-9);
  EXPECT_TRUE(g.down_c().isApprox(c_M_g.linear() * Eigen::Vector3d(0, 0, -1), 1e-9));
  // A board lying printed side down (camera below its plane) is refused.
  EXPECT_THROW(cameraToGround({c_M_g}, BoardType::Chessboard), core::InvalidInput);
  // A single tag's frame already has z up.
  EXPECT_NEAR(cameraToGround({c_M_g}, BoardType::AprilTag).height_m, 1.2, 1e-9);
}
