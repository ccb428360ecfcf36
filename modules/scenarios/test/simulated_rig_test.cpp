#include "viewline/scenarios/simulated_rig.h"

#include <gtest/gtest.h>

#include <cstdio>
#include <filesystem>
#include <fstream>

#include "viewline/core/error.h"

using namespace viewline;

namespace {
const std::string kRigs = "calib/rigs";  // ctest runs every test from the source root
}

TEST(SimulatedRig, EveryDefaultRigLoadsWithMatchingCameras) {
  for (const char* name : {"dart", "catching", "pan_tilt", "table", "mobile"}) {
    SCOPED_TRACE(name);
    const auto rig = scenarios::loadSimulatedRig(kRigs + "/" + name + "/");
    ASSERT_FALSE(rig.truth.cameras.empty());
    for (const auto& t : rig.truth.cameras) {
      const core::Camera& c = rig.calibratedCamera(t.name);
      // Calibrated, not copied: the focal length differs from the truth, but only a little.
      const double fx_t = t.intrinsics.get_px(), fx_c = c.intrinsics.get_px();
      EXPECT_NE(fx_t, fx_c);
      EXPECT_LT(std::abs(fx_c - fx_t) / fx_t, 0.01);
    }
    EXPECT_NE(rig.folder.back(), '/');
  }
}

TEST(SimulatedRig, UnknownCameraAndMissingFolderAreNamed) {
  const auto rig = scenarios::loadSimulatedRig(kRigs + "/table");
  try {
    rig.trueCamera("nope");
    FAIL() << "expected InvalidInput";
  } catch (const core::InvalidInput& e) {
    EXPECT_NE(std::string(e.what()).find("nope"), std::string::npos);
    EXPECT_NE(std::string(e.what()).find("head"), std::string::npos);
  }
  const auto dir = std::filesystem::temp_directory_path() / "viewline_simulated_rig_test";
  std::filesystem::create_directories(dir);
  const auto cfg_path = dir / "scenario.yaml";
  std::ofstream(cfg_path) << "rig: does/not/exist\n";
  const auto cfg = io::ConfigNode::loadFile(cfg_path.string());
  try {
    scenarios::loadSimulatedRig(cfg, "rig");
    FAIL() << "expected InvalidInput";
  } catch (const core::InvalidInput& e) {
    const std::string msg = e.what();
    EXPECT_NE(msg.find("scenario.yaml:1"), std::string::npos) << msg;
    EXPECT_NE(msg.find("does/not/exist"), std::string::npos) << msg;
  }
  std::filesystem::remove_all(dir);
}
