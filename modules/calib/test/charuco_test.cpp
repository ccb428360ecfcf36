// ChArUco boards: YAML, rendered views through both renderers, partial views, intrinsics.
#include <gtest/gtest.h>

#include <iostream>
#include <opencv2/calib3d.hpp>

#include "viewline/calib/board.h"
#include "viewline/calib/extrinsics.h"
#include "viewline/calib/intrinsics.h"
#include "viewline/calib/render.h"
#include "viewline/calib/synthetic.h"
#include "viewline/core/error.h"
#include "viewline/core/frames.h"
#include "board_fixtures.h"

using namespace viewline;
using namespace viewline::calib;
using viewline::calib::test::boardPose;
using viewline::calib::test::trueCamera;

namespace {

// 10 x 7 squares of 25 mm: the same 9 x 6 inner corners as the chessboard of board_test.cpp.
BoardSpec charuco() {
  BoardSpec b;
  b.type = BoardType::ChArUco;
  b.cols = 10;
  b.rows = 7;
  b.spacing = 0.025;
  b.marker_size = 0.019;
  b.dictionary = "DICT_5X5_100";
  return b;
}

std::string errorOf(const std::string& yaml) {
  try {
    const auto cfg = io::ConfigNode::fromString(yaml, "b.yaml");
    readBoard(cfg);
    cfg.finish();
  } catch (const core::InvalidInput& e) {
    return e.what();
  }
  return "";
}

}  // namespace

TEST(ChArUco, ReadsBoardFilesStrictlyWithClearErrors) {
  const std::string ok = "type: charuco\ncols: 10\nrows: 7\nspacing: 0.025\nmarker_size: 0.019\ndictionary: DICT_5X5_100\n";
  const auto cfg = io::ConfigNode::fromString(ok, "b.yaml");
  const BoardSpec b = readBoard(cfg);
  cfg.finish();
  EXPECT_EQ(b.type, BoardType::ChArUco);
  EXPECT_EQ(b.cols, 10);
  EXPECT_EQ(b.rows, 7);
  EXPECT_DOUBLE_EQ(b.marker_size, 0.019);
  EXPECT_EQ(b.dictionary, "DICT_5X5_100");
  EXPECT_EQ(b.describe(), "charuco 10x7 squares of 0.025 m, markers DICT_5X5_100 of 0.019 m");
  // Object points: the 9 x 6 inner corners, row-major (OpenCV's corner ids), origin at the first.
  ASSERT_EQ(b.objectPoints().size(), 54u);
  EXPECT_NEAR(b.objectPoints()[10].x, 0.025, 1e-7);
  EXPECT_NEAR(b.objectPoints()[10].y, 0.025, 1e-7);
  // ... the same corners OpenCV's board has, shifted by one square.
  const auto cb = charucoBoard(b);
  ASSERT_EQ(cb->chessboardCorners.size(), 54u);
  for (std::size_t i = 0; i < 54; ++i) {
    EXPECT_NEAR(cb->chessboardCorners[i].x - 0.025f, b.objectPoints()[i].x, 1e-6);
    EXPECT_NEAR(cb->chessboardCorners[i].y - 0.025f, b.objectPoints()[i].y, 1e-6);
  }

  // The shipped board file (tests run in the source tree) is this board.
  const BoardSpec shipped = loadBoard("calib/boards/charuco_10x7_25mm.yaml");
  EXPECT_EQ(shipped.describe(), b.describe());

  auto expectError = [](const std::string& yaml, const std::string& needle) {
    const std::string e = errorOf(yaml);
    EXPECT_NE(e.find(needle), std::string::npos) << "yaml:\n" << yaml << "error: '" << e << "'";
  };
  const std::string base = "type: charuco\ncols: 10\nrows: 7\nspacing: 0.025\n";
  // Marker not smaller than the square.
  expectError(base + "marker_size: 0.025\ndictionary: DICT_5X5_100\n", "marker_size must be a positive length");
  expectError(base + "marker_size: -0.01\ndictionary: DICT_5X5_100\n", "marker_size");
  // Missing keys are named.
  expectError(base + "dictionary: DICT_5X5_100\n", "marker_size");
  expectError(base + "marker_size: 0.019\n", "dictionary");
  // Unknown dictionary: the key and a valid name are in the message.
  expectError(base + "marker_size: 0.019\ndictionary: DICT_9X9_1\n", "dictionary");
  expectError(base + "marker_size: 0.019\ndictionary: DICT_9X9_1\n", "DICT_5X5_100");
  // Not enough markers in the dictionary: 12 x 12 squares need 72 markers.
  expectError("type: charuco\ncols: 12\nrows: 12\nspacing: 0.02\nmarker_size: 0.015\ndictionary: DICT_4X4_50\n",
              "dictionary 'DICT_4X4_50' has 50 markers, the board needs 72");
  // Too few squares for a 2-D set of inner corners.
  expectError("type: charuco\ncols: 2\nrows: 7\nspacing: 0.025\nmarker_size: 0.019\ndictionary: DICT_5X5_100\n",
              "at least 3");
  // Keys of other boards are unknown here.
  expectError(ok + "tag_size: 0.02\n", "tag_size");
  EXPECT_THROW(charucoBoard(BoardSpec{}), core::InvalidInput);  // a chessboard
}

