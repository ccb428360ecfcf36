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
// records what a replay needs (the measurements with their time stamps) from a live run, from
// the scenario app's --log directory or from a recording of its frames (--record), and re-runs
// its filter on those measurements for candidate noise values, returning the innovation cost
// (autotune.h).
//
// Adapters are compiled only when their scenario's library exists (modules/tuning/CMakeLists.txt)
// and register themselves in makeBuiltinAdapters().

#include <atomic>
#include <cstdint>
#include <functional>
#include <limits>
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
  double sum = 0.0;       ///< Σ of the samples
  double dof_sum = 0.0;   ///< Σ of their degrees of freedom
  std::size_t count = 0;  ///< samples
  /// One sample (a NEES or NIS value) of `dof` degrees of freedom.
  void add(double value, double dof);
  /// Pools another set of samples into this one.
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

/// One plotted curve: points (x[i], y[i]) in the units of its plot's axes.
struct Curve {
  std::string name;       ///< what it shows
  std::vector<double> x;  ///< abscissae
  std::vector<double> y;  ///< ordinates (as many as x)
};

/// Time series of one run, for the plots.
struct RunSeries {
  std::string time_label = "t [s]";  ///< x axis of the error curves
  std::string error_label;          ///< e.g. "position error [m]"
  std::vector<Curve> error;         ///< error over time (one curve per track/flight, or one)
  std::string nis_x_label = "t [s]";  ///< x axis of the NIS samples
  std::vector<double> nis_t;        ///< abscissae of the NIS samples (time, or the sample number)
  std::vector<double> nis;          ///< NIS samples
  double nis_dof = 0.0;             ///< degrees of freedom of one NIS sample
  std::string traj_x_label;         ///< top view x axis, with units
  std::string traj_y_label;         ///< top view y axis, with units
  std::vector<Curve> truth;         ///< true paths (top view)
  std::vector<Curve> estimate;      ///< estimated paths (top view)
  std::vector<Curve> prediction;    ///< predicted paths (top view)
};

/// One seeded run: its metrics and consistency.
struct RunResult {
  std::uint64_t seed = 0;                 ///< the run's seed
  std::map<std::string, double> metrics;  ///< by name (ScenarioAdapter::metricNames), NaN when undefined
  Consistency nees;                       ///< NEES samples of the run
  Consistency nis;                        ///< NIS samples of the run
  std::string verdict;                    ///< combinedVerdict of nees and nis
  std::shared_ptr<RunSeries> series;  ///< when asked for
  std::string error;                  ///< non-empty when the run failed (message)
  double wall_s = 0.0;                ///< s of wall-clock time
};

/// Live samples for --display (called from the running thread).
struct LiveSample {
  double t = 0.0;      ///< s, time of the sample (or its number in the run)
  double error = 0.0;  ///< NaN when none at this sample
  double nis = -1.0;   ///< < 0 when none
};

/// What a run produces besides its result.
struct RunOptions {
  bool series = false;                 ///< fill RunResult::series
  io::LogDirectory* log = nullptr;     ///< CSV logs (truth, measurements, estimates, innovations, S)
  std::function<void(double)> progress;                 ///< fraction done (single runs)
  std::function<void(const LiveSample&)> live;          ///< live curves (single runs)
  bool display = false;                ///< the scenario's own live view (camera image) when it has one
};

/// A noise parameter the auto-tuner may change.
struct NoiseParameter {
  std::string name;         ///< "process" / "measurement"
  std::string symbol;       ///< "q", "sigma_px"...
  std::string unit;         ///< its unit, e.g. "m^2/s^3"
  std::string config_key;   ///< dotted scenario key written to the tuned config ("" = not a config key)
  std::string description;  ///< one line: what it is
  double value = 0.0;       ///< the value the instance uses
};

/// What a replay needs (measurements, time stamps); opaque to the tuning core.
class ReplayData {
public:
  virtual ~ReplayData() = default;
  /// Measurements a replay feeds the filter.
  virtual std::size_t measurements() const = 0;
  /// One line: what was recorded and from where.
  virtual std::string describe() const = 0;
};

/// The innovations of one replay, scored.
struct ReplayResult {
  double cost = 0.0;        ///< −2 log-likelihood of the innovations (up to a constant), see autotune.h
  std::size_t terms = 0;    ///< innovations in the cost
  Consistency nis;          ///< NIS of the replayed (accepted) innovations
  std::shared_ptr<RunSeries> series;  ///< the replay's curves, when asked for
};

/// One scenario config ready to run (see the file comment).
class ScenarioInstance {
public:
  virtual ~ScenarioInstance() = default;
  /// One seeded run (thread-safe: const, no shared mutable state); depends only on (config, seed).
  virtual RunResult run(std::uint64_t seed, const RunOptions& options) const = 0;
  /// Confidence of the NEES/NIS bands the scenario uses.
  virtual double confidence() const { return 0.99; }

