// Guard of the pan-tilt headline figures (docs/results.md, "Pan-tilt tracking"): the shipped filter, one
// configuration for the three paths, replayed on each path's measurements with [T]'s noise (synthetic
// frames, no rendering: scenarios::writeSyntheticPanTiltFrames) on a seed the settings were not chosen
// on. The bounds sit about 20 % above today's figures on that seed, so a regression of that size fails;
// the NIS must stay inside its two-sided 99 % band, and the random path's NEES too.
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
// rectangle filtered 0.998 / 0.622 cm, 10.13 px at the frames' horizon; circle 0.303 / 0.259 cm, 2.95 px;
// random 1.161 / 0.673 cm, 12.02 px; NIS means 1.908, 1.933, 1.947 (band [1.838, 2.170] for 960 samples);
// NEES means 2.79, 1.30, 5.06 (band [2.829, 5.405], one sample per second): the random path's is guarded.
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
  EXPECT_LT(m.rmse_filtered_cm.x(), 0.36);
  EXPECT_LT(m.rmse_filtered_cm.y(), 0.31);
  EXPECT_LT(m.frame_predicted_error_px, 3.5);
  EXPECT_TRUE(m.consistency.nisBand().contains(m.consistency.nis.mean())) << m.consistency.nis.mean();
}

TEST(PanTiltHeadline, RandomPathPredictionNisAndNees) {
  const auto m = replayShipped("random", kSeed, kDuration);
  EXPECT_LT(m.rmse_filtered_cm.x(), 1.39);
  EXPECT_LT(m.rmse_filtered_cm.y(), 0.81);
  EXPECT_LT(m.frame_predicted_error_px, 14.4);
  EXPECT_TRUE(m.consistency.nisBand().contains(m.consistency.nis.mean())) << m.consistency.nis.mean();
  // The soft corner mixture over every jump time: its covariance is the model's posterior one (when it kept the
  // four likeliest jump times, the NEES was 34-125 on seeds 1-5).
  EXPECT_TRUE(m.consistency.neesBand().contains(m.consistency.nees.mean())) << m.consistency.nees.mean();
}
