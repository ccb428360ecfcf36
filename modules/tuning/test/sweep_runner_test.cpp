#include <gtest/gtest.h>

#include <atomic>
#include <filesystem>
#include <fstream>
#include <string>

#include "toy_scenario.h"
#include "viewline/core/error.h"
#include "viewline/tuning/sweep_runner.h"

using namespace viewline;
using namespace viewline::tuning;

namespace {

struct Fixture {
  SweepSpec spec;
  std::vector<Setting> settings;
  std::vector<std::unique_ptr<ScenarioInstance>> instances;
  explicit Fixture(int seeds) {
    const auto reg = toy::registry();
    spec = sweepSpecFromString("scenario: toy\nseeds: " + std::to_string(seeds) +
                                   "\nparameters:\n  - key: filter.q\n    range: [0.0001, 1]\n    count: 9\n    scale: log\n",
                               "s.yaml", reg);
    settings = generateSettings(spec);
    const YAML::Node base = YAML::Load("q_true: 0.01\nr_true: 1\nsteps: 300\nfilter: {q: 0.01, r: 1}\n");
    for (const auto& s : settings) instances.push_back(reg.get("toy").load(applySetting(base, spec, s), "toy.yaml", {}));
  }
};

}  // namespace

TEST(SweepRunner, SameResultsForAnyWorkerCountAndBestIsTheTrueNoise) {
  Fixture f(4);
  SweepOptions o1, o3;
  o1.workers = 1;
  o3.workers = 3;
  const SweepOutcome a = runSweep(f.spec, f.settings, f.instances, o1);
  const SweepOutcome b = runSweep(f.spec, f.settings, f.instances, o3);
  std::string diff;
  EXPECT_TRUE(sameResults(a, b, &diff)) << diff;
  ASSERT_TRUE(a.best.has_value());
  // q grid 1e-4 ... 1 by half decades: the true q = 0.01 is index 4; the RMSE optimum is at or next to it.
  EXPECT_NEAR(static_cast<double>(*a.best), 4.0, 1.0);
  EXPECT_EQ(a.settings[4].verdict, "consistent");
  EXPECT_EQ(a.settings[0].verdict, "overconfident");   // q 100x too small
  EXPECT_EQ(a.settings[8].verdict, "underconfident");  // q 100x too large
  EXPECT_EQ(a.jobs_done, 36u);
  EXPECT_FALSE(a.interrupted);
}

TEST(SweepRunner, StopKeepsFinishedSettingsAndJsonLines) {
  Fixture f(2);
  const std::string path = (std::filesystem::temp_directory_path() / "viewline_tuning_test.jsonl").string();
  std::filesystem::remove(path);
  std::atomic<bool> stop{false};
  SweepOptions o;
  o.workers = 1;
  o.stop = &stop;
  o.results_jsonl = path;
  o.progress_interval_s = 0.0;
  std::size_t seen = 0;
  o.progress = [&](const SweepProgress& p) {
    seen = p.done;
    if (p.done >= 7) stop = true;  // stops in the middle of setting 3
  };
  const SweepOutcome out = runSweep(f.spec, f.settings, f.instances, o);
  EXPECT_TRUE(out.interrupted);
  EXPECT_GE(out.jobs_done, 7u);
  EXPECT_LT(out.jobs_done, 18u);
  std::ifstream in(path);
  std::string line;
  std::size_t lines = 0;
  while (std::getline(in, line)) {
    const auto j = nlohmann::json::parse(line);
    EXPECT_TRUE(j["complete"].get<bool>());
    ++lines;
  }
  EXPECT_EQ(lines, out.jobs_done / 2);
  EXPECT_FALSE(out.settings.back().complete);
  ASSERT_TRUE(out.best.has_value());
  EXPECT_LT(*out.best, lines);
  std::filesystem::remove(path);
  (void)seen;
}

TEST(SweepRunner, ProgressText) {
  SweepProgress p;
  p.done = 37;
  p.total = 100;
  p.elapsed_s = 12.34;
  p.eta_s = 20.2;
  EXPECT_EQ(formatProgress(p), "[37/100] 12.3 s elapsed, ETA 20 s");
}

TEST(SweepRunner, AJobThatThrowsOnAWorkerReachesTheCaller) {
  // On worker threads an escaping exception would call std::terminate; it must reach the caller
  // (the tool then reports it and exits 1), whatever the worker count, and stop the hand-out.
  for (const int workers : {1, 2, 4}) {
    std::atomic<int> started{0};
    try {
      parallelFor(1000, workers, [&](std::size_t i) {
        started.fetch_add(1);
        if (i == 3) throw core::InvalidInput("job 3: process noise Q is not positive semi-definite");
      });
      ADD_FAILURE() << "no exception with " << workers << " workers";
    } catch (const core::InvalidInput& e) {
      EXPECT_NE(std::string(e.what()).find("job 3"), std::string::npos) << e.what();
    }
    EXPECT_LT(started.load(), 1000) << workers << " workers kept taking jobs after the failure";
  }
}
