// A rig that is only calibrated (rig.yaml + e_M_c.yaml, no truth.yaml): it loads, runs pan-tilt on
// real frames (a recording, an images folder), table ball on a recording, and both refuse to render
// (source: sim) with a message that names the folder and says truth.yaml is needed only to render.
#include <gtest/gtest.h>
#include <unistd.h>

#include <cmath>
#include <filesystem>
#include <string>

#include "viewline/core/error.h"
#include "viewline/io/config_edit.h"
#include "viewline/scenarios/pan_tilt/loop.h"
#include "viewline/scenarios/table_ball.h"
#include "viewline/scenarios/simulated_rig.h"

namespace fs = std::filesystem;
using namespace viewline;

namespace {

fs::path scratch(const std::string& name) {
  const fs::path p = fs::path(testing::TempDir()) / ("viewline_calrig_" + std::to_string(::getpid()) + "_" + name);
  fs::remove_all(p);
  return p;
}

/// calib/rigs/pan_tilt copied without truth.yaml: what a real pan-tilt rig's calibration holds.
fs::path calibratedOnlyPanTiltRig() {
  const fs::path dir = scratch("rig");
  fs::create_directories(dir);
  for (const auto& e : fs::directory_iterator("calib/rigs/pan_tilt"))
    if (e.path().filename() != "truth.yaml") fs::copy(e.path(), dir / e.path().filename(), fs::copy_options::recursive);
  return dir;
}

/// A short pan-tilt circle run (ours only): the loading and the loop are under test, not the figures.
scenarios::PanTiltScenarioConfig shortRun(std::vector<std::string> edits) {
  edits.insert(edits.end(), {"run.duration=0.7", "run.metrics_start=0.2", "run.baseline=false"});
  return scenarios::loadPanTiltScenarioConfig(io::loadConfigWithValues("config/pan_tilt_circle.yaml", edits));
}

}  // namespace

TEST(CalibratedRig, LoadsWithoutTruthAndRefusesToGiveTheTrueCamera) {
  const fs::path dir = calibratedOnlyPanTiltRig();
  const auto rig = scenarios::loadSimulatedRig(dir.string());
  EXPECT_FALSE(rig.hasTruth());
  EXPECT_TRUE(rig.truth.cameras.empty());
  EXPECT_GT(rig.calibratedCamera("ptu_camera").intrinsics.get_px(), 0.0);
  try {
    rig.trueCamera("ptu_camera");
    FAIL() << "expected InvalidInput";
  } catch (const core::InvalidInput& e) {
    const std::string msg = e.what();
    EXPECT_NE(msg.find(rig.folder), std::string::npos) << msg;
    EXPECT_NE(msg.find("truth.yaml"), std::string::npos) << msg;
    EXPECT_NE(msg.find("needed only to render"), std::string::npos) << msg;
  }
  // The shipped rig still has its truth.
  EXPECT_TRUE(scenarios::loadSimulatedRig("calib/rigs/pan_tilt").hasTruth());
  fs::remove_all(dir);
}

TEST(CalibratedRig, PanTiltRefusesToRenderWithoutTruth) {
  const fs::path dir = calibratedOnlyPanTiltRig();
  try {
    shortRun({"rig=" + dir.string()});
    FAIL() << "expected InvalidInput";
  } catch (const core::InvalidInput& e) {
    const std::string msg = e.what();
    EXPECT_NE(msg.find("pan_tilt_circle.yaml"), std::string::npos) << msg;  // file:line of the rig key
    EXPECT_NE(msg.find(dir.string()), std::string::npos) << msg;
    EXPECT_NE(msg.find("source: sim"), std::string::npos) << msg;
    EXPECT_NE(msg.find("needed only to render"), std::string::npos) << msg;
  }
  fs::remove_all(dir);
}

