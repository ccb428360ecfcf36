#pragma once
// Tuning sessions (what apps/viewline_tune runs; the app only parses the command line).
//
// Sweep session (runSweepSession), all outputs in one folder:
//   results.jsonl      one JSON line per finished setting (appended + flushed as they finish)
//   summary.json       the session's figures (keys documented in tutorials/tune_tracking_loop)
//   best_config.yaml   the scenario config with the best setting's values (readable by the app)
//   autotuned_config.yaml  (with autotune) the config with the auto-tuned noise values
//   report.html        self-contained report (tables + gnuplot plots embedded)
//   plots/             the plots' data files and gnuplot scripts
// Single run (runSingleSession): one seeded run with its consistency and plots.
// Auto-tune (runAutotuneSession): from the scenario app's --log folder or a live recording.

#include <atomic>
#include <functional>
#include <map>
#include <nlohmann/json.hpp>
#include <string>
#include <vector>

#include "viewline/tuning/scenario.h"

namespace viewline::tuning {

/// What a sweep session runs and where its outputs go.
struct SessionOptions {
  std::string out_dir = "tune_out";   ///< folder of every output (created)
  std::string config_override;        ///< scenario config instead of the sweep file's `config`
  /// "key=value" edits of the scenario config (the command line's --set): applied to its text before
  /// anything is loaded (io::configTextWithValues, comments kept where the keys are plain scalars), so
  /// the runs, the summary's `config_set` and the configs written back (best_config.yaml,
  /// autotuned_config.yaml) all have them.
  std::vector<std::string> set;
  int workers = 0;                    ///< 0: all cores
  int seeds_override = 0;             ///< > 0: seeds per setting instead of the file's
  bool measure_speedup = false;       ///< also run the sweep with one worker: parallel_speedup
  bool skip_autotune = false;         ///< leave out the sweep file's autotune section
  const std::atomic<bool>* stop = nullptr;  ///< when it becomes true, no new run starts (optional)
  bool quiet = false;                 ///< no progress lines on stderr
};

/// Sweep (+ optional auto-tune) session; returns the summary (also written to summary.json).
nlohmann::json runSweepSession(const AdapterRegistry& registry, const std::string& sweep_file,
                               const SessionOptions& options);

/// Live curves of a single run (--display): given the window title and the run's confidence level,
/// returns where the samples go, or an empty function when no window can open. The app supplies it
/// (viz::LivePlot): the tuning library opens no window.
using LiveViewFactory =
    std::function<std::function<void(const LiveSample&)>(const std::string& title, double confidence)>;

/// What a single seeded run session runs and where its outputs go.
struct SingleRunOptions {
  std::string scenario;      ///< adapter name
  std::string config;        ///< scenario YAML
  std::uint64_t seed = 1;    ///< seed of the run
  std::string out_dir = "tune_run";  ///< folder of the summary and report (created)
  std::string log_dir;       ///< scenario logs (CSV) of the run, "" = none
  bool display = false;      ///< live curves (live_view) + the scenario's view
  LiveViewFactory live_view; ///< the live curves' window (from the app; empty: none)
  std::vector<std::string> set;  ///< --set edits of the config (see SessionOptions::set)
  AdapterOptions adapter_options;  ///< --option values (checked against the adapter's declarations)
  bool quiet = false;        ///< no progress on stderr
};
/// One seeded run with its metrics, consistency and plots; returns the summary (also summary.json).
nlohmann::json runSingleSession(const AdapterRegistry& registry, const SingleRunOptions& options);

/// What a noise auto-tuning session tunes, from which data, and where its outputs go.
struct AutotuneSessionOptions {
  std::string scenario;       ///< adapter name
  std::string config;         ///< scenario YAML
  std::string log_dir;        ///< the scenario app's --log folder; "" = record a live run
  std::uint64_t record_seed = 1000;  ///< seed of the live recording
  int record_runs = 1;        ///< runs of the live recording
  double start_scale = 1.0;   ///< start from the config's noise values times this
  /// Start values by config key, used as given (e.g. for a noise the config sets to 0, which a
  /// log-space search cannot start from).
  std::map<std::string, double> start_values;
  double outlier_prior = 0.05;  ///< AutotuneOptions::outlier_prior
  double span_decades = 2.5;  ///< AutotuneOptions::span_decades
  int grid_points = 11;       ///< AutotuneOptions::grid_points
  int verify_runs = 0;        ///< > 0: live runs of the start and tuned configs for NEES/NIS (base seed below)
  /// Seed of the fresh-seed check (a new recording replayed at the tuned noise) and base seed of the
  /// live runs; 0: record_seed + 1 for the check, 1 for the live runs. Must differ from record_seed
  /// when the data are recorded live.
  std::uint64_t verify_seed = 0;
  int workers = 0;            ///< threads; 0: all cores
  std::string out_dir = "tune_autotune";  ///< folder of every output (created)
  std::vector<std::string> set;  ///< --set edits of the config (see SessionOptions::set)
  AdapterOptions adapter_options;  ///< --option values (checked against the adapter's declarations)
  bool quiet = false;         ///< no progress lines on stderr
};
/// Noise auto-tuning with its report and tuned config; returns the summary (also summary.json).
nlohmann::json runAutotuneSession(const AdapterRegistry& registry, const AutotuneSessionOptions& options);

/// What a consistency check runs: a config as it is, on fresh seeds.
struct CheckOptions {
  std::string scenario;        ///< adapter name
  std::string config;          ///< scenario YAML (as shipped, or with --set edits)
  std::uint64_t seed = 2;      ///< base seed: runs use deriveSeed(seed, 0..seeds-1)
  int seeds = 3;               ///< seeded runs pooled
  int workers = 0;             ///< threads; 0: all cores
  std::string out_dir;         ///< "" : no files; else summary.json there
  std::vector<std::string> set;  ///< --set edits of the config (see SessionOptions::set)
  AdapterOptions adapter_options;  ///< --option values (checked against the adapter's declarations)
  bool quiet = false;          ///< no progress lines on stderr
};
/// NIS and NEES of the config's filter pooled over seeded runs, each mean with its two-sided
/// chi-square band at the scenario's confidence and a verdict (Consistency); returns the summary
/// (keys check_nis / check_nees {mean, bounds, samples, verdict}, check_verdict, metrics).
nlohmann::json runCheckSession(const AdapterRegistry& registry, const CheckOptions& options);

/// "1.23 0.98 0.50" (the 1, 5, 15 minute load averages) or "" when unavailable.
std::string loadAverage();

}  // namespace viewline::tuning
