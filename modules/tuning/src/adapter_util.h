#pragma once
// Pieces shared by the scenario adapters (internal to modules/tuning):
//  - CsvTable: reads a CSV the scenario apps' --log writes (header row, named columns), with
//    errors that name the file and line;
//  - TempLogDir: a private log folder for one run (scenarios that expose their filter only
//    through their --log CSV), removed on destruction;
//  - innovationCost: the −2 log-likelihood term of one innovation under the outlier mixture of
//    autotune.h;
//  - viewlineInnovation: the innovation of an image measurement for a tracking::ViewlineTracker,
//    read from the tracker's own update (or, for a tracker seen from outside, formed as it will);
//  - InnovationTally, addNis, TrackCurves, newSeries: the innovation cost, NIS/NEES and plot
//    curves every adapter accumulates;
//  - OptionTable / makeAdapter: a ScenarioAdapter from its description (name, metrics), its
//    options declared with type, range and default (checked in one place) and a loader, so each
//    adapter file holds only what is specific to its scenario.

#include <Eigen/Core>
#include <cstddef>
#include <cstdint>
#include <cstdlib>
#include <functional>
#include <limits>
#include <memory>
#include <string>
#include <utility>
#include <vector>

#include "viewline/core/camera.h"
#include "viewline/core/error.h"
#include "viewline/io/config.h"
#include "viewline/tracking/tracker.h"
#include "viewline/tuning/scenario.h"