TEST(CalibratedRig, PanTiltRunsFromARecordingAndFromImages) {
  const fs::path rig = calibratedOnlyPanTiltRig();
  // A recording made on the simulated rig (truth.yaml renders), then run on the calibrated-only one.
  const fs::path rec = scratch("rec");
  scenarios::PanTiltRunIo record;
  record.record_dir = rec.string();
  const auto live = scenarios::runPanTiltComparison(shortRun({}), 3, record);
  ASSERT_GT(live.ours.detections, 15u);

  const auto on_rec =
      shortRun({"rig=" + rig.string(), "source.kind=recording", "source.path=" + (rec / "predictive").string()});
  EXPECT_EQ(on_rec.rig_folder, fs::path(rig.string()).string());
  // The controllers' camera is the calibration, and nothing renders: the "true" one is the same.
  EXPECT_EQ(on_rec.true_camera->intrinsics.get_px(), on_rec.calibrated_camera->intrinsics.get_px());
  EXPECT_TRUE(on_rec.true_e_M_c->isApprox(*on_rec.calibrated_e_M_c));
  const auto r = scenarios::runPanTiltComparison(on_rec, 3);
  EXPECT_TRUE(r.ours.scored);  // the recording carries its truth
  EXPECT_EQ(r.ours.frames, live.ours.frames);
  EXPECT_GT(r.ours.detections, 15u);
  EXPECT_TRUE(std::isfinite(r.ours.image_error_rms_px));

  // The same frames as an images folder (no truth: run, not scored).
  const auto on_images = shortRun({"rig=" + rig.string(), "source.kind=images",
                                   "source.pattern=" + (rec / "predictive" / "cam0" / "%06d.png").string(),
                                   "source.first=0", "source.rate_hz=30"});
  const auto f = scenarios::runPanTiltComparison(on_images, 3);
  EXPECT_FALSE(f.ours.scored);
  EXPECT_EQ(f.ours.frames, live.ours.frames);
  EXPECT_GT(f.ours.detections, 15u);
  fs::remove_all(rec);
  fs::remove_all(rig);
}

TEST(CalibratedRig, TableBallRunsFromARecordingAndRefusesToRenderWithoutTruth) {
  const fs::path rig = scratch("table_rig");
  fs::create_directories(rig);
  for (const auto& e : fs::directory_iterator("calib/rigs/table"))
    if (e.path().filename() != "truth.yaml") fs::copy(e.path(), rig / e.path().filename(), fs::copy_options::recursive);
  try {
    scenarios::tableBallConfigFromYaml(io::loadConfigWithValues("config/table_ball.yaml", {"rig=" + rig.string()}));
    FAIL() << "expected InvalidInput";
  } catch (const core::InvalidInput& e) {
    const std::string msg = e.what();
    EXPECT_NE(msg.find(rig.string()), std::string::npos) << msg;
    EXPECT_NE(msg.find("needed only to render"), std::string::npos) << msg;
  }
  // A short recorded run on the simulated table rig, replayed on the calibrated-only one.
  auto cfg = scenarios::tableBallConfigFromYaml(io::loadConfigWithValues("config/table_ball.yaml", {}));
  cfg.duration = 0.6;
  const fs::path rec = scratch("table_rec");
  scenarios::TableBallHooks record;
  record.record_dir = rec.string();
  const auto live = scenarios::runTableBall(cfg, 5, record);
  auto on_rec = scenarios::tableBallConfigFromYaml(io::loadConfigWithValues(
      "config/table_ball.yaml", {"rig=" + rig.string(), "source.kind=recording", "source.path=" + rec.string()}));
  on_rec.duration = cfg.duration;
  ASSERT_TRUE(on_rec.rig);
  EXPECT_EQ(on_rec.rig->truth.intrinsics.get_px(), on_rec.rig->calibrated.intrinsics.get_px());
  const auto r = scenarios::runTableBall(on_rec, 5);
  EXPECT_EQ(r.frames, live.frames);
  EXPECT_GT(r.frames, 15);
  fs::remove_all(rec);
  fs::remove_all(rig);
}
