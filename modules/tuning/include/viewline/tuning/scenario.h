#pragma once
// The interface between the tuning tool and a scenario's library code.
//
// A ScenarioAdapter knows one scenario (dart, pan_tilt, ...): it parses the scenario's YAML
// exactly as the scenario's app does (strict keys, so a config the adapter accepts is a config the
// app accepts), and gives a ScenarioInstance that runs one seeded run in-process and returns its
// metrics, NEES/NIS consistency and (on request) the time series for the plots. Runs of one
// instance may execute concurrently on several threads: run() is const and touches no shared
// mutable state; the result depends only on (config, seed).
//
// For the noise auto-tuning an instance also names its noise parameters (process, measurement),
// records what a replay needs (the measurements with their time stamps) from a live run or from
// the scenario app's --log directory, and re-runs its filter on those measurements for candidate
// noise values, returning the innovation cost (autotune.h).
//
// Adapters are compiled only when their scenario's library exists (modules/tuning/CMakeLists.txt)
// and register themselves in makeBuiltinAdapters().

#include <atomic>
#include <cstdint>
#include <functional>
#include <map>
#include <memory>
#include <string>
#include <vector>
#include <yaml-cpp/yaml.h>

#include "viewline/core/statistics.h"
#include "viewline/io/config.h"
#include "viewline/io/log.h"

namespace viewline::tuning {

/// Pooled NEES or NIS samples (mergeable across runs), with the chi-square band of their mean.
///
/// The band treats the samples as independent: Σ of N independent χ²(n) values is χ²(N n), so the
/// mean lies in [χ²((1−c)/2, N n), χ²((1+c)/2, N n)] / N with probability c. NIS values of a
/// consistent Kalman filter are independent over time (the innovations are white), so a run may
/// pool all of them; NEES values of one run are correlated over time, so adapters take one NEES
/// sample per independent track (e.g. per flight).
struct Consistency {
  double sum = 0.0;
  double dof_sum = 0.0;
  std::size_t count = 0;
  void add(double value, double dof);
  void merge(const Consistency& o);
  double mean() const;      ///< NaN when empty
  double meanDof() const;   ///< NaN when empty
  core::Interval bounds(double confidence) const;  ///< {NaN, NaN} when empty
  /// "overconfident" (mean above the band: errors larger than the filter claims), "underconfident"
  /// (below: the filter claims more uncertainty than it has), "consistent", or "n/a" (no samples).
  std::string verdict(double confidence) const;
};

/// Combined verdict of NEES and NIS: any statistic above its band -> "overconfident", any below
/// -> "underconfident" (both at once -> "inconsistent"), else "consistent"; "n/a" with no samples.
std::string combinedVerdict(const Consistency& nees, const Consistency& nis, double confidence);

struct Curve {
  std::string name;
  std::vector<double> x, y;
};

/// Time series of one run, for the plots.
struct RunSeries {
  std::string time_label = "t [s]";
  std::string error_label;          ///< e.g. "position error [m]"
  std::vector<Curve> error;         ///< error over time (one curve per track/flight, or one)
  std::string nis_x_label = "t [s]";
  std::vector<double> nis_t, nis;   ///< NIS samples over time (or over the sample number)
  double nis_dof = 0.0;
  std::string traj_x_label, traj_y_label;  ///< top view axes
  std::vector<Curve> truth, estimate, prediction;  ///< top-view trajectories
};

struct RunResult {
  std::uint64_t seed = 0;
  std::map<std::string, double> metrics;
  Consistency nees, nis;
  std::string verdict;
  std::shared_ptr<RunSeries> series;  ///< when asked for
  std::string error;                  ///< non-empty when the run failed (message)
  double wall_s = 0.0;
};

/// Live samples for --display (called from the running thread).
struct LiveSample {
  double t = 0.0;
  double error = 0.0;  ///< NaN when none at this sample
  double nis = -1.0;   ///< < 0 when none
};

struct RunOptions {
  bool series = false;                 ///< fill RunResult::series
  io::LogDirectory* log = nullptr;     ///< CSV logs (truth, measurements, estimates, innovations, S)
  std::function<void(double)> progress;                 ///< fraction done (single runs)
  std::function<void(const LiveSample&)> live;          ///< live curves (single runs)
  bool display = false;                ///< the scenario's own live view (camera image) when it has one
};

struct NoiseParameter {
  std::string name;         ///< "process" / "measurement"
  std::string symbol;       ///< "q", "sigma_px"...
  std::string unit;
  std::string config_key;   ///< dotted scenario key written to the tuned config ("" = not a config key)
  std::string description;
  double value = 0.0;       ///< the value the instance uses
};

/// What a replay needs (measurements, time stamps); opaque to the tuning core.
class ReplayData {
public:
  virtual ~ReplayData() = default;
  virtual std::size_t measurements() const = 0;
  virtual std::string describe() const = 0;
};

struct ReplayResult {
  double cost = 0.0;        ///< −2 log-likelihood of the innovations (up to a constant), see autotune.h
  std::size_t terms = 0;    ///< innovations in the cost
  Consistency nis;          ///< NIS of the replayed (accepted) innovations
  std::shared_ptr<RunSeries> series;
};

class ScenarioInstance {
public:
  virtual ~ScenarioInstance() = default;
  virtual RunResult run(std::uint64_t seed, const RunOptions& options) const = 0;
  virtual double confidence() const { return 0.99; }