  // --- noise auto-tuning
  /// Empty when this instance supports noise auto-tuning; otherwise why not (shown to the user,
  /// e.g. "the filter's measurements depend on the filter itself (closed loop), so they cannot be
  /// replayed"). An instance that does not support it need not override the methods below: their
  /// defaults throw core::InvalidInput with that reason.
  virtual std::string autotuneUnsupported() const { return {}; }
  /// The noise parameters the auto-tuner may change, with the values this instance uses.
  virtual std::vector<NoiseParameter> noiseParameters() const;
  /// Runs the scenario (`runs` seeded runs from `seed`) and records the replay data.
  virtual std::unique_ptr<ReplayData> record(std::uint64_t seed, int runs) const;
  /// Reads the replay data from the scenario app's --log directory.
  virtual std::unique_ptr<ReplayData> loadLog(const std::string& dir) const;
  /// Reads the replay data from a viewline recording folder (the scenario app's --record): its
  /// frames run through the scenario's own detector and loop, so no truth is needed (NIS only).
  /// Default: throws core::InvalidInput saying this adapter does not read recordings.
  virtual std::unique_ptr<ReplayData> loadRecording(const std::string& dir) const;
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

/// An option of an adapter, given in the sweep file's `adapter:` map or as `--option name=value`,
/// declared with its type and range: a number (a whole one when `integer`) in [min, max], or one
/// of `choices`. Checked in one place (accepts(), checkedOptions()) for every way it is given.
struct AdapterOption {
  std::string name;                  ///< key in the `adapter:` map
  std::string default_value;         ///< text used when the option is not given
  std::vector<std::string> choices;  ///< the accepted words; empty: a number
  std::string doc;                   ///< one line for the help (units in it)
  double min = -std::numeric_limits<double>::infinity();  ///< smallest accepted number (inclusive)
  double max = std::numeric_limits<double>::infinity();   ///< largest accepted number (inclusive)
  bool integer = false;              ///< numbers must be whole
  /// What a value must be, for messages: "an integer >= 1", "a number in [0, 1e+06]", "one of: a, b".
  std::string expected() const;
  /// True when `text` is a value of this option (a finite number of the type and range, or a choice).
  bool accepts(const std::string& text) const;
};
/// Option values by name, as text (numbers as written).
using AdapterOptions = std::map<std::string, std::string>;

/// What the tuning tool knows of one scenario (see the file comment).
class ScenarioAdapter {
public:
  virtual ~ScenarioAdapter() = default;
  /// The scenario's name in sweep files and on the command line.
  virtual std::string name() const = 0;
  /// One line for the help.
  virtual std::string description() const = 0;
  /// The scenario app that reads the same config (for the "ready to use" command line).
  virtual std::string appCommand(const std::string& config_path) const = 0;
  /// The metric a sweep optimises unless it names one.
  virtual std::string defaultMetric() const = 0;
  /// Direction of the default metric.
  virtual bool defaultMinimize() const { return true; }
  /// Metric names a run reports (documentation, sweep-file check).
  virtual std::vector<std::string> metricNames() const = 0;
  /// The declared options (type, range, default).
  virtual std::vector<AdapterOption> options() const { return {}; }
  /// Reads the scenario tree exactly like the scenario app (strict; `name` is the file's path: it
  /// names the file in errors, relative paths resolve against its folder). A tree parsed from the
  /// file and edited (a sweep setting, editedTree) is read as it is, no text round trip
  /// (io::ConfigNode::fromTree), so errors name the file's lines. Throws core::InvalidInput.
  virtual std::unique_ptr<ScenarioInstance> load(const YAML::Node& scenario, const std::string& name,
                                                 const AdapterOptions& options) const = 0;
  /// The same from a config parsed once (io::ConfigNode, its keys not yet read; its file name names
  /// the file in errors): sessions load their scenario this way, so the text is parsed once. The
  /// default hands the tree to load(); an adapter whose reader takes a ConfigNode reads it directly.
  virtual std::unique_ptr<ScenarioInstance> loadConfig(const io::ConfigNode& config, const AdapterOptions& options) const;
};

/// The adapters a build has, by name.
class AdapterRegistry {
public:
  /// Adds an adapter; throws core::InvalidInput when its name is taken.
  void add(std::unique_ptr<ScenarioAdapter> adapter);
  /// Throws core::InvalidInput listing the registered names when `name` is unknown.
  const ScenarioAdapter& get(const std::string& name) const;
  /// True when an adapter has this name.
  bool has(const std::string& name) const;
  /// The adapters' names, in registration order.
  std::vector<std::string> names() const;

private:
  std::vector<std::unique_ptr<ScenarioAdapter>> adapters_;
};

/// Every adapter compiled into this build (generated registration, see CMakeLists.txt).
AdapterRegistry makeBuiltinAdapters();

/// Reads the options declared by `adapter` from a config node (strict: unknown keys are left for
/// the caller's finish()); defaults for absent ones. A value of the wrong type or out of its range
/// is refused naming the node's file, line and key.
AdapterOptions readAdapterOptions(const ScenarioAdapter& adapter, const io::ConfigNode* node);

/// Every option of `declared`: the `given` value where there is one, else the default. Throws
/// core::InvalidInput naming `adapter` and the option for a name not declared or a value the
/// option does not accept (AdapterOption::accepts).
AdapterOptions checkedOptions(const std::vector<AdapterOption>& declared, const AdapterOptions& given,
                              const std::string& adapter);

/// The option's value as a number (throws core::InvalidInput naming the option).
double optionNumber(const AdapterOptions& o, const std::string& name);
/// The option's value as text (throws core::InvalidInput naming a missing option).
std::string optionText(const AdapterOptions& o, const std::string& name);

}  // namespace viewline::tuning
