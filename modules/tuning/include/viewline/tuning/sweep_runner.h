#pragma once
// Runs a sweep in-process on a pool of std::threads: jobs = (setting, seed index), handed out in a
// fixed order from an atomic counter; each job's result lands in its own slot, so the results do
// not depend on the number of workers or on which thread ran what (the seed of run j is
// deriveSeed(base_seed, j), the same for every setting).
//
// Incremental results: when the last run of a setting finishes, the setting's aggregate is
// appended as one JSON line to `results_jsonl` and flushed, so an interrupted session keeps what
// it finished. Stop: when *stop becomes true no new job is started; running jobs finish; settings
// with missing runs are reported as incomplete and left out of the best-setting choice.

#include <atomic>
#include <cstdio>
#include <functional>
#include <map>
#include <memory>
#include <nlohmann/json.hpp>
#include <optional>
#include <string>
#include <vector>

#include "viewline/tuning/scenario.h"
#include "viewline/tuning/sweep_spec.h"

namespace viewline::tuning {

/// One metric of a setting over its seeds (finite values only).
struct MetricStats {
  double mean = 0.0;  ///< mean over seeds
  double std = 0.0;   ///< sample standard deviation over seeds (0 for one seed)
  double min = 0.0;   ///< smallest value
  double max = 0.0;   ///< largest value
  std::size_t n = 0;  ///< finite values
};

/// A setting's runs and their aggregate.
struct SettingResult {
  Setting setting;               ///< the parameter values
  std::vector<RunResult> runs;   ///< in seed order
  bool complete = false;         ///< every run finished without error
  std::string error;             ///< first run error, if any
  std::map<std::string, MetricStats> metrics;  ///< by metric name
  Consistency nees;              ///< NEES pooled over the runs
  Consistency nis;               ///< NIS pooled over the runs
  std::string verdict;           ///< combinedVerdict of the pooled NEES and NIS
  /// The setting as one JSON object (a results.jsonl line), parameters named as in `spec`.
  nlohmann::json toJson(const SweepSpec& spec) const;
};

/// Aggregates the runs of a setting (means, spreads, pooled consistency, verdict).
void aggregate(SettingResult& r, double confidence);

/// How far a sweep is.
struct SweepProgress {
  std::size_t done = 0;    ///< runs finished
  std::size_t total = 0;   ///< runs in all
  double elapsed_s = 0.0;  ///< s since the sweep started
  double eta_s = 0.0;      ///< s still expected
};

/// "[37/100] 12.3 s elapsed, ETA 20 s".
std::string formatProgress(const SweepProgress& p);

/// How a sweep runs.
struct SweepOptions {
  int workers = 0;                         ///< 0: std::thread::hardware_concurrency()
  const std::atomic<bool>* stop = nullptr; ///< when it becomes true, no new run starts (optional)
  std::string results_jsonl;               ///< "" = no incremental file
  std::function<void(const SweepProgress&)> progress;  ///< progress reports (optional)
  double progress_interval_s = 0.5;        ///< minimum time between progress calls (the last one always comes)
  bool series_for_first_seed = false;      ///< keep the time series of every setting's first run
};

/// What a sweep ran and found.
struct SweepOutcome {
  std::vector<SettingResult> settings;     ///< every setting, by index (complete or not)
  std::size_t jobs_done = 0;               ///< runs finished
  std::size_t jobs_total = 0;              ///< runs in all
  bool interrupted = false;                ///< stopped before every run finished
  double wall_s = 0.0;                     ///< s of wall-clock time
  double cpu_s = 0.0;                      ///< process CPU time during the sweep
  int workers = 1;                         ///< threads used
  std::optional<std::size_t> best;         ///< index into settings (complete settings only)
};

/// Runs every (setting, seed). `instances[i]` is setting i's scenario.
SweepOutcome runSweep(const SweepSpec& spec, const std::vector<Setting>& settings,
                      const std::vector<std::unique_ptr<ScenarioInstance>>& instances, const SweepOptions& options);

/// Index of the best complete setting by the spec's metric and direction (ties: lower index).
std::optional<std::size_t> bestSetting(const SweepSpec& spec, const std::vector<SettingResult>& settings);

/// True when two outcomes have bit-identical metrics and consistency sums for every setting.
bool sameResults(const SweepOutcome& a, const SweepOutcome& b, std::string* first_difference = nullptr);

/// Runs `n` indexed jobs on `workers` threads (fixed hand-out order; `job(i)` must write only its
/// own slot). Returns the number of jobs run (fewer when *stop became true). A job that throws
/// stops the hand-out; the first exception is rethrown here once every worker has joined. The jobs are the
/// only parallelism while it runs: OpenCV's thread pool is off (cv::setNumThreads(0), restored
/// after) and each worker runs OpenMP regions on one thread, so runs do not compete with the
/// workers for the cores.
std::size_t parallelFor(std::size_t n, int workers, const std::function<void(std::size_t)>& job,
                        const std::atomic<bool>* stop = nullptr,
                        const std::function<void(std::size_t)>& after = nullptr);

/// Process CPU time (user + system), s.
double processCpuSeconds();

}  // namespace viewline::tuning
