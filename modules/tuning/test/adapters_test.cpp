// The scenario adapters for table ball, ball catching and mobile capture: a tiny sweep
// of each (2 settings x 1 seed, short runs) through the full session, checking the report, the
// summary and that the metrics a user optimises and the consistency statistics exist and are
// finite; the adapters without noise auto-tuning must say so (not crash, not pretend; mobile
// capture tunes from live recordings and says why not from a --log folder), and so must
// the pan-tilt adapter for a filter without process noise.
// Runs from the source root (ctest's working directory), so config/ paths resolve.

#include <gtest/gtest.h>

#include <cmath>
#include <filesystem>
#include <fstream>
#include <sstream>

#include "viewline/core/error.h"
#include "viewline/core/random.h"
#include "viewline/io/config.h"
#include "viewline/io/config_edit.h"
#include "viewline/tuning/scenario.h"
#include "viewline/tuning/session.h"
#include "viewline/tuning/yaml_edit.h"

using namespace viewline;
using namespace viewline::tuning;
namespace fs = std::filesystem;

namespace {

fs::path scratch(const std::string& name) {
  const fs::path d = fs::temp_directory_path() / ("viewline_adapters_test_" + name);
  fs::remove_all(d);
  fs::create_directories(d);
  return d;
}

std::string writeSweep(const fs::path& dir, const std::string& body) {
  const fs::path p = dir / "sweep.yaml";
  std::ofstream(p) << body;
  return p.string();
}

std::string configPath(const std::string& name) { return (fs::current_path() / "config" / name).string(); }

/// Runs the sweep and checks what every session must produce; returns the summary.
nlohmann::json runTiny(const std::string& name, const std::string& body, const std::vector<std::string>& finite_metrics) {
  const AdapterRegistry reg = makeBuiltinAdapters();
  const fs::path dir = scratch(name);
  SessionOptions o;
  o.out_dir = (dir / "out").string();
  o.workers = 2;
  o.quiet = true;
  const nlohmann::json j = runSweepSession(reg, writeSweep(dir, body), o);
  EXPECT_TRUE(fs::exists(dir / "out" / "report.html"));
  EXPECT_TRUE(fs::exists(dir / "out" / "best_config.yaml"));
  EXPECT_GE(j.value("report_plots", 0), 3) << "metric plot, error over time, trajectories at least";
  EXPECT_TRUE(j.value("best_config_loads", false));
  const auto& all = j.at("all_settings");
  EXPECT_EQ(all.size(), 2u);
  for (const auto& s : all) {
    EXPECT_TRUE(s.value("complete", false)) << s.dump();
    EXPECT_FALSE(s.contains("error")) << s.dump();
    for (const std::string& k : finite_metrics) {
      if (!s.at("metrics").contains(k)) {
        ADD_FAILURE() << name << ": no metric " << k;
        continue;
      }
      const auto& v = s.at("metrics").at(k).at("mean");
      EXPECT_TRUE(v.is_number() && std::isfinite(v.get<double>())) << name << ": metric " << k << " = " << v.dump();
    }
  }
  return j;
}

bool hasInvalidInput(const std::function<void()>& f, const std::string& needle) {
  try {
    f();
  } catch (const core::InvalidInput& e) {
    return std::string(e.what()).find(needle) != std::string::npos;
  }
  return false;
}

}  // namespace

TEST(ScenarioAdapters, AllScenariosAreRegistered) {
  const AdapterRegistry reg = makeBuiltinAdapters();
  for (const char* n : {"table_ball", "ball_catching", "mobile_capture"}) EXPECT_TRUE(reg.has(n)) << n;
}

TEST(ScenarioAdapters, TableBallTinySweepWithAutotune) {
  const nlohmann::json j = runTiny("table_ball",
                                   "scenario: table_ball\nconfig: " + configPath("table_ball.yaml") +
                                       "\nseeds: 1\nmetric: observer_rmse_mm\nparameters:\n"
                                       "  - key: observer.sigma_v\n    values: [0.003, 0.01]\n"
                                       "adapter: {duration: 2}\n"
                                       "autotune: {start_scale: 10, outlier_prior: 0.01, grid_points: 5}\n",
                                   {"observer_rmse_mm", "measurement_rmse_mm", "ball_detection_rate", "nis_mean", "nees_mean"});
  // The auto-tuning replayed the observer's measurements: NIS before and after, tuned noise written.
  ASSERT_TRUE(j.contains("autotune_nis_mean")) << j.dump();
  EXPECT_TRUE(j.at("autotune_nis_mean").is_number());
  EXPECT_TRUE(fs::exists(j.at("autotuned_config").get<std::string>()));
}

TEST(ScenarioAdapters, BallCatchingTinySweep) {
  const nlohmann::json j = runTiny("ball_catching",
                                   "scenario: ball_catching\nconfig: " + configPath("ball_catching.yaml") +
                                       "\nseeds: 1\nmetric: prediction_error_mm_median\nparameters:\n"
                                       "  - key: tracker.accel_psd\n    values: [0.1, 1]\nadapter: {throws: 2}\n",
                                   {"catch_rate_all", "detection_rate", "prediction_error_mm_median", "nis_mean",
                                    "nees_mean", "replay_fate_mismatch"});
  for (const auto& s : j.at("all_settings")) EXPECT_GT(s.at("nis").at("samples").get<double>(), 20.0) << s.dump();
}

