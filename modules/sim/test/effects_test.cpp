#include <gtest/gtest.h>

#include <cmath>

#include "viewline/core/error.h"
#include "viewline/core/frames.h"
#include "viewline/sim/effects.h"
#include "viewline/sim/rig.h"

using namespace viewline;
using namespace viewline::sim;

TEST(Effects, SensorNoiseHasTheRequestedStatisticsAndIsSeeded) {
  SensorNoise sn;
  sn.sigma = 5.0;
  core::Rng pool_rng = core::makeRng(1);
  const NoisePool pool(sn, pool_rng);
  cv::Mat img(480, 656, CV_8UC3, cv::Scalar(128, 128, 128));
  core::Rng r1 = core::makeRng(9), r2 = core::makeRng(9);
  cv::Mat a = img.clone(), b = img.clone();
  pool.apply(a, r1);
  pool.apply(b, r2);
  EXPECT_EQ(cv::norm(a, b, cv::NORM_INF), 0.0);
  cv::Scalar mean, sd;
  cv::meanStdDev(a.reshape(1), mean, sd);
  EXPECT_NEAR(mean[0], 128.0, 0.05);
  EXPECT_NEAR(sd[0], std::sqrt(25.0 + 1.0 / 12.0), 0.05);  // rounding adds 1/12
  pool.apply(a, r1);  // a second frame: different noise
  EXPECT_GT(cv::norm(a, b, cv::NORM_INF), 0.0);
  // The cv::randn fallback for images larger than the pool has the same statistics.
  SensorNoise small = sn;
  small.pool_size = 4096;
  const NoisePool p2(small, pool_rng);
  cv::Mat c = img.clone();
  p2.apply(c, r1);
  cv::meanStdDev(c.reshape(1), mean, sd);
  EXPECT_NEAR(sd[0], 5.0, 0.1);
}

TEST(Effects, IlluminationAndWhiteBalanceGains) {
  Illumination il;
  il.gain = 1.2;
  il.white_balance_bgr = Eigen::Vector3d(0.5, 1.0, 2.0);
  cv::Mat img(4, 4, CV_8UC3, cv::Scalar(100, 100, 100));
  applyIllumination(img, il, 0.0);
  EXPECT_EQ(img.at<cv::Vec3b>(1, 1), cv::Vec3b(60, 120, 240));
  il.white_balance_bgr.setOnes();
  il.gain = 1.0;
  il.flicker_amplitude = 0.5;
  il.flicker_frequency = 1.0;
  EXPECT_NEAR(illuminationGain(il, 0.25)[0], 1.5, 1e-12);
  EXPECT_NEAR(illuminationGain(il, 0.75)[0], 0.5, 1e-12);
  il.flicker_amplitude = 0.0;
  il.drift = -0.1;
  EXPECT_NEAR(illuminationGain(il, 2.0)[1], 0.8, 1e-12);
}

TEST(Effects, DiscSegmentFraction) {
  EXPECT_NEAR(discSegmentFraction(0.0), 0.5, 1e-15);
  EXPECT_NEAR(discSegmentFraction(-1.0), 1.0, 1e-15);
  EXPECT_NEAR(discSegmentFraction(1.0), 0.0, 1e-15);
  EXPECT_NEAR(discSegmentFraction(0.3) + discSegmentFraction(-0.3), 1.0, 1e-12);
}

TEST(Effects, OccluderHidesTheRequestedFraction) {
  Scene scene;
  scene.background_bgr = Eigen::Vector3d(0.2, 0.2, 0.2);
  const SceneWorld world(scene, [](double, std::vector<Primitive>& out) {
    out.push_back(makeSphere("ball", {0.3, 0.0, 1.2}, 0.05, Eigen::Vector3d(0.1, 0.5, 0.9)));
  });
  for (double fraction : {0.2, 0.5, 0.8}) {
    SimCamera c;
    c.camera.width = 656;
    c.camera.height = 480;
    c.camera.intrinsics = vpCameraParameters(600, 600, 328, 240);
    c.camera.c_M_w = core::lookAt({0.0, -3.0, 1.0}, {0.0, 0.0, 1.0}, Eigen::Vector3d::UnitZ());
    c.effects.occlusion.fraction = fraction;
    core::Rng rng = core::makeRng(5);
    CameraRig rig({c}, rng);
    int n = 0;
    rig.run(world, 0.0, 0.1, [&](Frame&& f) {
      const ObjectTruth* b = f.find("ball");
      ASSERT_NE(b, nullptr);
      EXPECT_NEAR(b->visible_fraction, 1.0 - fraction, 0.03) << "fraction " << fraction;
      ++n;
    });
    EXPECT_EQ(n, 5);
  }
}

TEST(Effects, ValidationNamesTheField) {
  ImagingEffects e;
  EXPECT_NO_THROW(validate(e));
  e.blur.samples = 0;
  try {
    validate(e);
    FAIL();
  } catch (const core::InvalidInput& ex) {
    EXPECT_NE(std::string(ex.what()).find("blur.samples"), std::string::npos);
  }
  e = {};
  e.faults.drop_probability = 1.0;
  EXPECT_THROW(validate(e), core::InvalidInput);
  e = {};
  e.illumination.gain = std::nan("");
  EXPECT_THROW(validate(e), core::InvalidInput);
  e = {};
  e.occlusion.fraction = 1.5;
  EXPECT_THROW(validate(e), core::InvalidInput);
}