namespace viewline::tuning::detail {

/// True when an X display is configured (DISPLAY set): the scenarios' live views need one.
bool xDisplayAvailable();

/// Splits one CSV line (fields may be "quoted"; no embedded newlines).
std::vector<std::string> splitCsvLine(const std::string& line);

class CsvTable {
public:
  /// Reads `path`; `what` says what file was expected (in the error when it cannot be read).
  static CsvTable read(const std::string& path, const std::string& what);
  std::size_t col(const std::string& name) const;  ///< throws InvalidInput naming the file
  std::size_t rows() const { return rows_.size(); }
  const std::string& text(std::size_t row, std::size_t col) const { return rows_[row][col]; }
  double number(std::size_t row, std::size_t col) const;  ///< throws InvalidInput naming file:line
  std::string where(std::size_t row) const { return path_ + ":" + std::to_string(lines_[row]); }

private:
  std::string path_;
  std::vector<std::string> header_;
  std::vector<std::vector<std::string>> rows_;
  std::vector<std::size_t> lines_;
};

/// A fresh folder under the system temporary directory, unique per process and call; removed
/// (with its contents) on destruction.
class TempLogDir {
public:
  TempLogDir();
  ~TempLogDir();
  TempLogDir(const TempLogDir&) = delete;
  TempLogDir& operator=(const TempLogDir&) = delete;
  const std::string& dir() const { return dir_; }
  std::string file(const std::string& name) const;

private:
  std::string dir_;
};

/// −2 log[(1 − ε) N(d; 0, S) + ε u] for an innovation of dimension `dim` with NIS dᵀS⁻¹d and
/// log det S (ε = 0: the plain Gaussian term), by log-sum-exp. `log_u` is the log density of a
/// gross outlier in innovation space (unused when ε = 0).
double innovationCost(double nis, double log_det_S, int dim, double eps, double log_u);

/// The innovation of an image measurement for a ViewlineTracker, formed exactly as the tracker
/// forms it (tracking::viewlineRows at the predicted state x̂(t|t−)):
///   d = y − C x̂,  S = R2 + C P Cᵀ,  NIS = dᵀ S⁻¹ d (2 dof);
/// `log_u` is the log density of a gross outlier uniform over the W x H image, mapped to the two
/// rows (|det| = sqrt(det R2) / σ², viewline.h): u = σ² / (W H sqrt(det R2)).
struct ViewlineInnovation {
  bool valid = false;
  Eigen::Vector2d d = Eigen::Vector2d::Zero();
  Eigen::Matrix2d S = Eigen::Matrix2d::Identity();
  double nis = 0.0;
  double log_u = 0.0;
};
/// Valid only when the tracker is initialised, has fused at least `burn_in` images in its track
/// and the measurement is not older than its state (what the tracker would fuse directly).
ViewlineInnovation viewlineInnovation(const tracking::ViewlineTracker& tracker, const std::vector<core::Camera>& cameras,
                                      const tracking::TrackerConfig& config, const tracking::ImageMeasurement& m,
                                      int burn_in);

/// The same read from the tracker's own update of the image (ViewlineTracker::lastUpdate()):
/// valid when the image was tested against a live track with at least `burn_in` fused images.
ViewlineInnovation viewlineInnovation(const tracking::ImageUpdate& update, const core::Camera& camera, int burn_in);

/// The checked input of a ScenarioInstance::replay: the data were recorded by this adapter (type
/// D) and `noise` holds `count` values; throws core::InvalidInput naming `scenario` otherwise.
template <class D>
const D& replayInput(const ReplayData& data, const std::vector<double>& noise, std::size_t count,
                     const std::string& scenario) {
  const auto* d = dynamic_cast<const D*>(&data);
  if (d == nullptr) throw core::InvalidInput(scenario + " replay: data of another scenario");
  if (noise.size() != count)
    throw core::InvalidInput(scenario + " replay: expected " + std::to_string(count) + " noise values");
  return *d;
}

/// Replay data of an adapter: the recorded items (runs or flights, each with its measurements and
/// time stamps) and where they came from.
template <class Item>
class Recording final : public ReplayData {
public:
  /// `items_name` ("dart flights") and `measurements_name` ("detections") word describe();
  /// `count` gives the measurements of one item.
  Recording(std::string items_name, std::string measurements_name, std::size_t (*count)(const Item&))
      : items_name_(std::move(items_name)), measurements_name_(std::move(measurements_name)), count_(count) {}
  std::vector<Item> items;  ///< in recording order
  std::string source;       ///< where they came from (a log file, or "live: ...")
  std::size_t measurements() const override {
    std::size_t n = 0;
    for (const Item& i : items) n += count_(i);
    return n;
  }
  std::string describe() const override {
    return std::to_string(items.size()) + " " + items_name_ + ", " + std::to_string(measurements()) + " " +
           measurements_name_ + " (" + source + ")";
  }

private:
  std::string items_name_, measurements_name_;
  std::size_t (*count_)(const Item&);
};

/// "live: <runs> run(s) from seed <seed>", the source of a recording made by running the scenario.
std::string liveSource(int runs, std::uint64_t seed);

/// True when the run writes CSV logs (RunOptions::log set and enabled).
bool logging(const RunOptions& ro);
/// The run's CSV stream `name` with this header when it writes logs, else null.
io::CsvWriter* logStream(const RunOptions& ro, const std::string& name, const std::vector<std::string>& header);

/// What every scenario instance holds: its config (as its reader validated it, with what the
/// adapter options change) and its adapter options.
template <class Config, class Options>
class ConfiguredInstance : public ScenarioInstance {
protected:
  /// Keeps the config and the options.
  ConfiguredInstance(Config cfg, Options opt) : cfg_(std::move(cfg)), opt_(std::move(opt)) {}
  Config cfg_;    ///< the scenario config of every run
  Options opt_;   ///< the adapter options
};

/// Adds one NIS sample (`dof` degrees of freedom) to `nis` and, when `series` is given, to its NIS
/// curve at `x` (the sample's time, or its number in the run).
void addNis(Consistency& nis, double value, double dof, double x, RunSeries* series);

/// What a pass over one filter's innovations accumulates: the innovation cost of autotune.h and the
/// NIS and NEES samples.
struct InnovationTally {
  double cost = 0.0;      ///< Σ of the innovations' −2 log-likelihood terms (innovationCost)
  std::size_t terms = 0;  ///< innovations in `cost`
  Consistency nis;        ///< NIS samples
  Consistency nees;       ///< NEES samples
  /// One innovation's term in the cost (arguments as innovationCost).
  void addCost(double nis_value, double log_det_S, int dim, double eps, double log_u);
  /// A replay's result from the cost, terms and NIS, with the replay's curves.
  ReplayResult replayResult(std::shared_ptr<RunSeries> series) const;
};

/// The axis labels of a scenario's run plots and the dof of its NIS.
struct SeriesLabels {
  std::string time = "t [s]";        ///< x axis of the error curves
  std::string error;                 ///< y axis of the error curves, with units
  std::string nis_x = "t [s]";       ///< x axis of the NIS samples
  double nis_dof = 2.0;              ///< degrees of freedom of one NIS sample
  std::string traj_x, traj_y;        ///< top-view axes, with units
};
/// A new RunSeries with these labels when `wanted` (RunOptions::series), else null.
std::shared_ptr<RunSeries> newSeries(bool wanted, const SeriesLabels& labels);

/// A replay (ScenarioInstance::replay) of recorded data: checks it (replayInput: a Recording<Item>,
/// `count` noise values), then `pass(recording, tally, series)` replays it into a fresh Tally (an
/// InnovationTally or one that extends it) and, when `want_series`, a RunSeries with `labels`.
template <class Item, class Tally, class Pass>
ReplayResult replayRecording(const ReplayData& data, const std::vector<double>& noise, std::size_t count,
                             const std::string& scenario, bool want_series, const SeriesLabels& labels, Pass pass) {
  const Recording<Item>& recording = replayInput<Recording<Item>>(data, noise, count, scenario);
  Tally tally;
  const std::shared_ptr<RunSeries> series = newSeries(want_series, labels);
  pass(recording, tally, series.get());
  return tally.replayResult(series);
}

/// The error and top-view curves of one track (or run) while they are filled.
struct TrackCurves {
  Curve error{"error", {}, {}};            ///< error over time
  Curve truth{"truth", {}, {}};            ///< true path (top view)
  Curve estimate{"estimate", {}, {}};      ///< estimated path (top view)
  Curve prediction{"prediction", {}, {}};  ///< predicted path (top view)
  /// Appends the curves that have points to `series` (the plots draw nothing for an empty one).
  void moveInto(RunSeries& series);
};

/// What the tuning tool shows and checks about an adapter (see ScenarioAdapter).
struct AdapterInfo {
  std::string name;            ///< the scenario's name in sweep files and on the command line
  std::string description;     ///< one line for the help
  std::string app;             ///< the scenario app that reads the same config, e.g. "table_ball_balancing"
  std::string app_arguments;   ///< what follows "--config <path>" in the ready-to-use command line
  std::string default_metric;  ///< the metric a sweep optimises unless it names one
  bool minimize = true;        ///< direction of the default metric
  std::vector<std::string> metrics;     ///< every metric a run reports
  std::vector<AdapterOption> options = {};  ///< declared options (type, range, default)
};

/// Reads the scenario config (a ConfigNode, keys not yet read: the scenario's own reader reads each
/// key, calls finish() and validates once) with the adapter's options, checked against their
/// declarations; returns the instance; throws core::InvalidInput naming the file.
using ConfigLoader = std::function<std::unique_ptr<ScenarioInstance>(const io::ConfigNode& config, const AdapterOptions&)>;
/// A ScenarioAdapter from its description and loader. A tree edited by the caller (a sweep setting)
/// is read as it is (io::ConfigNode::fromTree: no text round trip, messages keep the file's lines).
std::unique_ptr<ScenarioAdapter> makeConfigAdapter(AdapterInfo info, ConfigLoader load);

/// No bound: the upper end of an option's range that has none.
inline constexpr double kUnbounded = std::numeric_limits<double>::infinity();

/// The options of an adapter, each declared once with its type, range, default and help line
/// (an AdapterOption) and bound to the field of the adapter's option struct O that holds its value.
template <class O>
class OptionTable {
public:
  /// A number in [min, max] (units in `doc`) stored in `field`.
  OptionTable& number(const std::string& name, double O::*field, const std::string& default_value, double min,
                      double max, const std::string& doc) {
    add({name, default_value, {}, doc, min, max, false}, [field](O& o, const std::string& v) { o.*field = toNumber(v); });
    return *this;
  }
  /// A whole number in [min, max] stored in `field` (an integer type that holds the range).
  template <class I>
  OptionTable& integer(const std::string& name, I O::*field, const std::string& default_value, double min, double max,
                       const std::string& doc) {
    add({name, default_value, {}, doc, min, max, true},
        [field](O& o, const std::string& v) { o.*field = static_cast<I>(toNumber(v)); });
    return *this;
  }
  /// One of the words of `choices`; the value paired with the word is stored in `field`.
  template <class T>
  OptionTable& choice(const std::string& name, T O::*field, const std::string& default_value,
                      const std::vector<std::pair<std::string, T>>& choices, const std::string& doc) {
    std::vector<std::string> words;
    for (const auto& c : choices) words.push_back(c.first);
    add({name, default_value, words, doc}, [field, choices](O& o, const std::string& v) {
      for (const auto& c : choices)
        if (c.first == v) o.*field = c.second;
    });
    return *this;
  }
  /// The declarations, for AdapterInfo::options.
  const std::vector<AdapterOption>& options() const { return options_; }
  /// The option struct from checked options (checkedOptions(options(), ...): every name present).
  O read(const AdapterOptions& checked) const {
    O o{};
    for (std::size_t i = 0; i < options_.size(); ++i) store_[i](o, checked.at(options_[i].name));
    return o;
  }

private:
  static double toNumber(const std::string& v) { return std::strtod(v.c_str(), nullptr); }
  void add(AdapterOption option, std::function<void(O&, const std::string&)> store) {
    options_.push_back(std::move(option));
    store_.push_back(std::move(store));
  }
  std::vector<AdapterOption> options_;
  std::vector<std::function<void(O&, const std::string&)>> store_;
};

/// An adapter whose options are `table`: `load(config, options)` receives the option struct read
/// from the checked options (range errors are the table's, the same for every adapter).
template <class O, class Load>
std::unique_ptr<ScenarioAdapter> makeAdapter(AdapterInfo info, OptionTable<O> table, Load load) {
  info.options = table.options();
  return makeConfigAdapter(std::move(info), [table = std::move(table), load = std::move(load)](
                                                const io::ConfigNode& config, const AdapterOptions& checked) {
    return std::unique_ptr<ScenarioInstance>(load(config, table.read(checked)));
  });
}

/// The scenario tree for the scenario's own loader, parsed from text: `name` is the config file's
/// path, so its relative paths (`rig: ../calib/rigs/<rig>`) resolve against the file's folder, as
/// in the app.
io::ConfigNode scenarioConfig(const std::string& yaml, const std::string& name);

/// The same for a tree already parsed (and perhaps edited): read as it is (io::ConfigNode::fromTree).
io::ConfigNode scenarioConfig(const YAML::Node& tree, const std::string& name);

}  // namespace viewline::tuning::detail