TEST(ScenarioAdapters, MobileCaptureTinySweep) {
  const nlohmann::json j = runTiny("mobile_capture",
                                   "scenario: mobile_capture\nconfig: " + configPath("mobile_capture.yaml") +
                                       "\nseeds: 1\nmetric: estimate_rmse_mm\nparameters:\n"
                                       "  - key: filter.q_v\n    values: [0.003, 0.03]\nadapter: {max_time: 5, settle_s: 1}\n",
                                   {"estimate_rmse_mm", "detection_rate", "capture_time_s", "nees_mean", "nis_mean"});
  // The gate's NIS of every tested measurement after the settle time (4 s at the 10 Hz vision rate).
  for (const auto& s : j.at("all_settings")) EXPECT_GT(s.at("nis").at("samples").get<double>(), 20.0) << s.dump();
}

/// A copy of the shipped config `name` in `dir` with `values` set (its relative paths re-expressed).
std::string editedConfig(const fs::path& dir, const std::string& name, std::vector<std::pair<std::string, YAML::Node>> values) {
  const std::string shipped = configPath(name);
  std::ostringstream read;
  read << std::ifstream(shipped).rdbuf();
  const std::string text = read.str();
  auto all = relocatedPaths(YAML::Load(text), fs::path(shipped).parent_path().string(), dir.string());
  for (auto& v : values) all.push_back(std::move(v));
  const std::string path = (dir / name).string();
  std::ofstream(path) << io::rewriteYamlText(text, all, "test: " + name + " edited");
  return path;
}

TEST(ScenarioAdapters, AutotuneSaysWhenAnAdapterDoesNotSupportIt) {
  const AdapterRegistry reg = makeBuiltinAdapters();
  for (const std::string sc : {"ball_catching"}) {
    const fs::path dir = scratch("unsupported_" + sc);
    AutotuneSessionOptions a;
    a.scenario = sc;
    // The detection's std per detection (blob covariance): no one told std to tune.
    a.config = editedConfig(dir, sc + ".yaml", {{"detector.sigma_px", YAML::Node(0.0)}});
    a.out_dir = (dir / "out").string();
    a.quiet = true;
    EXPECT_TRUE(hasInvalidInput([&] { runAutotuneSession(reg, a); }, "noise auto-tuning is not supported")) << sc;
    EXPECT_TRUE(hasInvalidInput([&] { runAutotuneSession(reg, a); }, "detector.sigma_px is 0")) << sc;
    // A sweep file asking for it is refused before any run, naming the file.
    const std::string sweep = writeSweep(dir, "scenario: " + sc + "\nconfig: " + a.config +
                                                  "\nseeds: 1\nparameters:\n  - key: threads\n    values: [1]\n"
                                                  "autotune: {start_scale: 10}\n");
    SessionOptions o;
    o.out_dir = (dir / "sweep_out").string();
    o.quiet = true;
    EXPECT_TRUE(hasInvalidInput([&] { runSweepSession(reg, sweep, o); }, "sweep.yaml: section 'autotune'")) << sc;
  }
}

TEST(ScenarioAdapters, BallCatchingReplayIsWhatTheLoopGaveItsTracker) {
  // The auto-tuner's replay of recorded throws at the shipped noise gives the live run's NIS sample
  // for sample (same images, same tracker, counted as the loop counts them); a std told 4x too
  // large shrinks it about 16-fold, so the replay does follow the noise.
  const AdapterRegistry reg = makeBuiltinAdapters();
  const ScenarioAdapter& ad = reg.get("ball_catching");
  const io::ConfigNode o = io::ConfigNode::fromString("throws: 2", "adapter options");
  const AdapterOptions opts = readAdapterOptions(ad, &o);
  const auto inst = ad.loadConfig(io::ConfigNode::loadFile(configPath("ball_catching.yaml")), opts);
  ASSERT_EQ(inst->autotuneUnsupported(), "");
  const std::vector<NoiseParameter> noise = inst->noiseParameters();
  ASSERT_EQ(noise.size(), 2u);
  EXPECT_EQ(noise[0].config_key, "tracker.accel_psd");
  EXPECT_EQ(noise[1].config_key, "detector.sigma_px");
  const std::uint64_t seed = 21;
  const RunResult live = inst->run(core::deriveSeed(seed, 0), {});
  const auto data = inst->record(seed, 1);
  ASSERT_GT(data->measurements(), 40u);
  const ReplayResult same = inst->replay(*data, {noise[0].value, noise[1].value}, 0.0, false);
  ASSERT_GT(live.nis.count, 20u);
  EXPECT_EQ(same.nis.count, live.nis.count);
  EXPECT_DOUBLE_EQ(same.nis.sum, live.nis.sum);
  const ReplayResult wide = inst->replay(*data, {noise[0].value, 4.0 * noise[1].value}, 0.0, false);
  EXPECT_LT(wide.nis.mean(), 0.25 * same.nis.mean());
  EXPECT_GT(same.terms, 0u);
}

