#include "viewline/scenarios/table_ball/observer.h"

#include <gtest/gtest.h>

#include <cmath>

#include "viewline/core/error.h"
#include "viewline/core/frames.h"
#include "viewline/core/random.h"
#include "viewline/scenarios/table_ball.h"
#include "viewline/sim/physics.h"
#include "viewline/sim/renderer.h"
#include "viewline/sim/worlds.h"

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

// The table-plane depth uses the cone's axis only: for the exact image of a ball resting on a
// tilted table it returns the ball, and an edge found 0.05 px inside the limb all round (what
// shading and blur do to the detected outline) leaves it within 0.01 mm, while the known-radius depth
// d = r / sin α moves by millimetres along the viewing ray.
TEST(TableBallObserver, TablePlaneDepthIgnoresTheCircleSizeBias) {
  const core::Camera cam = headCamera();
  const double r = 0.025;
  Eigen::Isometry3d w_M_t = Eigen::Isometry3d::Identity();
  w_M_t.linear() = core::rotation(Eigen::Vector3d::UnitX(), 0.08) * core::rotation(Eigen::Vector3d::UnitY(), -0.05);
  const Eigen::Isometry3d c_M_t = cam.c_M_w * w_M_t;
  const Eigen::Vector2d ball(0.06, -0.04);  // on the table, m
  const Eigen::Vector3d pc = c_M_t * Eigen::Vector3d(ball.x(), ball.y(), r);
  // The sphere's outline: the two tangent rays in the plane of the optical axis and the centre
  // ray project to the ends of the outline's radial diameter.
  const Eigen::Vector3d u = pc.normalized();
  const Eigen::Vector3d n = Eigen::Vector3d::UnitZ().cross(u).normalized();
  const double alpha = std::asin(r / pc.norm());
  auto project = [&](double angle) {
    const Eigen::Vector3d ray = Eigen::AngleAxisd(angle, n) * u;
    return cam.normalizedToPixel(ray.head<2>() / ray.z());
  };
  const Eigen::Vector2d a = project(alpha), b = project(-alpha);
  vision::Circle circle{0.5 * (a + b), 0.5 * (a - b).norm()};
  const auto exact = scenarios::ballOnTablePlane(cam, circle, c_M_t, r);
  ASSERT_TRUE(exact.has_value());
  EXPECT_LT((exact->head<2>() - ball).norm(), 1e-9);
  EXPECT_NEAR(exact->z(), r, 1e-12);
  const double known_exact = (vision::ballOnTableKnownRadius(cam, circle, c_M_t, r).p_t.head<2>() - ball).norm();
  EXPECT_LT(known_exact, 1e-6);
  circle.radius -= 0.05;  // the edge a little inside the limb
  const auto plane = scenarios::ballOnTablePlane(cam, circle, c_M_t, r);
  ASSERT_TRUE(plane.has_value());
  EXPECT_LT((plane->head<2>() - ball).norm(), 1e-5);  // 2 µm: the pixel-symmetric shrink is not angle-symmetric
  EXPECT_GT((vision::ballOnTableKnownRadius(cam, circle, c_M_t, r).p_t.head<2>() - ball).norm(), 0.001);
}

