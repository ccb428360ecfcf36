#include <gtest/gtest.h>

#include "viewline/calib/hand_eye.h"
#include "viewline/core/error.h"
#include "viewline/core/frames.h"
#include "viewline/core/random.h"

using namespace viewline;
using namespace viewline::calib;

namespace {
Eigen::Isometry3d pose(const Eigen::Vector3d& t, const Eigen::Vector3d& rot_deg) {
  Eigen::Isometry3d T = Eigen::Isometry3d::Identity();
  const double a = rot_deg.norm();
  if (a > 0) T.linear() = Eigen::AngleAxisd(core::deg2rad(a), rot_deg / a).toRotationMatrix();
  T.translation() = t;
  return T;
}
Eigen::Isometry3d noisy(const Eigen::Isometry3d& T, core::Rng& rng, double sigma_t, double sigma_r) {
  return pose({core::gaussian(rng, sigma_t), core::gaussian(rng, sigma_t), core::gaussian(rng, sigma_t)},
              Eigen::Vector3d(core::gaussian(rng, sigma_r), core::gaussian(rng, sigma_r), core::gaussian(rng, sigma_r))) * T;
}
}  // namespace

TEST(HandEye, EyeInHandAndEyeToHandRecoverTheTruth) {
  core::Rng rng = core::makeRng(5);
  const Eigen::Isometry3d e_M_c = pose({0.05, -0.02, 0.1}, {10, -5, 90});
  const Eigen::Isometry3d r_M_o = pose({0.6, 0.1, 0.0}, {180, 0, 0});
  const Eigen::Isometry3d r_M_c_fixed = pose({1.0, 0.5, 0.8}, {120, 30, 0});
  const Eigen::Isometry3d e_M_o = pose({0.0, 0.0, 0.08}, {0, 0, 45});
  std::vector<Eigen::Isometry3d> r_M_e, c_M_o_in, c_M_o_to;
  for (int i = 0; i < 10; ++i) {
    const Eigen::Isometry3d T = pose({0.5 + 0.05 * i, 0.1 * std::sin(i), 0.4 + 0.02 * i},
                                     {160 + 8.0 * std::cos(i), 15.0 * std::sin(2.0 * i), 20.0 * i});
    r_M_e.push_back(T);
    c_M_o_in.push_back(noisy(e_M_c.inverse() * T.inverse() * r_M_o, rng, 0.0005, 0.05));
    c_M_o_to.push_back(noisy(r_M_c_fixed.inverse() * T * e_M_o, rng, 0.0005, 0.05));
  }
  const HandEyeResult a = calibrateHandEye(r_M_e, c_M_o_in, HandEyeSetup::EyeInHand);
  EXPECT_LT((a.X.translation() - e_M_c.translation()).norm(), 0.005);
  EXPECT_LT(core::rad2deg(core::rotationAngle(a.X.linear(), e_M_c.linear())), 0.3);
  EXPECT_LT(a.rms_translation_m, 0.005);
  EXPECT_GT(a.rms_translation_m, 0.0);
  const HandEyeResult b = calibrateHandEye(r_M_e, c_M_o_to, HandEyeSetup::EyeToHand);
  EXPECT_LT((b.X.translation() - r_M_c_fixed.translation()).norm(), 0.005);
  EXPECT_LT(core::rad2deg(core::rotationAngle(b.X.linear(), r_M_c_fixed.linear())), 0.3);
  EXPECT_NE(b.report().find("eye-to-hand: r_M_c"), std::string::npos);
}

TEST(HandEye, RejectsBadInputWithReasons) {
  std::vector<Eigen::Isometry3d> a(4, Eigen::Isometry3d::Identity()), b(3, Eigen::Isometry3d::Identity());
  auto msg = [](auto&& f) {
    try {
      f();
    } catch (const core::InvalidInput& e) {
      return std::string(e.what());
    }
    return std::string("no error");
  };
  EXPECT_NE(msg([&] { calibrateHandEye(a, b, HandEyeSetup::EyeInHand); }).find("4 robot poses but 3 camera poses"),
            std::string::npos);
  b.resize(4, Eigen::Isometry3d::Identity());
  EXPECT_NE(msg([&] { calibrateHandEye(a, b, HandEyeSetup::EyeInHand); }).find("two non-parallel axes"),
            std::string::npos);
  a[2].matrix()(0, 3) = std::nan("");
  EXPECT_NE(msg([&] { calibrateHandEye(a, b, HandEyeSetup::EyeInHand); }).find("robot pose 2: contains NaN"),
            std::string::npos);
}
