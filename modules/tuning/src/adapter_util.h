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
//  - makeAdapter / makeConfigAdapter: a ScenarioAdapter from its description (name, metrics,
//    options) and a loader, so each adapter file holds only what is specific to its scenario.

#include <Eigen/Core>
#include <cstddef>
#include <functional>
#include <memory>
#include <string>
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

/// A replay's result from its accumulated cost, terms and NIS.
ReplayResult replayResult(double cost, std::size_t terms, const Consistency& nis, std::shared_ptr<RunSeries> series);

/// What the tuning tool shows and checks about an adapter (see ScenarioAdapter).
struct AdapterInfo {
  std::string name;
  std::string description;
  std::string app;             ///< the scenario app that reads the same config, e.g. "table_ball_balancing"
  std::string app_arguments;   ///< what follows "--config <path>" in the ready-to-use command line
  std::string default_metric;
  bool minimize = true;
  std::vector<std::string> metrics;
  std::vector<AdapterOption> options;
};
/// Parses the scenario config (YAML text, `name` names the file in errors) with the scenario's own
/// loader and returns the instance; throws core::InvalidInput.
using AdapterLoader =
    std::function<std::unique_ptr<ScenarioInstance>(const std::string& yaml, const std::string& name, const AdapterOptions&)>;
std::unique_ptr<ScenarioAdapter> makeAdapter(AdapterInfo info, AdapterLoader load);
/// The same with a loader that reads the parsed config (keys not yet read; the loader reads each,
/// calls finish() and validates once): a session that parsed the file hands it over as it is.
using ConfigLoader = std::function<std::unique_ptr<ScenarioInstance>(const io::ConfigNode& config, const AdapterOptions&)>;
std::unique_ptr<ScenarioAdapter> makeConfigAdapter(AdapterInfo info, ConfigLoader load);

/// The scenario tree for the scenario's own loader: `name` is the config file's path, so its
/// relative paths (`rig: ../calib/rigs/<rig>`) resolve against the file's folder, as in the app.
io::ConfigNode scenarioConfig(const std::string& yaml, const std::string& name);

}  // namespace viewline::tuning::detail