// The AprilTag table pose. A tagged table rendered at a known tilt must come back at
// that pose. The layout has to be in vpDetectorAprilTag's tag frame (z out of the tag); with the
// simulator's tag frame (z into the table) every tag's corners are mirrored and the pose came out
// flipped (tilt error 179.8°).
TEST(TableBallObserver, AprilTagTablePoseMatchesTheRenderedTable) {
  sim::TiltTableParams params;
  params.w_M_base.translation() = Eigen::Vector3d(0.0, 0.0, 0.9);
  params.delay = 0.0;
  sim::TiltTable table(params, sim::TiltTableState{0.0, {0.0, 0.0}, {0.03, -0.02}, {0.0, 0.0}});
  const Eigen::Vector2d tilt(core::deg2rad(4.0), core::deg2rad(-3.0));
  table.command(0.0, tilt);
  table.advanceTo(0.5);  // well past the rate-limited ramp
  const sim::TiltTableState truth = table.stateAt(0.5);
  ASSERT_NEAR((truth.tilt - tilt).norm(), 0.0, 1e-9);
  sim::TableAppearance look;
  look.tags = true;
  look.tag_size = 0.05;
  core::Rng rng = core::makeRng(5);
  sim::RoomParams room;
  room.floor_texture.resolution = 256;
  room.wall_texture.resolution = 256;
  const sim::TableWorld world(table, sim::makeRoom(room, rng), look);
  // The scenario's head camera (config/table_ball.yaml).
  core::Camera cam;
  cam.width = 320;
  cam.height = 240;
  cam.intrinsics = core::intrinsicsFromFov(core::deg2rad(90.0), 320, 240);
  cam.c_M_w = core::lookAt({0.0, -0.30, 1.32}, {0.0, 0.0, 0.9}, {0.0, 0.0, 1.0});
  sim::RenderSettings rs;
  rs.supersampling = 3;
  sim::Renderer renderer(rs);
  const cv::Mat image = renderer.render(world, cam, sim::ExposureSpec{0.5, 0.0, 1});
  const Eigen::Isometry3d w_M_t = table.tablePose(truth.tilt);
  const Eigen::Isometry3d c_M_t_true = cam.c_M_w * w_M_t;

  const std::vector<vision::TagOnTable> layout = scenarios::tableTagLayout(world);
  ASSERT_EQ(layout.size(), 4u);
  // The tag frames sit on the table plane with z along the table normal.
  for (const auto& tag : layout) EXPECT_NEAR(tag.t_M_tag.linear()(2, 2), 1.0, 1e-12);

  scenarios::TableBallObserverConfig ocfg;
  ocfg.table_pose = scenarios::TablePoseSource::AprilTag;
  ocfg.tag_layout = layout;
  ocfg.tag_detector.tag_size_m = look.tag_size;
  scenarios::TableBallObserver observer(cam, ocfg);
  // A prior that is only roughly right (the arm's nominal pose, level table).
  const scenarios::ObserverFrame& of = observer.process(image, 0.5, cam.c_M_w.linear(), cam.c_M_w * table.tablePose({0.0, 0.0}));
  ASSERT_TRUE(of.table_found) << of.failure;
  const double rot_err = core::rad2deg(core::rotationAngle(of.c_M_t.linear(), c_M_t_true.linear()));
  const double pos_err = (of.c_M_t.translation() - c_M_t_true.translation()).norm();
  EXPECT_LT(rot_err, 0.75) << "table rotation error, deg";
  EXPECT_LT(pos_err, 0.005) << "table origin error, m";
  EXPECT_LT(core::rad2deg((of.measured_tilt - truth.tilt).cwiseAbs().maxCoeff()), 0.75);
  // The ball measured on that table frame lies where it is.
  ASSERT_TRUE(of.ball_found) << of.failure;
  EXPECT_LT((of.measured - truth.p).norm(), 0.005);
}

