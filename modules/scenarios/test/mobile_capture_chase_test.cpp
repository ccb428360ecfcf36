// The chase's shared perception and commands (mobile_capture/chase.h): from the rendered frames of
// the held head camera (the object coming towards the robot, as in the footage test) the
// controller tracks the object and plans from the given pose; with the object out of sight long
// enough it sweeps around the track's last bearing, and that bearing turns with the base's own
// rotation (the simulated loop's turn rate) or stays put (the footage session's held robot, 0).
#include <gtest/gtest.h>

#include <cmath>
#include <string>
#include <vector>

#include "viewline/io/config_edit.h"
#include "viewline/scenarios/mobile_capture.h"
#include "viewline/scenarios/mobile_capture/chase.h"
#include "viewline/scenarios/mobile_capture/world.h"

using namespace viewline;
using namespace viewline::scenarios::mobile_capture;

TEST(MobileCaptureChase, TracksTheRenderedObjectThenSweepsAboutABearingThatTurnsWithTheBase) {
  // The footage test's scene: the object 3.5 m ahead of the held camera, coming towards it.
  const auto cfg = scenarios::loadMobileCaptureConfig(io::loadConfigWithValues(
      "config/mobile_capture.yaml", {"world.object_start=[-0.1, 3.0]", "world.object_heading_deg=210", "world.max_time=1"}));
  Streams rng(3);
  const sim::GroundTarget target(targetParams(cfg, sim::GroundProfile::Capture, targetDuration(cfg)), rng.object);
  const RobotSim robot(cfg);
  const robots::BasePose pose = robot.base.pose();
  RenderedHeadCamera head(cfg, target, rng,
                          [&] { return trueCamera_c_M_w(robot.head, robot.q, pose.x, pose.y, pose.theta); });
  core::Camera camera = estimatorCamera(cfg);
  camera.c_M_w = estimatorCamera_c_M_w(cfg, trueCamera_c_M_w(robot.head, robot.q, pose.x, pose.y, pose.theta));

  runtime::FaultPlan faults;
  ChaseController turning(cfg);
  EXPECT_EQ(turning.mode(), control::SearchMode::Sweeping);
  EXPECT_LT(turning.lastSeen(), 0.0);
  int frames = 0;
  double t_last = 0.0;
  while (head.nextReadyTime()) {
    const auto frame = head.grab();
    ASSERT_TRUE(frame.has_value());
    const ChaseObservation o = turning.frame(faults, *frame, camera, pose);
    ASSERT_TRUE(o.pixel && o.floor && o.update) << "frame " << frames;  // in view, on the floor, given to the track
    EXPECT_EQ(turning.lastSeen(), frame->stamp);
    const auto s = target.state(frame->stamp);
    EXPECT_LT((o.floor->z - Eigen::Vector2d(s.x, s.y)).norm(), 0.2) << "frame " << frames;
    t_last = frame->stamp;
    ++frames;
  }
  ASSERT_GE(frames, 5);
  ASSERT_TRUE(turning.track().valid());
  EXPECT_FALSE(turning.prediction().empty());
  EXPECT_EQ(turning.track().positionAt(t_last), turning.track().state().x().head<2>());
  const auto s = target.state(t_last);
  EXPECT_LT((turning.track().positionAt(t_last) - Eigen::Vector2d(s.x, s.y)).norm(), 0.1);
  ChaseController held = turning;  // the same track and plan: one turns with the base, one is held

  // Seen just now: tracking, the base towards the capture point, the head at the prediction.
  const double T = cfg.controlPeriod();
  const ChaseCommand tracking = turning.command(t_last + T, pose, robot.head, robot.q, 0.0);
  EXPECT_EQ(tracking.mode, control::SearchMode::Tracking);
  const control::BaseCommand go = control::goToPoint(pose, turning.plan().point, cfg.goParams());
  EXPECT_EQ(tracking.base.v, go.v);
  EXPECT_EQ(tracking.base.omega, go.omega);
  held.command(t_last + T, pose, robot.head, robot.q, 0.0);

  // Out of sight past lost_after + search_after: the sweep about the track's last bearing, the
  // base turning towards it. Over k periods at turn rate w the bearing is b0 - k w T.
  const Eigen::Vector2d rel = toRobot(pose, turning.track().state().x().head<2>());
  const double b0 = std::atan2(rel.y(), rel.x());
  // The base's turn (2 b, clamped at 2 base_turn_rate) is unclamped here, so it shows the bearing.
  ASSERT_LT(std::abs(b0) + 0.1, cfg.search.base_turn_rate);
  const control::SearchPattern search(cfg.search);
  const double w = 0.5;  // rad/s, the turning base's rate
  const double t0 = t_last + cfg.search.lost_after + cfg.search.search_after + T;
  for (int k = 0; k < 5; ++k) {
    const double t = t0 + k * T;
    const ChaseCommand c = turning.command(t, pose, robot.head, robot.q, w);
    const ChaseCommand h = held.command(t, pose, robot.head, robot.q, 0.0);
    ASSERT_EQ(c.mode, control::SearchMode::Sweeping) << k;
    ASSERT_EQ(h.mode, control::SearchMode::Sweeping) << k;
    const double b = std::remainder(b0 - k * w * T, 2.0 * M_PI);
    EXPECT_NEAR(c.base.omega, search.baseWhileSearching(b, true).omega, 1e-12) << k;
    EXPECT_NEAR(c.head.pan, search.sweep(robot.head, t, t0, b).pan, 1e-12) << k;
    EXPECT_EQ(h.base.omega, search.baseWhileSearching(b0, true).omega) << k;  // held: the bearing stays
    EXPECT_EQ(h.head.pan, search.sweep(robot.head, t, t0, b0).pan) << k;
  }
}
