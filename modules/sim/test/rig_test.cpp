#include <gtest/gtest.h>

#include <cmath>

#include "viewline/core/error.h"
#include "viewline/core/frames.h"
#include "viewline/sim/rig.h"
#include "viewline/sim/worlds.h"

using namespace viewline;
using namespace viewline::sim;

namespace {

SimCamera smallCamera(const std::string& name, const Eigen::Vector3d& eye, double rate, double phase) {
  SimCamera c;
  c.camera.name = name;
  c.camera.width = 160;
  c.camera.height = 120;
  c.camera.intrinsics = core::intrinsicsFromFov(core::deg2rad(60.0), 160, 120);
  c.camera.c_M_w = core::lookAt(eye, {0.0, 0.0, 1.0}, Eigen::Vector3d::UnitZ());
  c.clock.rate = rate;
  c.clock.phase = phase;
  return c;
}

BallFlightWorld smallWorld() {
  core::Rng rng = core::makeRng(3);
  RoomParams room;
  room.floor_texture.resolution = 128;
  room.wall_texture.resolution = 128;
  return BallFlightWorld({DragFlight({{0.0, 0.0, 1.0}, {0.3, 0.0, 2.0}}, 0.0, 0.5, DragBody::ball5cm())},
                         makeRoom(room, rng));
}

}  // namespace

TEST(CameraRig, TwoCamerasAt50HzGiveTimeOrderedFrames) {
  core::Rng rng = core::makeRng(1);
  CameraRig rig({smallCamera("a", {-2, -3, 1.5}, 50.0, 0.0), smallCamera("b", {2, -3, 1.5}, 50.0, 0.01)}, rng);
  const auto sched = rig.schedule(0.0, 10.0);
  ASSERT_EQ(sched.size(), 1000u);
  for (std::size_t i = 1; i < sched.size(); ++i) {
    EXPECT_LE(sched[i - 1].capture_time, sched[i].capture_time);
    EXPECT_NE(sched[i - 1].camera_index, sched[i].camera_index);  // interleaved by the 10 ms phase
  }
  const BallFlightWorld world = smallWorld();
  std::vector<Frame> frames;
  const std::size_t n = rig.run(world, 0.0, 0.5, [&](Frame&& f) { frames.push_back(std::move(f)); });
  ASSERT_EQ(n, 50u);
  for (std::size_t i = 0; i < frames.size(); ++i) {
    const Frame& f = frames[i];
    EXPECT_EQ(f.image.type(), CV_8UC3);
    EXPECT_EQ(f.image.cols, 160);
    EXPECT_EQ(f.image.rows, 120);
    EXPECT_EQ(f.stamp, f.capture_time);  // no jitter configured
    EXPECT_NEAR(f.capture_time, 0.02 * static_cast<double>(f.sequence) + (f.camera_index == 1 ? 0.01 : 0.0), 1e-12);
    const ObjectTruth* ball = f.find("ball");
    ASSERT_NE(ball, nullptr);
    EXPECT_LT((ball->w_M_o.translation() - world.flights()[0].state(f.capture_time).p).norm(), 1e-12);
    if (i > 0) {
      EXPECT_LT(frames[i - 1].capture_time, f.capture_time);
    }
  }
}

TEST(CameraRig, DeterministicPerSeedAndRewoundByReset) {
  const BallFlightWorld world = smallWorld();
  auto make = [&](std::uint64_t seed) {
    core::Rng rng = core::makeRng(seed);
    SimCamera c = smallCamera("a", {-2, -3, 1.5}, 30.0, 0.0);
    c.effects.noise.sigma = 4.0;
    c.effects.faults.drop_probability = 0.2;
    c.effects.faults.stamp_jitter = 1e-3;
    c.effects.occlusion.fraction = 0.3;
    return CameraRig({c}, rng);
  };
  auto collect = [&](CameraRig& rig) {
    std::vector<Frame> out;
    rig.run(world, 0.0, 0.4, [&](Frame&& f) { out.push_back(std::move(f)); });
    return out;
  };
  CameraRig a = make(11), b = make(11), c = make(12);
  const auto fa = collect(a), fb = collect(b), fa2 = collect(a), fc = collect(c);
  ASSERT_EQ(fa.size(), fb.size());
  ASSERT_EQ(fa.size(), fa2.size());
  for (std::size_t i = 0; i < fa.size(); ++i) {
    EXPECT_EQ(fa[i].stamp, fb[i].stamp);
    EXPECT_EQ(cv::norm(fa[i].image, fb[i].image, cv::NORM_INF), 0.0);
    EXPECT_EQ(cv::norm(fa[i].image, fa2[i].image, cv::NORM_INF), 0.0);
  }
  ASSERT_FALSE(fc.empty());
  EXPECT_GT(cv::norm(fa[0].image, fc[0].image, cv::NORM_INF), 0.0);
}

