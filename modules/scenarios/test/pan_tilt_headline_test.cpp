// Guard of the pan-tilt headline figures (docs/results.md, "Pan-tilt tracking"): the shipped filter, one
// configuration for the three paths, replayed on each path's measurements with [T]'s noise (synthetic
// frames, no rendering: scenarios::writeSyntheticPanTiltFrames) on a seed the settings were not chosen
// on. The bounds sit about 20 % above today's figures on that seed, so a regression of that size fails;
// the NIS must stay inside its two-sided 99 % band.
#include <gtest/gtest.h>
#include <unistd.h>

#include <filesystem>
#include <string>

#include "viewline/io/config_edit.h"
#include "viewline/scenarios/pan_tilt/replay.h"
#include "viewline/scenarios/pan_tilt_scenario.h"

using namespace viewline;

namespace {

scenarios::PanTiltScenarioConfig shipped(const std::string& name) {
  // Tests run with the project root as working directory (viewline_add_test).
  return scenarios::loadPanTiltScenarioConfig(io::loadConfigWithValues("config/pan_tilt_" + name + ".yaml", {}));
}

scenarios::PanTiltReplayMetrics replayShipped(const std::string& name, std::uint64_t seed, double duration) {
  scenarios::PanTiltScenarioConfig cfg = shipped(name);
  cfg.duration = duration;
  const std::filesystem::path csv =
      std::filesystem::temp_directory_path() / ("viewline_pt_guard_" + name + "_" + std::to_string(::getpid()) + ".csv");
  scenarios::writeSyntheticPanTiltFrames(cfg, seed, csv.string());
  const scenarios::PanTiltReplayMetrics m = scenarios::replayPanTiltFilter(cfg, seed, csv.string());
  std::filesystem::remove(csv);
  return m;
}

// Seed 21 (the settings were chosen on seeds 1-5), 40 s (the occlusion at 30 s included). Today on this seed:
// rectangle filtered 0.999 / 0.629 cm, 10.01 px at the frames' horizon; circle 0.418 / 0.337 cm, 4.00 px;
// random 1.180 / 0.684 cm, 12.30 px; NIS means 1.925, 1.917, 1.966 (band [1.838, 2.170] for 960 samples).
constexpr std::uint64_t kSeed = 21;
constexpr double kDuration = 40.0;

}  // namespace

TEST(PanTiltHeadline, TheThreeShippedPathsShareOneFilter) {
  const auto a = shipped("rectangle").control.filter, b = shipped("circle").control.filter,
             c = shipped("random").control.filter;
  for (const auto* f : {&b, &c}) {
    EXPECT_EQ(f->model, a.model);
    EXPECT_EQ(f->q, a.q);
    EXPECT_EQ(f->ct_q_accel, a.ct_q_accel);
    EXPECT_EQ(f->ct_q_omega, a.ct_q_omega);
    EXPECT_EQ(f->mixture_switch_rate, a.mixture_switch_rate);
    EXPECT_EQ(f->jump_window, a.jump_window);
    EXPECT_EQ(f->jump_rate, a.jump_rate);
    EXPECT_EQ(f->jump_decision, a.jump_decision);
    EXPECT_EQ(f->jump_evidence, a.jump_evidence);
    EXPECT_EQ(f->constant_speed, a.constant_speed);
    EXPECT_EQ(f->constant_speed_sigma, a.constant_speed_sigma);
    EXPECT_EQ(f->jump_min_samples, a.jump_min_samples);
    EXPECT_EQ(f->jump_corner_sigma, a.jump_corner_sigma);
    EXPECT_EQ(f->region_center, a.region_center);
    EXPECT_EQ(f->region_size, a.region_size);
    EXPECT_EQ(f->turn_prior_weight, a.turn_prior_weight);
    EXPECT_EQ(f->init_velocity_sigma, a.init_velocity_sigma);
    EXPECT_EQ(f->gate_probability, a.gate_probability);
  }
  EXPECT_EQ(a.model, tracking::TargetModel::Mixture);
}

TEST(PanTiltHeadline, RectangleFilteredRmsePredictionAndNis) {
  const auto m = replayShipped("rectangle", kSeed, kDuration);
  EXPECT_LT(m.rmse_filtered_cm.x(), 1.20);
  EXPECT_LT(m.rmse_filtered_cm.y(), 0.76);
  EXPECT_LT(m.frame_predicted_error_px, 12.0);
  EXPECT_TRUE(m.consistency.nisBand().contains(m.consistency.nis.mean())) << m.consistency.nis.mean();
}

TEST(PanTiltHeadline, CircleFilteredRmsePredictionAndNis) {
  const auto m = replayShipped("circle", kSeed, kDuration);
  EXPECT_LT(m.rmse_filtered_cm.x(), 0.50);
  EXPECT_LT(m.rmse_filtered_cm.y(), 0.40);
  EXPECT_LT(m.frame_predicted_error_px, 4.8);
  EXPECT_TRUE(m.consistency.nisBand().contains(m.consistency.nis.mean())) << m.consistency.nis.mean();
}

TEST(PanTiltHeadline, RandomPathPredictionAndNis) {
  const auto m = replayShipped("random", kSeed, kDuration);
  EXPECT_LT(m.rmse_filtered_cm.x(), 1.42);
  EXPECT_LT(m.rmse_filtered_cm.y(), 0.82);
  EXPECT_LT(m.frame_predicted_error_px, 14.8);
  EXPECT_TRUE(m.consistency.nisBand().contains(m.consistency.nis.mean())) << m.consistency.nis.mean();
}