TEST(ChArUco, DetectsRenderedBoardAndRecoversItsPose) {
  const core::Camera cam = trueCamera(false);
  core::Rng rng = core::makeRng(5);
  const BoardSpec b = charuco();
  const Eigen::Isometry3d truth = boardPose(b, 0.5, 15, -10);
  const Detection d = detectBoard(renderBoard(cam, truth, b, rng), b);
  ASSERT_TRUE(d.observation) << d.reason;
  EXPECT_EQ(d.observation->image_points.size(), 54u);
  ASSERT_EQ(d.observation->corner_ids.size(), 54u);
  const BoardPose p =
      estimatePose(PoseCamera::fromVisp(cam.intrinsics), d.observation->object_points, d.observation->image_points);
  EXPECT_LT((p.c_M_o.translation() - truth.translation()).norm(), 0.002);
  EXPECT_LT(core::rad2deg(core::rotationAngle(p.c_M_o.linear(), truth.linear())), 0.5);
  EXPECT_LT(p.rms_px, 0.5);

  // Too few corners: a reason naming the board, like the other board types.
  const Detection none = detectBoard(cv::Mat(480, 640, CV_8UC1, cv::Scalar(128)), b);
  EXPECT_FALSE(none.observation);
  EXPECT_NE(none.reason.find("charuco 10x7 (DICT_5X5_100): found 0 corners from 0 markers, need at least 6"),
            std::string::npos)
      << none.reason;
}

TEST(ChArUco, SimulatorRenderedViewsAreDetected) {
  // The synthetic-rig path (sampleIntrinsicsPoses + the simulator's renderer).
  const core::Camera cam = trueCamera(true);
  core::Rng rng = core::makeRng(6);
  const BoardSpec b = charuco();
  for (const auto& c_M_o : sampleIntrinsicsPoses(cam, b, 3, rng)) {
    const Detection d = detectBoard(renderBoardImage(cam, c_M_o, b, SyntheticImaging{}, rng), b);
    ASSERT_TRUE(d.observation) << d.reason;
    EXPECT_GE(d.observation->image_points.size(), 50u);
    // Each corner where the true camera projects its object point, without a common offset (OpenCV
    // 4.6's own corners are half a pixel off; a chessboard here: worst ~0.16 px, mean ~0.01 px).
    double worst = 0.0;
    Eigen::Vector2d mean = Eigen::Vector2d::Zero();
    const auto& obs = *d.observation;
    for (std::size_t i = 0; i < obs.image_points.size(); ++i) {
      const auto& o = obs.object_points[i];
      const auto uv = cam.project(c_M_o * Eigen::Vector3d(o.x, o.y, o.z));
      ASSERT_TRUE(uv);
      const Eigen::Vector2d e = Eigen::Vector2d(obs.image_points[i].x, obs.image_points[i].y) - *uv;
      worst = std::max(worst, e.norm());
      mean += e / static_cast<double>(obs.image_points.size());
    }
    EXPECT_LT(worst, 0.35);
    EXPECT_LT(mean.norm(), 0.05);
  }
}