  // --- noise auto-tuning
  /// Empty when this instance supports noise auto-tuning; otherwise why not (shown to the user,
  /// e.g. "the filter's measurements depend on the filter itself (closed loop), so they cannot be
  /// replayed"). An instance that does not support it need not override the methods below: their
  /// defaults throw core::InvalidInput with that reason.
  virtual std::string autotuneUnsupported() const { return {}; }
  virtual std::vector<NoiseParameter> noiseParameters() const;
  /// Runs the scenario (`runs` seeded runs from `seed`) and records the replay data.
  virtual std::unique_ptr<ReplayData> record(std::uint64_t seed, int runs) const;
  /// Reads the replay data from the scenario app's --log directory.
  virtual std::unique_ptr<ReplayData> loadLog(const std::string& dir) const;
  /// Re-runs the filter on the data with the given noise values (in noiseParameters() order).
  /// `outlier_prior` is the prior probability that a measurement is a gross outlier (0: none).
  virtual ReplayResult replay(const ReplayData& data, const std::vector<double>& noise, double outlier_prior,
                              bool series) const;
  /// A copy using these noise values.
  virtual std::unique_ptr<ScenarioInstance> withNoise(const std::vector<double>& noise) const;

  /// Throws core::InvalidInput "<scenario>: noise auto-tuning is not supported: <reason>" when
  /// autotuneUnsupported() is not empty.
  void requireAutotune(const std::string& scenario) const;
};

/// An option of an adapter, given in the sweep file's `adapter:` map.
struct AdapterOption {
  std::string name;
  std::string default_value;
  std::vector<std::string> choices;  ///< empty: a number
  std::string doc;
};
using AdapterOptions = std::map<std::string, std::string>;

class ScenarioAdapter {
public:
  virtual ~ScenarioAdapter() = default;
  virtual std::string name() const = 0;
  virtual std::string description() const = 0;
  /// The scenario app that reads the same config (for the "ready to use" command line).
  virtual std::string appCommand(const std::string& config_path) const = 0;
  virtual std::string defaultMetric() const = 0;
  virtual bool defaultMinimize() const { return true; }
  /// Metric names a run reports (documentation, sweep-file check).
  virtual std::vector<std::string> metricNames() const = 0;
  virtual std::vector<AdapterOption> options() const { return {}; }
  /// Parses the scenario tree exactly like the scenario app (strict; `name` names the file in
  /// errors). Throws core::InvalidInput.
  virtual std::unique_ptr<ScenarioInstance> load(const YAML::Node& scenario, const std::string& name,
                                                 const AdapterOptions& options) const = 0;
  /// The same from a config parsed once (io::ConfigNode, its keys not yet read; its file name names
  /// the file in errors): sessions load their scenario this way, so the text is parsed once. The
  /// default hands the tree to load(); an adapter whose reader takes a ConfigNode reads it directly.
  virtual std::unique_ptr<ScenarioInstance> loadConfig(const io::ConfigNode& config, const AdapterOptions& options) const;
};

class AdapterRegistry {
public:
  void add(std::unique_ptr<ScenarioAdapter> adapter);
  /// Throws core::InvalidInput listing the registered names when `name` is unknown.
  const ScenarioAdapter& get(const std::string& name) const;
  bool has(const std::string& name) const;
  std::vector<std::string> names() const;

private:
  std::vector<std::unique_ptr<ScenarioAdapter>> adapters_;
};

/// Every adapter compiled into this build (generated registration, see CMakeLists.txt).
AdapterRegistry makeBuiltinAdapters();

/// Reads the options declared by `adapter` from a config node (strict: unknown keys are left for
/// the caller's finish()); defaults for absent ones.
AdapterOptions readAdapterOptions(const ScenarioAdapter& adapter, const io::ConfigNode* node);

/// Option helpers for adapters (throw core::InvalidInput naming the option).
double optionNumber(const AdapterOptions& o, const std::string& name);
std::string optionText(const AdapterOptions& o, const std::string& name);

}  // namespace viewline::tuning
