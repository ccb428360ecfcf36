// Tuning on one's own data: two short pan-tilt recordings of the same setting (their truth removed,
// as a real rig's would have none), tuned and checked with no seed and no simulator: the frames go
// through the detector and are back-projected at the unit readings the recording holds (ptu.csv).
// Those measurements are the live run's, bit for bit; the noise auto-tuned on the first recording
// gives NIS inside its two-sided 99 % band on the second, and a far-off noise does not. (About
// 10 s of CPU: two short rendered recordings, their frames through the detector a few times.)
#include <gtest/gtest.h>
#include <unistd.h>
#include <yaml-cpp/yaml.h>

#include <filesystem>
#include <string>
#include <vector>

#include "pan_tilt_recording.h"
#include "viewline/core/error.h"
#include "viewline/io/config_edit.h"
#include "viewline/runtime/telemetry.h"
#include "viewline/scenarios/pan_tilt/loop.h"
#include "viewline/tuning/scenario.h"
#include "viewline/tuning/session.h"

namespace fs = std::filesystem;
using namespace viewline;

namespace {

const std::string kConfig = "config/pan_tilt_circle.yaml";  // ctest runs from the source root
/// The setting of both recordings: the constant-acceleration filter (whose noise the pan-tilt
/// adapter tunes) without the shared config's corner machinery (the mixture's: jumps, legs,
/// region), a start q well off, 3 s (90 frames) each.
const std::vector<std::string> kSetting = {
    "filter.model=ca",           "filter.q=0.1",           "filter.jump_window=0",
    "filter.jump_rate=0",        "filter.jump_decision=test", "filter.jump_evidence=kink",
    "filter.constant_speed=false", "filter.turn_prior_weight=0", "filter.region.size=[0,0]",
    "run.baseline=false",        "run.duration=3",         "run.metrics_start=1"};

fs::path scratch(const std::string& name) {
  const fs::path p = fs::path(testing::TempDir()) / ("viewline_rectune_" + std::to_string(::getpid()) + "_" + name);
  fs::remove_all(p);
  return p;
}

/// Records one seeded run of the setting as pan_tilt_tracking --record does (frames, unit readings,
/// config as run), then drops its truth; `live` receives the run's telemetry.
fs::path recordRun(const std::string& name, std::uint64_t seed, runtime::MemorySink& live) {
  const fs::path dir = scratch(name);
  const io::ConfigNode root = io::loadConfigWithValues(kConfig, kSetting);
  const auto cfg = scenarios::loadPanTiltScenarioConfig(root);
  YAML::Emitter yaml;
  yaml << root.yaml();
  scenarios::PanTiltRunIo io;
  io.record_dir = dir.string();
  io.config_text = std::string(yaml.c_str()) + "\n";
  io.telemetry = &live;
  scenarios::runPanTiltComparison(cfg, seed, io);
  EXPECT_TRUE(fs::remove(dir / "predictive" / "truth.csv"));
  EXPECT_TRUE(fs::exists(dir / "predictive" / "ptu.csv"));
  return dir;
}

nlohmann::json checkOn(const std::string& config, const std::vector<std::string>& set, const fs::path& recording) {
  tuning::CheckOptions co;
  co.scenario = "pan_tilt";
  co.config = config;
  co.set = set;
  co.recording = recording.string();
  co.quiet = true;
  return tuning::runCheckSession(tuning::makeBuiltinAdapters(), co);
}

}  // namespace