TEST(ChArUco, HalfHiddenBoardStillGivesItsVisibleCorners) {
  const core::Camera cam = trueCamera(false);
  core::Rng rng = core::makeRng(7);
  const BoardSpec b = charuco();
  const Eigen::Isometry3d truth = boardPose(b, 0.45, 10, 15);
  cv::Mat img = renderBoard(cam, truth, b, rng);
  // Hide the left half of the board (the board's x = 4 squares, a vertical line near the image centre).
  const auto mid = cam.project(truth * Eigen::Vector3d(4 * b.spacing, 2.5 * b.spacing, 0));
  ASSERT_TRUE(mid);
  const int cut = static_cast<int>(mid->x());
  img(cv::Rect(0, 0, cut, img.rows)).setTo(cv::Scalar(128));

  // A chessboard detector needs the whole grid of inner corners: it fails.
  std::vector<cv::Point2f> cb_corners;
  EXPECT_FALSE(cv::findChessboardCorners(img, cv::Size(b.cols - 1, b.rows - 1), cb_corners,
                                         cv::CALIB_CB_ADAPTIVE_THRESH | cv::CALIB_CB_NORMALIZE_IMAGE));
  BoardSpec chess;
  chess.type = BoardType::Chessboard;
  chess.cols = b.cols - 1;
  chess.rows = b.rows - 1;
  chess.spacing = b.spacing;
  EXPECT_FALSE(detectBoard(img, chess).observation);

  // The charuco detection keeps the corners of the visible half, with their own object points.
  const Detection d = detectBoard(img, b);
  ASSERT_TRUE(d.observation) << d.reason;
  const auto& o = *d.observation;
  std::cout << "[charuco half] " << o.image_points.size() << " corners\n";
  EXPECT_GE(o.image_points.size(), 18u);
  EXPECT_LT(o.image_points.size(), 54u);
  for (std::size_t i = 0; i < o.image_points.size(); ++i) {
    EXPECT_GT(o.image_points[i].x, cut) << "corner " << o.corner_ids[i];
    EXPECT_GE(o.object_points[i].x, 4 * b.spacing - 1e-6) << "corner " << o.corner_ids[i];
  }
  const BoardPose p = estimatePose(PoseCamera::fromVisp(cam.intrinsics), o.object_points, o.image_points);
  EXPECT_LT((p.c_M_o.translation() - truth.translation()).norm(), 0.003);
  EXPECT_LT(core::rad2deg(core::rotationAngle(p.c_M_o.linear(), truth.linear())), 0.5);
  EXPECT_LT(p.rms_px, 0.5);
}

TEST(ChArUco, IntrinsicsRecoverRenderedCameraWithViSPDistortion) {
  // board_test.cpp's chessboard test with a charuco board of the same inner corners: same camera,
  // poses and bounds, plus one half-hidden view (partial views calibrate too).
  const core::Camera cam = trueCamera(true);
  core::Rng rng = core::makeRng(11);
  const BoardSpec b = charuco();
  std::vector<ViewInput> views;
  auto ps = test::intrinsicsPoses(b);
  for (std::size_t k = 0; k < ps.size(); ++k) {
    const Detection d = detectBoard(renderBoard(cam, ps[k], b, rng), b);
    ASSERT_TRUE(d.observation) << d.reason;
    EXPECT_GE(d.observation->image_points.size(), 50u) << "view " << k;
    views.push_back({"view" + std::to_string(k), *d.observation});
  }
  {
    cv::Mat img = renderBoard(cam, boardPose(b, 0.42, -20, -20, 0.04, 0.0), b, rng);
    img(cv::Rect(0, 0, 320, 480)).setTo(cv::Scalar(128));
    const Detection d = detectBoard(img, b);
    ASSERT_TRUE(d.observation) << d.reason;
    EXPECT_LT(d.observation->image_points.size(), 54u);
    views.push_back({"half", *d.observation});
  }
  const IntrinsicsResult r = calibrateIntrinsics(views, cv::Size(640, 480));
  EXPECT_TRUE(r.rejected.empty());
  test::expectRecoversTrueCamera(r);
  std::cout << "[charuco intrinsics] views " << r.view_names.size() << ", OpenCV RMS " << r.rms_px
            << " px, ViSP (kud) RMS " << r.visp_with_rms_px << " px; errors px " << r.visp_with.get_px() - 600
            << " py " << r.visp_with.get_py() - 605 << " u0 " << r.visp_with.get_u0() - 318 << " v0 "
            << r.visp_with.get_v0() - 243 << " kud " << r.visp_with.get_kud() + 0.08 << "\n";
}
