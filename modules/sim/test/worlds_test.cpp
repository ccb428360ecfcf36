#include <gtest/gtest.h>

#include <cmath>
#include <set>
#include <opencv2/imgproc.hpp>
#include <visp3/core/vpImageConvert.h>
#include <visp3/detection/vpDetectorAprilTag.h>

#include "viewline/core/error.h"
#include "viewline/core/frames.h"
#include "viewline/sim/rig.h"
#include "viewline/sim/worlds.h"

using namespace viewline;
using namespace viewline::sim;

namespace {
cv::Vec3b pixelAt(const cv::Mat& img, const Eigen::Vector2d& uv) {
  return img.at<cv::Vec3b>(static_cast<int>(std::lround(uv.y())), static_cast<int>(std::lround(uv.x())));
}
RoomParams smallRoom() {
  RoomParams r;
  r.floor_texture.resolution = 256;
  r.wall_texture.resolution = 256;
  return r;
}
}  // namespace

TEST(Worlds, TableSceneOfMompo) {
  // SPEC §3: 320x240, 90 deg HFOV, no distortion, table 0.3 m, green ball r = 0.025 m.
  TiltTableParams tp;
  tp.w_M_base.translation() = Eigen::Vector3d(0.0, 0.0, 0.8);
  TiltTableState s0;
  s0.p = Eigen::Vector2d(0.05, -0.03);
  s0.tilt = Eigen::Vector2d(0.1, -0.05);
  TiltTable table(tp, s0);
  table.command(0.0, s0.tilt);
  core::Rng rng = core::makeRng(1);
  for (bool tags : {false, true}) {
    TableAppearance look;
    look.tags = tags;
    look.tag_size = 0.08;  // 8 cm tags: ~3 px per code cell at this 320x240 view
    const TableWorld world(table, makeRoom(smallRoom(), rng), look);
    core::Camera cam;
    cam.width = 320;
    cam.height = 240;
    cam.intrinsics = core::intrinsicsFromFov(core::deg2rad(90.0), 320, 240);
    cam.c_M_w = core::lookAt({0.05, -0.35, 1.3}, {0.0, 0.0, 0.8}, Eigen::Vector3d::UnitZ());
    Renderer renderer;
    std::vector<ObjectTruth> truth;
    const cv::Mat img = renderer.render(world, cam, {0.0, 0.0, 1}, &truth);
    const ObjectTruth* tab = nullptr;
    const ObjectTruth* ball = nullptr;
    int n_tags = 0;
    for (const auto& t : truth) {
      if (t.name == "table") tab = &t;
      if (t.name == "ball") ball = &t;
      if (t.tag_id >= 0) ++n_tags;
    }
    ASSERT_NE(tab, nullptr);
    ASSERT_NE(ball, nullptr);
    EXPECT_EQ(n_tags, tags ? 4 : 0);
    ASSERT_EQ(tab->corners_px.size(), 4u);
    // Table pose truth equals the physics.
    EXPECT_LT((tab->w_M_o.matrix() - table.tablePose(s0.tilt).matrix()).norm(), 1e-12);
    // Red surface, green ball, black border where they project.
    const cv::Vec3b red = pixelAt(img, 0.5 * (tab->corners_px[0] + tab->corners_px[1]) * 0.2 +
                                           0.8 * 0.25 * (tab->corners_px[0] + tab->corners_px[1] + tab->corners_px[2] + tab->corners_px[3]));
    EXPECT_GT(red[2], 2 * red[1]);
    const cv::Vec3b green = pixelAt(img, ball->center_px);
    EXPECT_GT(green[1], 2 * green[2]);
    EXPECT_NEAR(ball->visible_fraction, 1.0, 1e-9);
    const Eigen::Vector3d border_w = table.tablePose(s0.tilt) * Eigen::Vector3d(0.16, 0.0, 0.02);
    const cv::Vec3b black = pixelAt(img, *cam.project(border_w));
    EXPECT_LT(black[0] + black[1] + black[2], 90);
    if (tags) {
      cv::Mat grey;
      cv::cvtColor(img, grey, cv::COLOR_BGR2GRAY);
      vpImage<unsigned char> I;
      vpImageConvert::convert(grey, I);
      vpDetectorAprilTag det(vpDetectorAprilTag::TAG_36h11);
      det.detect(I);
      EXPECT_EQ(det.getNbObjects(), 4u);
      std::set<std::string> ids;
      for (std::size_t i = 0; i < det.getNbObjects(); ++i) ids.insert(det.getMessage(i));
      EXPECT_EQ(ids, (std::set<std::string>{"36h11 id: 0", "36h11 id: 1", "36h11 id: 2", "36h11 id: 3"}));
    }
  }
}