// The table pose filter (observer.h, step 2b): a constant camera-frame offset between the PnP
// pose and the kinematic one (calibration) under per-frame PnP noise is learnt, and the filtered
// pose is much closer to the true pose than the noisy PnP poses are.
TEST(TableBallObserver, TablePoseFilterLearnsTheOffsetAndAveragesThePnpNoise) {
  const double tau = 1.0, dt = 0.02;
  scenarios::TablePoseOffsetFilter filter(tau);
  EXPECT_FALSE(filter.valid());
  // The true offset: 0.06° about a skew axis and 1 mm (a calibration error of the head camera).
  Eigen::Isometry3d offset = Eigen::Isometry3d::Identity();
  offset.linear() = Eigen::AngleAxisd(core::deg2rad(0.06), Eigen::Vector3d(1.0, -2.0, 0.5).normalized()).toRotationMatrix();
  offset.translation() = Eigen::Vector3d(0.001, -0.0005, 0.0008);
  core::Rng rng = core::makeRng(11);
  double raw_sq = 0.0, filtered_sq = 0.0;
  int n = 0;
  for (int k = 0; k < 500; ++k) {
    const double t = k * dt;
    // The kinematic pose moves (the table tilts, the head sways).
    Eigen::Isometry3d kin = Eigen::Isometry3d::Identity();
    kin.linear() = (core::rotation(Eigen::Vector3d::UnitX(), -2.2 + 0.1 * std::sin(t)) *
                    core::rotation(Eigen::Vector3d::UnitY(), 0.05 * std::cos(1.3 * t)));
    kin.translation() = Eigen::Vector3d(0.002 * std::sin(2.0 * t), 0.05, 0.45);
    const Eigen::Isometry3d truth = offset * kin;
    // A PnP pose: 0.25° of rotation noise about the table's centre and 0.5 mm of translation noise.
    const Eigen::Vector3d w(core::gaussian(rng, 1.0), core::gaussian(rng, 1.0), core::gaussian(rng, 1.0));
    Eigen::Isometry3d noise = Eigen::Isometry3d::Identity();
    noise.linear() = Eigen::AngleAxisd(core::deg2rad(0.25) * w.norm() / std::sqrt(3.0), w.normalized()).toRotationMatrix();
    noise.translation() = 0.0005 * Eigen::Vector3d(core::gaussian(rng, 1.0), core::gaussian(rng, 1.0), core::gaussian(rng, 1.0));
    const Eigen::Isometry3d measured = truth * noise;  // noise in the table frame
    filter.update(t, measured, kin);
    ASSERT_TRUE(filter.valid());
    if (k == 0) {  // the first residual is taken as it is
      EXPECT_LT((filter.apply(kin).matrix() - measured.matrix()).norm(), 1e-12);
    }
    if (t < 3.0 * tau) continue;
    // Error of the table centre's position and of the rotation against the truth.
    const Eigen::Isometry3d f = filter.apply(kin);
    raw_sq += (measured.translation() - truth.translation()).squaredNorm();
    filtered_sq += (f.translation() - truth.translation()).squaredNorm();
    EXPECT_LT(core::rotationAngle(f.linear(), truth.linear()), core::deg2rad(0.06));
    ++n;
  }
  // Averaging over τ = 50 frames: about 1/sqrt(100) of the noise (0.1), at most 0.2 here.
  EXPECT_LT(std::sqrt(filtered_sq / n), 0.2 * std::sqrt(raw_sq / n));
  EXPECT_LT((filter.translation() - offset.translation()).norm(), 5e-4);  // of 1.4 mm
}

// A dropped frame does not stall the average: the gain follows the time since the last pose.
TEST(TableBallObserver, TablePoseFilterGainFollowsTheElapsedTime) {
  const Eigen::Isometry3d kin = Eigen::Isometry3d::Identity();
  Eigen::Isometry3d a = Eigen::Isometry3d::Identity(), b = Eigen::Isometry3d::Identity();
  b.translation() = Eigen::Vector3d(0.001, 0.0, 0.0);
  scenarios::TablePoseOffsetFilter one(0.5), two(0.5);
  one.update(0.0, a, kin);
  two.update(0.0, a, kin);
  one.update(0.02, b, kin);
  two.update(0.04, b, kin);
  EXPECT_NEAR(one.translation().x(), 0.001 * -std::expm1(-0.02 / 0.5), 1e-15);
  EXPECT_NEAR(two.translation().x(), 0.001 * -std::expm1(-0.04 / 0.5), 1e-15);
  EXPECT_THROW(scenarios::TablePoseOffsetFilter(0.0), core::InvalidInput);
}

// A wrong PnP pose (here 5° off) is skipped instead of pulling the offset; a run of them means the
// kinematics changed, and the offset restarts from the newest residual.
TEST(TableBallObserver, TablePoseFilterSkipsAWrongPoseAndRestartsAfterARun) {
  const Eigen::Isometry3d kin = Eigen::Isometry3d::Identity();
  Eigen::Isometry3d wrong = Eigen::Isometry3d::Identity();
  wrong.linear() = core::rotation(Eigen::Vector3d::UnitX(), core::deg2rad(5.0));
  scenarios::TablePoseOffsetFilter filter(1.0);
  ASSERT_TRUE(filter.update(0.0, kin, kin));
  double t = 0.0;
  for (int k = 1; k < scenarios::TablePoseOffsetFilter::kRestartAfter; ++k) {
    EXPECT_FALSE(filter.update(t += 0.02, wrong, kin));
    EXPECT_EQ(filter.rotation().norm(), 0.0);
  }
  EXPECT_TRUE(filter.update(t += 0.02, wrong, kin));  // the run: restart
  EXPECT_NEAR(filter.rotation().x(), core::deg2rad(5.0), 1e-12);
  EXPECT_EQ(filter.gated(), scenarios::TablePoseOffsetFilter::kRestartAfter);
}
