// The tuning tool on the dart scenario (measurement level): a sweep gives identical results on 1
// and 2 workers, the consistency verdicts follow the process noise, and the noise auto-tuner
// started 10x off recovers the simulated noise with NEES inside its 99 % band.
#include <gtest/gtest.h>

#include <fstream>
#include <sstream>

#include "viewline/core/error.h"
#include "viewline/tuning/autotune.h"
#include "viewline/tuning/sweep_runner.h"
#include "viewline/tuning/sweep_spec.h"
#include "viewline/tuning/yaml_edit.h"

using namespace viewline;
using namespace viewline::tuning;

namespace {

const std::string kGusty = std::string(VIEWLINE_SOURCE_DIR) + "/config/sweeps/scenarios/dart_gusty.yaml";

YAML::Node gusty() { return YAML::LoadFile(kGusty); }

SweepSpec spec(const AdapterRegistry& reg, const std::string& params) {
  return sweepSpecFromString("scenario: dart\nseeds: 3\nparameters:\n" + params +
                                 "adapter: {flights: 12, clock: alternating, outliers: none}\n",
                             "t.yaml", reg, VIEWLINE_SOURCE_DIR);
}

}  // namespace

TEST(TuningDart, SweepSameResultsOnAnyWorkerCountAndVerdictsFollowTheNoise) {
  const AdapterRegistry reg = makeBuiltinAdapters();
  if (!reg.has("dart")) GTEST_SKIP() << "dart adapter not built";
  const SweepSpec s = spec(reg, "  - key: tracker.accel_psd\n    values: [0.02, 2, 200]\n");
  const auto settings = generateSettings(s);
  std::vector<std::unique_ptr<ScenarioInstance>> inst;
  for (const auto& st : settings) inst.push_back(reg.get("dart").load(applySetting(gusty(), s, st), kGusty, s.adapter_options));
  SweepOptions one, two;
  one.workers = 1;
  two.workers = 2;
  const SweepOutcome a = runSweep(s, settings, inst, one), b = runSweep(s, settings, inst, two);
  std::string diff;
  EXPECT_TRUE(sameResults(a, b, &diff)) << diff;
  // Truth q = 2: 100x too small is overconfident, right is consistent, 100x too large underconfident.
  EXPECT_EQ(a.settings[0].nis.verdict(0.99), "overconfident");
  EXPECT_EQ(a.settings[1].verdict, "consistent");
  EXPECT_EQ(a.settings[2].nis.verdict(0.99), "underconfident");
  ASSERT_TRUE(a.best.has_value());
  EXPECT_EQ(*a.best, 1u);
}

TEST(TuningDart, AutotuneFrom10xOffGivesConsistentNees) {
  const AdapterRegistry reg = makeBuiltinAdapters();
  if (!reg.has("dart")) GTEST_SKIP() << "dart adapter not built";
  AdapterOptions o = readAdapterOptions(reg.get("dart"), nullptr);
  o["flights"] = "30";
  o["clock"] = "alternating";
  o["outliers"] = "none";
  const auto base = reg.get("dart").load(gusty(), kGusty, o);
  const auto start = base->withNoise({20.0, 5.0});  // truth: q = 2, sigma = 0.5 px
  const auto data = start->record(1000, 1);
  AutotuneOptions ao;
  ao.outlier_prior = 0.0;
  ao.grid_points = 9;
  ao.workers = 2;
  const AutotuneResult r = autotuneNoise(*start, *data, {20.0, 5.0}, ao);
  EXPECT_NEAR(r.tuned[1], 0.5, 0.05);                       // pixel noise
  EXPECT_GT(r.tuned[0], 0.5);                               // process noise within 4x of 2
  EXPECT_LT(r.tuned[0], 8.0);
  EXPECT_EQ(r.before.nis.verdict(0.99), "underconfident");
  EXPECT_EQ(r.after.nis.verdict(0.99), "consistent") << r.after.nis.mean();
  // Live runs of the tuned noise on other seeds: NEES inside its 99 % band.
  const auto tuned = base->withNoise(r.tuned);
  Consistency nees;
  for (std::uint64_t seed = 1; seed <= 4; ++seed) nees.merge(tuned->run(seed, {}).nees);
  const core::Interval band = nees.bounds(0.99);
  EXPECT_TRUE(band.contains(nees.mean())) << nees.mean() << " not in [" << band.lo << ", " << band.hi << "]";
}

TEST(TuningDart, BadSweepValueNamesTheKey) {
  const AdapterRegistry reg = makeBuiltinAdapters();
  if (!reg.has("dart")) GTEST_SKIP() << "dart adapter not built";
  const SweepSpec s = spec(reg, "  - key: tracker.gate\n    values: [mahalanobis, nearest]\n");
  const auto settings = generateSettings(s);
  try {
    reg.get("dart").load(applySetting(gusty(), s, settings[1]), kGusty, s.adapter_options);
    FAIL() << "expected an error";
  } catch (const core::InvalidInput& e) {
    EXPECT_NE(std::string(e.what()).find("tracker.gate"), std::string::npos) << e.what();
  }
}