TEST(Worlds, ScreenGroundDartAndBallWorldsPlaceTheirTargets) {
  core::Rng rng = core::makeRng(2);
  Renderer renderer;
  core::Camera cam;
  cam.width = 320;
  cam.height = 240;
  cam.intrinsics = core::intrinsicsFromFov(core::deg2rad(60.0), 320, 240);
  // Screen 3 m in front of the camera, facing it.
  {
    Eigen::Isometry3d w_M_screen = Eigen::Isometry3d::Identity();
    w_M_screen.linear().col(0) = Eigen::Vector3d::UnitX();
    w_M_screen.linear().col(1) = -Eigen::Vector3d::UnitZ();
    w_M_screen.linear().col(2) = Eigen::Vector3d::UnitY();
    w_M_screen.translation() = Eigen::Vector3d(0.0, 3.0, 1.5);
    ScreenPathParams pp;
    pp.shape = PathShape::Circle;
    const ScreenWorld world(ScreenPath(pp, rng), w_M_screen, Scene{});
    cam.c_M_w = core::lookAt({0.0, 0.0, 1.5}, {0.0, 3.0, 1.5}, Eigen::Vector3d::UnitZ());
    std::vector<ObjectTruth> truth;
    const cv::Mat img = renderer.render(world, cam, {1.0, 0.0, 1}, &truth);
    const ObjectTruth* target = nullptr;
    for (const auto& t : truth) {
      if (t.name == "target") target = &t;
    }
    ASSERT_NE(target, nullptr);
    EXPECT_LT((target->w_M_o.translation() - world.target_w(1.0)).norm(), 1e-12);
    EXPECT_LT(pixelAt(img, target->center_px)[0], 40);
    EXPECT_GT(pixelAt(img, target->center_px + Eigen::Vector2d(20, 0))[0], 180);
    EXPECT_GT(target->enclosing_radius_px, 3.0);
  }
  // Ground target seen from above.
  {
    GroundTargetParams gp;
    gp.start = Eigen::Vector2d(0.0, 0.0);
    gp.duration = 5.0;
    const GroundWorld world(GroundTarget(gp, rng), makeRoom(smallRoom(), rng));
    const GroundState s = world.target().state(2.0);
    cam.c_M_w = core::lookAt({s.x, s.y - 0.5, 0.6}, {s.x, s.y, 0.0}, Eigen::Vector3d::UnitZ());
    std::vector<ObjectTruth> truth;
    const cv::Mat img = renderer.render(world, cam, {2.0, 0.0, 1}, &truth);
    ASSERT_EQ(truth.back().name, "target");
    ASSERT_EQ(truth.back().corners_px.size(), 8u);
    const cv::Vec3b c = pixelAt(img, *cam.project(Eigen::Vector3d(s.x, s.y, 0.05)));
    EXPECT_GT(c[2], 2 * c[1]);
  }
  // Dart: the barrel frame is the dart frame, the dart's pixels are drawn.
  {
    const DragFlight f({{0.0, 0.0, 1.7}, {0.0, 6.0, 0.5}}, 0.0, 0.4, DragBody::dart());
    Eigen::Isometry3d w_M_board = Eigen::Isometry3d::Identity();
    w_M_board.linear().col(0) = Eigen::Vector3d::UnitX();
    w_M_board.linear().col(1) = -Eigen::Vector3d::UnitZ();
    w_M_board.linear().col(2) = Eigen::Vector3d::UnitY();
    w_M_board.translation() = Eigen::Vector3d(0.0, 2.37, 1.73);
    const DartWorld world(f, Scene{}, w_M_board);
    cam.c_M_w = core::lookAt({1.0, 0.6, 1.8}, {0.0, 0.6, 1.7}, Eigen::Vector3d::UnitZ());
    std::vector<ObjectTruth> truth;
    const cv::Mat img = renderer.render(world, cam, {0.1, 0.0, 1}, &truth);
    const cv::Mat empty = renderer.render(world, cam, {0.39, 0.0, 1});
    cv::Mat diff;
    cv::absdiff(img, empty, diff);
    EXPECT_GT(cv::countNonZero(diff.reshape(1)), 100);
    bool found = false;
    for (const auto& t : truth) {
      if (t.name == "dart") {
        found = true;
        EXPECT_LT((t.w_M_o.translation() - f.state(0.1).p).norm(), 1e-12);
      }
    }
    EXPECT_TRUE(found);
  }
  // Ball flights must not overlap.
  std::vector<DragFlight> flights{DragFlight({}, 0.0, 1.0, DragBody{}), DragFlight({}, 0.5, 1.0, DragBody{})};
  EXPECT_THROW(BallFlightWorld(flights, Scene{}), core::InvalidInput);
}

TEST(Worlds, ClutterIsSeededAndStaysInItsBox) {
  ClutterSettings c;
  c.count = 25;
  c.min_w = Eigen::Vector3d(-1.0, 0.5, 0.2);
  c.max_w = Eigen::Vector3d(1.0, 1.5, 1.2);
  c.colour_bgr = Eigen::Vector3d(0.1, 0.5, 0.95);
  Scene a, b, d;
  core::Rng r1 = core::makeRng(3), r2 = core::makeRng(3), r3 = core::makeRng(4);
  addClutter(a, c, r1);
  addClutter(b, c, r2);
  addClutter(d, c, r3);
  ASSERT_EQ(a.primitives.size(), 25u);
  for (std::size_t i = 0; i < a.primitives.size(); ++i) {
    const Primitive& p = a.primitives[i];
    EXPECT_TRUE(p.name.empty());  // distractors are not in the truth
    EXPECT_TRUE(((p.w_M_o.translation() - c.min_w).array() >= 0.0).all());
    EXPECT_TRUE(((c.max_w - p.w_M_o.translation()).array() >= 0.0).all());
    EXPECT_GE(p.size.x(), c.radius_min);
    EXPECT_LE(p.size.x(), c.radius_max);
    EXPECT_LT((p.material.albedo_bgr - c.colour_bgr).norm(), 0.3);
    EXPECT_EQ(p.w_M_o.translation(), b.primitives[i].w_M_o.translation());
  }
  EXPECT_NE(a.primitives[0].w_M_o.translation(), d.primitives[0].w_M_o.translation());
  c.radius_min = -1.0;
  EXPECT_THROW(addClutter(a, c, r1), core::InvalidInput);
}