// With four cameras `high` cannot see the registration marker and keeps its calibrated pose; the
// loop tells it the unregistered bias std (tracker.pixel_bias.unregistered_sigma_px) and the others
// the registered one. The replay tells each camera what the loop told it: the same NIS, sample for
// sample (told the registered std everywhere, it differed).
TEST(ScenarioAdapters, BallCatchingReplayTellsEachCameraTheBiasStdTheLoopToldIt) {
  const AdapterRegistry reg = makeBuiltinAdapters();
  const ScenarioAdapter& ad = reg.get("ball_catching");
  const io::ConfigNode o = io::ConfigNode::fromString("throws: 2", "adapter options");
  const auto inst = ad.loadConfig(io::loadConfigWithValues(configPath("ball_catching.yaml"), {"camera_count=4"}),
                                  readAdapterOptions(ad, &o));
  const std::vector<NoiseParameter> noise = inst->noiseParameters();
  const std::uint64_t seed = 22;
  const RunResult live = inst->run(core::deriveSeed(seed, 0), {});
  const auto data = inst->record(seed, 1);
  const ReplayResult same = inst->replay(*data, {noise[0].value, noise[1].value}, 0.0, false);
  ASSERT_GT(live.nis.count, 20u);
  EXPECT_EQ(same.nis.count, live.nis.count);
  EXPECT_DOUBLE_EQ(same.nis.sum, live.nis.sum);
}

TEST(ScenarioAdapters, MobileCaptureAutotunesFromLiveRecordingsNotFromLogs) {
  const AdapterRegistry reg = makeBuiltinAdapters();
  const fs::path dir = scratch("mobile_capture_log");
  AutotuneSessionOptions a;
  a.scenario = "mobile_capture";
  a.config = configPath("mobile_capture.yaml");
  a.log_dir = dir.string();
  a.out_dir = (dir / "out").string();
  a.quiet = true;
  EXPECT_TRUE(hasInvalidInput([&] { runAutotuneSession(reg, a); }, "record live runs instead"));
  const auto inst = reg.get("mobile_capture").loadConfig(io::ConfigNode::loadFile(a.config), readAdapterOptions(reg.get("mobile_capture"), nullptr));
  EXPECT_EQ(inst->autotuneUnsupported(), "");
  ASSERT_EQ(inst->noiseParameters().size(), 3u);
  EXPECT_EQ(inst->noiseParameters()[2].config_key, "detector.pixel_sigma");
}

TEST(ScenarioAdapters, PanTiltAutotuneRefusesTheParticleFilter) {
  // filter.model waypoint_particles has no process noise: auto-tuning says so instead of "tuning" the
  // unused filter.q. The config is the shipped random one with that model, written elsewhere with its
  // relative rig path re-expressed (as the session's best_config.yaml is).
  const AdapterRegistry reg = makeBuiltinAdapters();
  if (!reg.has("pan_tilt")) GTEST_SKIP() << "no pan_tilt adapter in this build";
  const fs::path dir = scratch("pan_tilt_particles");
  const std::string shipped = configPath("pan_tilt_random.yaml");
  std::ostringstream read;
  read << std::ifstream(shipped).rdbuf();
  const std::string text = read.str();
  auto values = relocatedPaths(YAML::Load(text), fs::path(shipped).parent_path().string(), dir.string());
  values.emplace_back("filter.model", YAML::Node("waypoint_particles"));
  AutotuneSessionOptions a;
  a.scenario = "pan_tilt";
  a.config = (dir / "particles.yaml").string();
  std::ofstream(a.config) << io::rewriteYamlText(text, values, "test: the random config with the particle filter");
  a.out_dir = (dir / "out").string();
  a.quiet = true;
  EXPECT_TRUE(hasInvalidInput([&] { runAutotuneSession(reg, a); }, "waypoint_particles has no process noise"));
}

TEST(ScenarioAdapters, PanTiltAutotuneTakesTheShippedMixture) {
  // The three shipped pan-tilt configs share filter.model mixture: auto-tuning is supported and tunes
  // the cv part's acceleration density q (m²/s³, as constant_velocity) and the R scale.
  const AdapterRegistry reg = makeBuiltinAdapters();
  if (!reg.has("pan_tilt")) GTEST_SKIP() << "no pan_tilt adapter in this build";
  for (const std::string path : {"rectangle", "circle", "random"}) {
    const std::string config = configPath("pan_tilt_" + path + ".yaml");
    const auto inst =
        reg.get("pan_tilt").loadConfig(io::ConfigNode::loadFile(config), readAdapterOptions(reg.get("pan_tilt"), nullptr));
    EXPECT_EQ(inst->autotuneUnsupported(), "") << path;
    const std::vector<NoiseParameter> noise = inst->noiseParameters();
    ASSERT_EQ(noise.size(), 2u) << path;
    EXPECT_EQ(noise[0].config_key, "filter.q") << path;
    EXPECT_EQ(noise[0].unit, "m^2/s^3") << path;
    EXPECT_GT(noise[0].value, 0.0) << path;
  }
}