TEST(CameraRig, DroppedFramesAndJitterStatistics) {
  core::Rng rng = core::makeRng(2);
  SimCamera c = smallCamera("a", {-2, -3, 1.5}, 100.0, 0.0);
  c.effects.faults.drop_probability = 0.1;
  c.effects.faults.stamp_jitter = 2e-3;
  c.effects.faults.trigger_jitter = 1e-3;
  c.clock.drift = 1e-3;
  CameraRig rig({c}, rng);
  const auto sched = rig.schedule(0.0, 200.0);  // ~20000 captures
  const double n = static_cast<double>(sched.size());
  ASSERT_NEAR(n, 200.0 * 100.0 / 1.001, 2.0);
  double drops = 0.0, s_sum = 0.0, s_sq = 0.0, t_sum = 0.0, t_sq = 0.0;
  for (const auto& cap : sched) {
    drops += cap.dropped ? 1.0 : 0.0;
    const double e_stamp = cap.stamp - cap.capture_time;
    const double e_trig = cap.capture_time - static_cast<double>(cap.sequence) * 1.001 / 100.0;
    s_sum += e_stamp;
    s_sq += e_stamp * e_stamp;
    t_sum += e_trig;
    t_sq += e_trig * e_trig;
  }
  const double p = drops / n;
  EXPECT_NEAR(p, 0.1, 4.0 * std::sqrt(0.1 * 0.9 / n));
  EXPECT_NEAR(s_sum / n, 0.0, 4.0 * 2e-3 / std::sqrt(n));
  EXPECT_NEAR(std::sqrt(s_sq / n), 2e-3, 2e-3 * 0.03);
  EXPECT_NEAR(std::sqrt(t_sq / n), 1e-3, 1e-3 * 0.03);
  EXPECT_NEAR(t_sum / n, 0.0, 4.0 * 1e-3 / std::sqrt(n));
  // Delivered frames skip the dropped sequence numbers.
  const BallFlightWorld world = smallWorld();
  std::vector<std::uint64_t> seq;
  rig.run(world, 0.0, 0.5, [&](Frame&& f) { seq.push_back(f.sequence); });
  std::size_t expected_drops = 0;
  for (const auto& cap : rig.schedule(0.0, 0.5)) expected_drops += cap.dropped ? 1 : 0;
  EXPECT_EQ(seq.size() + expected_drops, 50u);
}

TEST(CameraRig, BadClocksNameTheField) {
  core::Rng rng = core::makeRng(0);
  SimCamera c = smallCamera("left", {-2, -3, 1.5}, 0.0, 0.0);
  try {
    CameraRig rig({c}, rng);
    FAIL();
  } catch (const core::InvalidInput& e) {
    EXPECT_NE(std::string(e.what()).find("clock.rate"), std::string::npos);
    EXPECT_NE(std::string(e.what()).find("left"), std::string::npos);
  }
  c.clock.rate = 30.0;
  c.effects.noise.sigma = -1.0;
  EXPECT_THROW(CameraRig({c}, rng), core::InvalidInput);
  EXPECT_THROW(CameraRig({}, rng), core::InvalidInput);
}

TEST(CameraRig, MovingCameraFollowsItsPose) {
  core::Rng rng = core::makeRng(4);
  SimCamera c = smallCamera("ptu", {0, -3, 1.0}, 10.0, 0.0);
  c.pose_at = [](double t) { return core::lookAt({0.0, -3.0, 1.0}, {t, 0.0, 1.0}, Eigen::Vector3d::UnitZ()); };
  CameraRig rig({c}, rng);
  const BallFlightWorld world = smallWorld();
  std::vector<Frame> frames;
  rig.run(world, 0.0, 0.3, [&](Frame&& f) { frames.push_back(std::move(f)); });
  ASSERT_EQ(frames.size(), 3u);
  EXPECT_LT((frames[2].camera.c_M_w.matrix() - c.pose_at(0.2).matrix()).norm(), 1e-12);
  EXPECT_GT(cv::norm(frames[0].image, frames[2].image, cv::NORM_L1), 0.0);
}
