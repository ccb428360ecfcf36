#include <gtest/gtest.h>

#include <cmath>
#include <filesystem>
#include <fstream>
#include <string>

#include "toy_scenario.h"
#include "viewline/core/error.h"
#include "viewline/tuning/autotune.h"
#include "viewline/tuning/session.h"

using namespace viewline;
using namespace viewline::tuning;

TEST(Autotune, NelderMeadFindsAQuadraticMinimum) {
  const auto x = nelderMead([](const std::vector<double>& v) { return std::pow(v[0] - 1.5, 2) + 3.0 * std::pow(v[1] + 0.5, 2); },
                            {0.0, 0.0}, 0.5, 1e-6, 500);
  EXPECT_NEAR(x[0], 1.5, 1e-4);
  EXPECT_NEAR(x[1], -0.5, 1e-4);
}

TEST(Autotune, RecoversProcessAndMeasurementNoiseFrom10xOff) {
  toy::Config c;
  c.q_true = 0.02;
  c.r_true = 0.5;
  c.steps = 2000;
  c.q = 0.2;  // 10x off
  c.r = 5.0;  // 10x off
  const toy::Instance inst(c);
  const auto data = inst.record(11, 2);
  AutotuneOptions o;
  o.workers = 2;
  const AutotuneResult r = autotuneNoise(inst, *data, {c.q, c.r}, o);
  EXPECT_NEAR(std::log(r.tuned[0] / c.q_true), 0.0, std::log(1.5)) << r.tuned[0];
  EXPECT_NEAR(std::log(r.tuned[1] / c.r_true), 0.0, std::log(1.2)) << r.tuned[1];
  EXPECT_EQ(r.before.nis.verdict(0.99), "underconfident");
  EXPECT_EQ(r.after.nis.verdict(0.99), "consistent") << r.after.nis.mean();
  EXPECT_LT(r.after.cost, r.before.cost);
}

TEST(Autotune, SessionChecksTheNisOnAFreshSeed) {
  // The session fits the noise on the recording of record_seed, then checks the NIS on a new
  // recording (verify seed, the tuned filter) replayed at the tuned noise; the recording's own
  // seed is refused as the verification seed.
  namespace fs = std::filesystem;
  const fs::path dir = fs::temp_directory_path() / "viewline_autotune_fresh_seed";
  fs::remove_all(dir);
  fs::create_directories(dir);
  const std::string config = (dir / "toy.yaml").string();
  std::ofstream(config) << "q_true: 0.02\nr_true: 0.5\nsteps: 1000\nfilter:\n  q: 0.2\n  r: 5.0\n";
  const AdapterRegistry reg = toy::registry();
  AutotuneSessionOptions a;
  a.scenario = "toy";
  a.config = config;
  a.record_seed = 11;
  a.grid_points = 7;
  a.workers = 2;
  a.verify_runs = 2;
  a.out_dir = (dir / "out").string();
  a.quiet = true;
  const nlohmann::json j = runAutotuneSession(reg, a);
  EXPECT_EQ(j.at("autotune_verify_seed").get<std::uint64_t>(), 12u);  // record seed + 1
  EXPECT_EQ(j.at("autotune_verify_nis_verdict").get<std::string>(), "consistent") << j.dump();
  const double fresh = j.at("autotune_verify_nis_mean").get<double>();
  const auto band = j.at("autotune_verify_nis_bounds");
  EXPECT_GE(fresh, band[0].get<double>());
  EXPECT_LE(fresh, band[1].get<double>());
  // Another data set: not the fitted replay's NIS.
  EXPECT_NE(fresh, j.at("autotune_nis_mean").get<double>());
  EXPECT_GT(j.at("autotune_verify_nis_samples").get<std::size_t>(), 900u);
  // Where the simulator knows the truth: NEES of the live runs at the verification seed.
  EXPECT_GT(j.at("autotune_verify_nees_samples").get<std::size_t>(), 20u);
  EXPECT_TRUE(j.at("autotune_verify_nees_mean").is_number());
  // The recording's seed as the verification seed is refused.
  a.verify_seed = 11;
  try {
    runAutotuneSession(reg, a);
    FAIL() << "the recording's seed accepted as the verification seed";
  } catch (const core::InvalidInput& e) {
    EXPECT_NE(std::string(e.what()).find("fresh-seed NIS check needs another one"), std::string::npos) << e.what();
  }
}