TEST(TuneOnRecording, AutotuneOnOneRecordingIsConsistentOnAnother) {
  runtime::MemorySink live_a, live_b;
  const fs::path a = recordRun("a", 11, live_a), b = recordRun("b", 12, live_b);

  // Without the unit, the simulator or the seed, B's frames give the live run's measurements bit for
  // bit: the same detections, back-projected at the recorded joint readings, with the recorded noise.
  const auto cfg = scenarios::loadPanTiltScenarioConfig(io::loadConfigWithValues(kConfig, kSetting));
  const tuning::detail::PanTiltRecordedMeasurements replayed = tuning::detail::panTiltRecordedMeasurements(cfg, b.string());
  std::vector<const runtime::MeasurementRecord*> measured;
  for (const auto& z : live_b.measurements)
    if (z.channel == "predictive") measured.push_back(&z);
  std::size_t k = 0;
  for (const auto& f : replayed.frames) {
    if (!f.detected) continue;
    ASSERT_LT(k, measured.size());
    EXPECT_EQ(f.t, measured[k]->t);
    EXPECT_EQ(f.z.x(), measured[k]->z(0));
    EXPECT_EQ(f.z.y(), measured[k]->z(1));
    ++k;
  }
  EXPECT_EQ(k, measured.size());
  EXPECT_GT(k, 60u);

  const fs::path out = scratch("autotune");
  tuning::AutotuneSessionOptions ao;
  ao.scenario = "pan_tilt";
  ao.config = kConfig;
  ao.set = kSetting;
  ao.recording = a.string();
  ao.grid_points = 5;
  ao.workers = 2;
  ao.out_dir = out.string();
  ao.quiet = true;
  const nlohmann::json j = tuning::runAutotuneSession(tuning::makeBuiltinAdapters(), ao);
  EXPECT_EQ(j["recording"], a.string());
  EXPECT_FALSE(j.contains("autotune_verify_seed"));  // no simulated fresh run: the check is on B
  const std::string tuned = j["autotuned_config"].get<std::string>();
  ASSERT_TRUE(fs::exists(tuned));
  const double q = j["parameters"]["process"]["tuned"].get<double>();
  const double r_scale = j["parameters"]["measurement"]["tuned"].get<double>();
  EXPECT_NEAR(r_scale, 1.0, 0.2);  // the scenario's R is the noise it draws: the fit confirms it
  EXPECT_LT(q, 0.1 / 10.0);  // the start was far off

  // Fit on A, checked on B (another seed): the tuned config's NIS inside its 99 % band.
  const nlohmann::json on_b = checkOn(tuned, {}, b);
  const auto& nis = on_b["check_nis"];
  ASSERT_GT(nis["samples"].get<std::size_t>(), 60u);
  EXPECT_EQ(nis["dof"].get<double>(), 2.0);
  EXPECT_EQ(nis["verdict"], "consistent") << on_b.dump(2);
  EXPECT_GE(nis["mean"].get<double>(), nis["bounds"][0].get<double>());
  EXPECT_LE(nis["mean"].get<double>(), nis["bounds"][1].get<double>());
  EXPECT_EQ(on_b["check_nees"]["samples"].get<std::size_t>(), 0u);  // no truth in the recording
  EXPECT_NE(on_b["data"].get<std::string>().find("ptu.csv"), std::string::npos) << on_b["data"];
  std::printf("NIS on B: %.4f in [%.4f, %.4f], %zu samples (tuned on A: q %.4g, R_scale %.4g)\n",
              nis["mean"].get<double>(), nis["bounds"][0].get<double>(), nis["bounds"][1].get<double>(),
              nis["samples"].get<std::size_t>(), q, r_scale);

  // The check can fail. At [T]'s measurement noise (10 % of the path amplitude) the NIS hardly moves
  // with q; it does with R: B's measurements replayed with R halved in std (R_scale 0.5) are
  // overconfident, NIS about 4x.
  const tuning::AdapterRegistry registry = tuning::makeBuiltinAdapters();
  const tuning::ScenarioAdapter& adapter = registry.get("pan_tilt");
  const auto options = tuning::checkedOptions(adapter.options(), {}, "pan_tilt");
  const auto inst = adapter.loadConfig(io::ConfigNode::loadFile(tuned), options);
  const auto data_b = inst->loadRecording(b.string());
  const tuning::ReplayResult halved = inst->replay(*data_b, {q, 0.5}, 0.0, false);
  EXPECT_EQ(halved.nis.verdict(0.99), "overconfident") << halved.nis.mean();
  EXPECT_GT(halved.nis.mean(), 2.0 * nis["mean"].get<double>());

  // Without its unit readings a recording cannot be placed on the screen: refused, naming ptu.csv.
  ASSERT_TRUE(fs::remove(b / "predictive" / "ptu.csv"));
  try {
    inst->loadRecording(b.string());
    FAIL() << "expected InvalidInput";
  } catch (const core::InvalidInput& e) {
    EXPECT_NE(std::string(e.what()).find("ptu.csv"), std::string::npos) << e.what();
  }

  for (const auto& p : {a, b, out}) fs::remove_all(p);
}

TEST(TuneOnRecording, RefusesAFolderThatIsNotARecording) {
  const fs::path none = scratch("none");
  fs::create_directories(none);
  try {
    checkOn(kConfig, kSetting, none);
    FAIL() << "expected InvalidInput";
  } catch (const core::InvalidInput& e) {
    EXPECT_NE(std::string(e.what()).find("recording.csv"), std::string::npos) << e.what();
  }
  fs::remove_all(none);
}
