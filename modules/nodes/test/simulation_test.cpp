// The world and camera simulation the nodes share with in-process references.
#include <gtest/gtest.h>

#include "viewline/io/config_edit.h"
#include "viewline/nodes/simulation.h"

using namespace viewline;

namespace {
scenarios::BallCatchingConfig loadCatching(const std::vector<std::string>& sets = {}) {
  return scenarios::loadBallCatchingConfig(io::loadConfigWithValues("config/ball_catching.yaml", sets));
}
}  // namespace

TEST(Simulation, RigHashChangesWithTheRigOnly) {
  const auto a = loadCatching();
  EXPECT_EQ(nodes::rigHash(a), nodes::rigHash(loadCatching()));
  EXPECT_EQ(nodes::rigHash(a), nodes::rigHash(loadCatching({"threads=1"})));  // not a rig key
  EXPECT_NE(nodes::rigHash(a), nodes::rigHash(loadCatching({"camera_count=3"})));
}

TEST(Simulation, GeneratorIsDeterministicAndSeesTheFlight) {
  const auto cfg = loadCatching();
  const nodes::WorldTruth truth(cfg, 7, 0.2);
  EXPECT_GT(truth.crossingTime(), 0.4);
  nodes::DetectionGenerator a(cfg, 0, 7, 0.5), b(cfg, 0, 7, 0.5);
  int frames = 0, seen = 0;
  double last = -1.0;
  for (int j = 0; j <= 750; ++j) {
    const double t = j * 0.002;
    std::optional<Eigen::Vector3d> p;
    if (truth.inFlight(t)) p = truth.state(t).p;
    const auto fa = a.onTick(t, p), fb = b.onTick(t, p);
    ASSERT_EQ(fa.has_value(), fb.has_value());
    if (!fa) continue;
    ++frames;
    EXPECT_GT(fa->stamp, last);
    last = fa->stamp;
    ASSERT_EQ(fa->pixel.has_value(), fb->pixel.has_value());
    if (fa->pixel) {
      ++seen;
      EXPECT_EQ(*fa->pixel, *fb->pixel);
    }
  }
  EXPECT_NEAR(frames, 1.5 * cfg.throwRate(0), 2);  // 1.5 s at the camera's rate
  EXPECT_GT(seen, 10);
}
