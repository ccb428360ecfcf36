#include "adapter_util.h"

#include <Eigen/Cholesky>
#include <algorithm>
#include <atomic>
#include <cmath>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <unistd.h>

#include "viewline/core/error.h"
#include "viewline/tracking/viewline.h"

namespace viewline::tuning::detail {

namespace fs = std::filesystem;

bool xDisplayAvailable() {
  const char* d = std::getenv("DISPLAY");
  return d != nullptr && *d != '\0';
}

std::vector<std::string> splitCsvLine(const std::string& line) {
  std::vector<std::string> out;
  std::string cur;
  bool quoted = false;
  for (char c : line) {
    if (c == '"') {
      quoted = !quoted;
    } else if (c == ',' && !quoted) {
      out.push_back(cur);
      cur.clear();
    } else if (c != '\r') {
      cur += c;
    }
  }
  out.push_back(cur);
  return out;
}

CsvTable CsvTable::read(const std::string& path, const std::string& what) {
  std::ifstream in(path);
  if (!in) throw core::InvalidInput(path + ": cannot read (expected " + what + ")");
  CsvTable t;
  t.path_ = path;
  std::string line;
  if (!std::getline(in, line)) throw core::InvalidInput(path + ": empty (expected " + what + ")");
  t.header_ = splitCsvLine(line);
  std::size_t n = 1;
  while (std::getline(in, line)) {
    ++n;
    if (line.empty() || line == "\r") continue;
    std::vector<std::string> f = splitCsvLine(line);
    if (f.size() != t.header_.size()) throw core::InvalidInput(path + ":" + std::to_string(n) + ": wrong number of columns");
    t.rows_.push_back(std::move(f));
    t.lines_.push_back(n);
  }
  return t;
}

std::size_t CsvTable::col(const std::string& name) const {
  const auto it = std::find(header_.begin(), header_.end(), name);
  if (it == header_.end()) throw core::InvalidInput(path_ + ": missing column '" + name + "'");
  return static_cast<std::size_t>(it - header_.begin());
}

double CsvTable::number(std::size_t row, std::size_t c) const {
  const std::string& s = rows_[row][c];
  char* end = nullptr;
  const double v = std::strtod(s.c_str(), &end);
  if (s.empty() || end == s.c_str() || *end != '\0')
    throw core::InvalidInput(where(row) + ": column '" + header_[c] + "': expected a number, got '" + s + "'");
  return v;
}

TempLogDir::TempLogDir() {
  static std::atomic<unsigned> counter{0};
  dir_ = (fs::temp_directory_path() /
          ("viewline_tune_" + std::to_string(::getpid()) + "_" + std::to_string(counter.fetch_add(1))))
             .string();
}

TempLogDir::~TempLogDir() {
  std::error_code ec;
  fs::remove_all(dir_, ec);
}

std::string TempLogDir::file(const std::string& name) const { return (fs::path(dir_) / name).string(); }

double innovationCost(double nis, double log_det_S, int dim, double eps, double log_u) {
  constexpr double kLog2Pi = 1.8378770664093454836;
  const double log_gauss = -0.5 * nis - 0.5 * dim * kLog2Pi - 0.5 * log_det_S;
  double lp = log_gauss;
  if (eps > 0.0) {
    const double l1 = std::log1p(-eps) + log_gauss, l2 = std::log(eps) + log_u;
    const double mx = std::max(l1, l2);
    lp = mx + std::log(std::exp(l1 - mx) + std::exp(l2 - mx));
  }
  return -2.0 * lp;
}

ViewlineInnovation viewlineInnovation(const tracking::ViewlineTracker& tracker, const std::vector<core::Camera>& cameras,
                                      const tracking::TrackerConfig& config, const tracking::ImageMeasurement& m,
                                      int burn_in) {
  ViewlineInnovation r;
  if (!tracker.initialised() || tracker.trackState().fused_in_track < burn_in || m.t < tracker.state().t()) return r;
  if (m.camera >= cameras.size()) return r;
  try {
    const estimation::StateEstimate pred = tracker.predictAt(m.t);
    const tracking::Vector6 x = pred.x();
    const tracking::Matrix6 P = pred.P();
    const core::Camera& cam = cameras[m.camera];
    const tracking::ViewlineRows rows = tracking::viewlineRows(cam, m.uv, m.sigma_px, x, P, 0.0, config.model,
                                                               config.min_depth, config.depth_variance_in_noise);
    r.d = rows.y - rows.C * x;
    r.S = rows.R + rows.C * P * rows.C.transpose();
    const Eigen::LLT<Eigen::Matrix2d> llt(r.S);
    if (llt.info() != Eigen::Success) return r;
    r.nis = r.d.dot(llt.solve(r.d));
    r.log_u = std::log(m.sigma_px * m.sigma_px /
                       (static_cast<double>(cam.width) * cam.height * std::sqrt(rows.R.determinant())));
    r.valid = std::isfinite(r.nis) && std::isfinite(r.log_u);
  } catch (const core::Error&) {
    r.valid = false;
  }
  return r;
}

ViewlineInnovation viewlineInnovation(const tracking::ImageUpdate& update, const core::Camera& camera, int burn_in) {
  ViewlineInnovation r;
  if (update.decision == tracking::GateDecision::Start || update.fused_before < burn_in) return r;
  r.d = update.innovation;
  r.S = update.S;
  r.nis = update.nis;
  const double sigma = update.m.sigma_px;
  r.log_u = std::log(sigma * sigma / (static_cast<double>(camera.width) * camera.height * std::sqrt(update.R.determinant())));
  r.valid = std::isfinite(r.nis) && std::isfinite(r.log_u);
  return r;
}

std::string liveSource(int runs, std::uint64_t seed) {
  return "live: " + std::to_string(runs) + " run(s) from seed " + std::to_string(seed);
}

bool logging(const RunOptions& ro) { return ro.log != nullptr && ro.log->enabled(); }

io::CsvWriter* logStream(const RunOptions& ro, const std::string& name, const std::vector<std::string>& header) {
  return logging(ro) ? &ro.log->stream(name, header) : nullptr;
}

void addNis(Consistency& nis, double value, double dof, double x, RunSeries* series) {
  nis.add(value, dof);
  if (series == nullptr) return;
  series->nis_t.push_back(x);
  series->nis.push_back(value);
}

void InnovationTally::addCost(double nis_value, double log_det_S, int dim, double eps, double log_u) {
  cost += innovationCost(nis_value, log_det_S, dim, eps, log_u);
  ++terms;
}

ReplayResult InnovationTally::replayResult(std::shared_ptr<RunSeries> series) const {
  ReplayResult r;
  r.cost = cost;
  r.terms = terms;
  r.nis = nis;
  r.series = std::move(series);
  return r;
}

std::shared_ptr<RunSeries> newSeries(bool wanted, const SeriesLabels& labels) {
  if (!wanted) return nullptr;
  auto s = std::make_shared<RunSeries>();
  s->time_label = labels.time;
  s->error_label = labels.error;
  s->nis_x_label = labels.nis_x;
  s->nis_dof = labels.nis_dof;
  s->traj_x_label = labels.traj_x;
  s->traj_y_label = labels.traj_y;
  return s;
}

void TrackCurves::moveInto(RunSeries& series) {
  for (auto [curve, into] : {std::pair{&error, &series.error}, std::pair{&truth, &series.truth},
                             std::pair{&estimate, &series.estimate}, std::pair{&prediction, &series.prediction}})
    if (!curve->x.empty()) into->push_back(std::move(*curve));
}

namespace {

class InfoAdapter final : public ScenarioAdapter {
public:
  InfoAdapter(AdapterInfo info, ConfigLoader load) : info_(std::move(info)), load_(std::move(load)) {}
  std::string name() const override { return info_.name; }
  std::string description() const override { return info_.description; }
  std::string appCommand(const std::string& config_path) const override {
    return info_.app + " --config " + config_path + (info_.app_arguments.empty() ? "" : " " + info_.app_arguments);
  }
  std::string defaultMetric() const override { return info_.default_metric; }
  bool defaultMinimize() const override { return info_.minimize; }
  std::vector<std::string> metricNames() const override { return info_.metrics; }
  std::vector<AdapterOption> options() const override { return info_.options; }
  std::unique_ptr<ScenarioInstance> load(const YAML::Node& scenario, const std::string& name,
                                         const AdapterOptions& options) const override {
    return loadConfig(scenarioConfig(scenario, name), options);
  }
  std::unique_ptr<ScenarioInstance> loadConfig(const io::ConfigNode& config, const AdapterOptions& options) const override {
    return load_(config, checkedOptions(info_.options, options, info_.name));
  }

private:
  AdapterInfo info_;
  ConfigLoader load_;
};

}  // namespace

std::unique_ptr<ScenarioAdapter> makeConfigAdapter(AdapterInfo info, ConfigLoader load) {
  return std::make_unique<InfoAdapter>(std::move(info), std::move(load));
}

io::ConfigNode scenarioConfig(const std::string& yaml, const std::string& name) {
  return io::ConfigNode::fromString(yaml, name, std::filesystem::path(name).parent_path().string());
}

io::ConfigNode scenarioConfig(const YAML::Node& tree, const std::string& name) {
  return io::ConfigNode::fromTree(tree, name, std::filesystem::path(name).parent_path().string());
}

}  // namespace viewline::tuning::detail
