// Dart scenario adapter ([L] §VI): runs flights of the measurement-level dart scenario through the
// ViewlineTracker in-process (scenarios::simulateDartFlight + ViewlineTracker), with the scenario
// config read by the scenario's own reader (scenarios/dart/config.h), so any config the tuning
// tool accepts or writes is one dart_tracking reads.
//
// One run = `flights` throws (adapter option), flight f drawn from deriveSeed(seed, f); one tracker
// per run, reset between flights. The innovations are the tracker's own (ViewlineTracker::
// lastUpdate(): the two viewline rows of the image at the predicted state x̂(t|t−)):
//   d = y − C x̂(t|t−),  S = R2 + C P Cᵀ  (2 rows),  NIS = dᵀ S⁻¹ d (2 dof),
// read as the tracker formed them, never recomputed.
// NIS samples: fused, non-seed measurements once the track has `burn_in` fused images (the prior
// dominates before). NEES: one 6-dof sample per flight, after the measurement of index
// `experiments.nees_index` (independent samples, the dart scenario's convention).
//
// Noise parameters: process q = tracker.accel_psd (m²/s³) and measurement σ = the pixel noise
// the tracker assumes (px). In the scenario file one key, pixel_noise_px, sets both the simulated
// detector noise and what the tracker assumes (the tracker reads each measurement's sigma_px); the
// adapter option `assumed_pixel_noise_px` (> 0) makes the tracker assume another value while the
// simulation keeps the file's noise — that is how a session starts "10x off". The tuned σ is
// written to pixel_noise_px: for a real rig that is the detector noise the tracker should assume.
// A recording (dart_tracking --record DIR) holds the detections themselves (the dart scenario
// renders no frames): each run's flight of experiment `log_experiment` is replayed as recorded,
// its truth and outlier flags not read (NIS only).
//
// Outlier density for the likelihood mixture (autotune.h): a gross outlier is uniform over the
// W x H image; the two rows map pixel errors to row residuals with |det| = sqrt(det R2) / σ²
// (viewline.h: R2 = E[Z²] σ² D J Jᵀ D), so its density in innovation space is
// u = σ² / (W H sqrt(det R2)) (independent of σ).

#include <Eigen/LU>
#include <algorithm>
#include <cmath>
#include <filesystem>
#include <limits>
#include <map>
#include <optional>

#include "adapter_util.h"
#include "viewline/core/error.h"
#include "viewline/core/random.h"
#include "viewline/runtime/recording.h"
#include "viewline/estimation/consistency.h"
#include "viewline/scenarios/dart/config.h"
#include "viewline/scenarios/dart/loop.h"
#include "viewline/scenarios/dart/recording.h"
#include "viewline/scenarios/dart/world.h"
#include "viewline/tracking/tracker.h"
#include "viewline/tuning/scenario.h"

namespace viewline::tuning {

namespace {

using scenarios::DartClockMode;
using scenarios::DartDetection;
using scenarios::DartScenarioConfig;
using tracking::ImageMeasurement;

/// The adapter options (declared with their defaults and ranges in registerDartAdapter).
struct DartOptions {
  int flights;            ///< throws per run
  DartClockMode clock;
  bool outliers;          ///< gross outliers at the config's outlier_rate
  double assumed_sigma;   ///< px; <= 0: the config's pixel_noise_px
  int burn_in;            ///< fused images of a track before its innovations count
  std::string log_experiment;
};

/// The adapter options: type, range, default and help of each, bound to its field.
detail::OptionTable<DartOptions> dartOptions() {
  detail::OptionTable<DartOptions> options;
  options.integer("flights", &DartOptions::flights, "50", 1, 1e6, "throws per run")
      .choice<DartClockMode>("clock", &DartOptions::clock, "free_running",
                             {{"free_running", DartClockMode::FreeRunning}, {"alternating", DartClockMode::Alternating}},
                             "free-running unsynchronised cameras (the full scenario) or alternating 100 Hz steps ([L] VI.A)")
      .choice<bool>("outliers", &DartOptions::outliers, "config", {{"config", true}, {"none", false}},
                    "gross outliers at the config's outlier_rate, or none")
      .number("assumed_pixel_noise_px", &DartOptions::assumed_sigma, "0", -detail::kUnbounded,
              detail::kUnbounded, "> 0: pixel noise the tracker assumes (simulation keeps pixel_noise_px)")
      .integer("burn_in", &DartOptions::burn_in, "4", 1, 1e6,
               "fused images of a track before its innovations count in NIS / likelihood")
      .choice<std::string>("log_experiment", &DartOptions::log_experiment, "A_alternating",
                           {{"A_alternating", "A_alternating"}, {"D_scenario", "D_scenario"}},
                           "which experiment of a dart_tracking --log or --record folder the auto-tuner replays");
  return options;
}

const detail::SeriesLabels kLabels{"time since the first detection [s]", "position error |p_hat - p| [m]",
                                   "innovation number (in the run)", 2.0, "world x (towards the board) [m]", "world y [m]"};

struct Flight {
  std::vector<DartDetection> dets;  ///< truth valid only when has_truth
  bool has_truth = true;
};

using DartReplayData = detail::Recording<Flight>;

std::size_t detections(const Flight& f) { return f.dets.size(); }

std::unique_ptr<DartReplayData> newReplayData() {
  return std::make_unique<DartReplayData>("dart flights", "detections", &detections);
}

/// Everything one pass over flights accumulates: the innovation tally and the scenario's metrics.
struct Accum : detail::InnovationTally {
  double sq_err = 0.0;
  std::size_t err_n = 0;
  double final_err = 0.0, pred_err = 0.0;
  std::size_t flights = 0, pred_n = 0;
  std::size_t outliers = 0, outliers_rejected = 0, inliers = 0, inliers_rejected = 0;
  std::size_t restarts = 0;
  std::size_t sample = 0;
};

class DartInstance final : public detail::ConfiguredInstance<DartScenarioConfig, DartOptions> {
public:
  DartInstance(DartScenarioConfig cfg, DartOptions opt)
      : ConfiguredInstance(std::move(cfg), std::move(opt)), cams_(scenarios::makeDartCameras(cfg_)) {}

  double confidence() const override { return cfg_.confidence; }
  double sigma() const { return opt_.assumed_sigma > 0.0 ? opt_.assumed_sigma : cfg_.pixel_noise_px; }

  RunResult run(std::uint64_t seed, const RunOptions& ro) const override {
    RunResult r;
    r.seed = seed;
    const std::shared_ptr<RunSeries> series = detail::newSeries(ro.series, kLabels);
    io::CsvWriter* det_csv = detail::logStream(ro, "detections", scenarios::dartLogColumns());  // as dart_tracking --log
    io::CsvWriter* inn_csv = nullptr;
    if (det_csv != nullptr) {
      inn_csv = &ro.log->stream("innovations", {"flight", "id", "camera", "t", "d0", "d1", "S00", "S01", "S11", "nis",
                                                "fused", "in_statistics"});
    }
    Accum a;
    tracking::ViewlineTracker tracker(cams_, trackerConfig(cfg_.tracker.model.accel_psd));
    for (int f = 0; f < opt_.flights; ++f) {
      core::Rng rng = core::makeRng(core::deriveSeed(seed, static_cast<std::uint64_t>(f)));
      Flight fl;
      fl.dets = simulate(rng);
      processFlight(tracker, fl, f, sigma(), 0.0, a, series.get(), det_csv, inn_csv, ro);
      if (ro.progress) ro.progress(static_cast<double>(f + 1) / opt_.flights);
    }
    r.nees = a.nees;
    r.nis = a.nis;
    r.metrics["rmse_position_m"] = a.err_n ? std::sqrt(a.sq_err / static_cast<double>(a.err_n)) : std::nan("");
    r.metrics["final_error_m"] = a.flights ? a.final_err / static_cast<double>(a.flights) : std::nan("");
    r.metrics["prediction_error_m"] = a.pred_n ? a.pred_err / static_cast<double>(a.pred_n) : std::nan("");
    r.metrics["nees_mean"] = a.nees.mean();
    r.metrics["nis_mean"] = a.nis.mean();
    r.metrics["outlier_rejected_fraction"] =
        a.outliers ? static_cast<double>(a.outliers_rejected) / static_cast<double>(a.outliers) : std::nan("");
    r.metrics["inlier_rejected_fraction"] =
        a.inliers ? static_cast<double>(a.inliers_rejected) / static_cast<double>(a.inliers) : std::nan("");
    r.metrics["restarts_per_flight"] = static_cast<double>(a.restarts) / std::max(1, opt_.flights);
    r.verdict = combinedVerdict(r.nees, r.nis, cfg_.confidence);
    r.series = series;
    return r;
  }

  std::vector<NoiseParameter> noiseParameters() const override {
    return {{"process", "q", "m^2/s^3", "tracker.accel_psd",
             "white-acceleration density of the tracker's ballistic model", cfg_.tracker.model.accel_psd},
            {"measurement", "sigma_px", "px", "pixel_noise_px", "pixel noise std the tracker assumes", sigma()}};
  }

  std::unique_ptr<ReplayData> record(std::uint64_t seed, int runs) const override {
    auto d = newReplayData();
    for (int run = 0; run < runs; ++run) {
      const std::uint64_t s = core::deriveSeed(seed, static_cast<std::uint64_t>(run));
      for (int f = 0; f < opt_.flights; ++f) {
        core::Rng rng = core::makeRng(core::deriveSeed(s, static_cast<std::uint64_t>(f)));
        Flight fl;
        fl.dets = simulate(rng);
        d->items.push_back(std::move(fl));
      }
    }
    d->source = detail::liveSource(runs, seed);
    return d;
  }

  std::unique_ptr<ReplayData> loadLog(const std::string& dir) const override {
    const std::string path = (std::filesystem::path(dir) / "detections.csv").string();
    const detail::CsvTable csv = detail::CsvTable::read(path, "the detections.csv of dart_tracking --log");
    const std::size_t ce = csv.col("experiment"), cr = csv.col("run"), ci = csv.col("id"), cc = csv.col("camera"),
                      ct = csv.col("t"), cu = csv.col("u"), cv = csv.col("v");
    auto d = newReplayData();
    std::map<std::string, std::size_t> index;
    for (std::size_t row = 0; row < csv.rows(); ++row) {
      if (!opt_.log_experiment.empty() && csv.text(row, ce) != opt_.log_experiment) continue;
      const std::string key = csv.text(row, ce) + "/" + csv.text(row, cr);
      auto it = index.find(key);
      if (it == index.end()) {
        it = index.emplace(key, d->items.size()).first;
        d->items.emplace_back();
        d->items.back().has_truth = false;
      }
      DartDetection det;
      det.truth.setZero();
      det.m.id = static_cast<std::uint64_t>(csv.number(row, ci));
      det.m.camera = static_cast<std::size_t>(csv.number(row, cc));
      det.m.t = csv.number(row, ct);
      det.m.uv = Eigen::Vector2d(csv.number(row, cu), csv.number(row, cv));
      if (det.m.camera >= cams_.size()) throw core::InvalidInput(csv.where(row) + ": camera index beyond the config's cameras");
      d->items[it->second].dets.push_back(det);
    }
    for (auto& fl : d->items)
      std::stable_sort(fl.dets.begin(), fl.dets.end(), [](const auto& x, const auto& y) { return x.m.t < y.m.t; });
    if (d->items.empty())
      throw core::InvalidInput(path + ": no rows of experiment '" + opt_.log_experiment + "' (adapter option log_experiment)");
    d->source = path + " (" + opt_.log_experiment + ")";
    return d;
  }

  /// A dart_tracking --record folder (recording.h: session.json, run_iii.json): the dart scenario's
  /// frames are its detections, so each run's flight of experiment `log_experiment` is replayed as
  /// recorded (the tracker's input: id, camera, stamp, pixel). Its truth (the state, the outlier
  /// flag) and the recorded sigma_px are not read: NIS only, as on a rig's detections.
  std::unique_ptr<ReplayData> loadRecording(const std::string& dir) const override {
    if (!std::filesystem::exists(std::filesystem::path(dir) / "session.json"))
      throw core::InvalidInput(dir + ": not a recording (no session.json, as dart_tracking --record DIR writes)");
    const runtime::SessionRecording session = runtime::readSessionRecording(dir, "dart_tracking");
    scenarios::DartFlights flights("", dir, session.seed, session.units, "");
    core::Rng unused = core::makeRng(0);  // a replayed flight draws nothing
    auto d = newReplayData();
    for (int run = 0; run < session.units; ++run) {
      flights.beginRun(run);
      Flight fl;
      fl.has_truth = false;
      for (const DartDetection& recorded :
           flights.flight(opt_.log_experiment, cfg_, cams_, opt_.clock, 0.0, unused).detections) {
        DartDetection det;
        det.m = recorded.m;
        det.truth.setZero();
        fl.dets.push_back(det);
      }
      d->items.push_back(std::move(fl));
    }
    if (d->measurements() == 0) throw core::InvalidInput(dir + ": no detections of experiment '" + opt_.log_experiment + "'");
    d->source = "recording " + dir + " (" + opt_.log_experiment + ", " + std::to_string(session.units) + " run(s))";
    return d;
  }

  ReplayResult replay(const ReplayData& data, const std::vector<double>& noise, double outlier_prior,
                      bool want_series) const override {
    return detail::replayRecording<Flight, Accum>(
        data, noise, 2, "dart", want_series, kLabels, [&](const DartReplayData& d, Accum& a, RunSeries* series) {
          tracking::ViewlineTracker tracker(cams_, trackerConfig(noise[0]));
          for (std::size_t f = 0; f < d.items.size(); ++f)
            processFlight(tracker, d.items[f], static_cast<int>(f), noise[1], outlier_prior, a, series, nullptr, nullptr, {});
        });
  }

  std::unique_ptr<ScenarioInstance> withNoise(const std::vector<double>& noise) const override {
    if (noise.size() != 2) throw core::InvalidInput("dart: expected (q, sigma_px)");
    DartScenarioConfig c = cfg_;
    c.tracker.model.accel_psd = noise[0];
    DartOptions o = opt_;
    o.assumed_sigma = noise[1];
    return std::make_unique<DartInstance>(c, o);
  }

private:
  std::vector<DartDetection> simulate(core::Rng& rng) const {
    return scenarios::simulateDartFlight(cfg_, cams_, opt_.clock, opt_.outliers ? cfg_.outlier_rate : 0.0, rng, 1)
        .detections;
  }

  tracking::TrackerConfig trackerConfig(double q) const {
    tracking::TrackerConfig tc = cfg_.trackerConfig();
    tc.model.accel_psd = q;
    return tc;
  }

  /// One flight through `tracker` (reset first), accumulating into `a`.
  void processFlight(tracking::ViewlineTracker& tracker, const Flight& fl, int f, double sigma, double eps, Accum& a,
                     RunSeries* series, io::CsvWriter* det_csv, io::CsvWriter* inn_csv, const RunOptions& ro) const {
    if (fl.dets.empty()) return;
    tracker.reset();
    const tracking::BallisticModel& model = tracker.config().model;
    const bool keep = series != nullptr;
    const bool keep_traj = keep && f < 5;
    const bool keep_err = keep && f < 30;
    detail::TrackCurves c;
    c.error.name = "flight " + std::to_string(f);
    const double t0 = fl.dets.front().m.t;
    const std::size_t half = fl.dets.size() / 2;
    std::optional<estimation::StateEstimate> half_state;
    double last_err = std::nan("");
    for (std::size_t k = 0; k < fl.dets.size(); ++k) {
      const DartDetection& det = fl.dets[k];
      ImageMeasurement m = det.m;
      m.sigma_px = sigma;
      // Only in-order images tested against a track with `burn_in` fused images count.
      const bool in_order = !tracker.initialised() || m.t >= tracker.state().t();
      tracker.submit(m);
      const std::optional<tracking::ImageUpdate>& up = tracker.lastUpdate();
      const detail::ViewlineInnovation inn =
          up && in_order ? detail::viewlineInnovation(*up, cams_[m.camera], opt_.burn_in) : detail::ViewlineInnovation{};
      const bool have = inn.valid;
      const Eigen::Vector2d& dv = inn.d;
      const Eigen::Matrix2d& S = inn.S;
      const double nis = inn.nis;
      const auto out = tracker.outcome(m.id);
      const bool fused = out && out->fate == tracking::Fate::Fused;
      if (have) {
        a.addCost(nis, std::log(S.determinant()), 2, eps, inn.log_u);
        if (fused && !out->seed) detail::addNis(a.nis, nis, 2.0, static_cast<double>(a.sample++), series);
      }
      if (inn_csv != nullptr) {
        inn_csv->row({static_cast<double>(f), static_cast<double>(m.id), static_cast<double>(m.camera), m.t,
                      have ? dv(0) : std::nan(""), have ? dv(1) : std::nan(""), have ? S(0, 0) : std::nan(""),
                      have ? S(0, 1) : std::nan(""), have ? S(1, 1) : std::nan(""), have ? nis : std::nan(""),
                      fused ? 1.0 : 0.0, have && fused ? 1.0 : 0.0});
      }
      // Only the estimates the tracker reports (a confirmed track), as the dart scenario scores them.
      if (!tracker.confirmed()) continue;
      const estimation::StateEstimate& s = tracker.state();
      if (fl.has_truth) {
        const double e = (s.x().head<3>() - det.truth.head<3>()).norm();
        last_err = e;
        if (k >= cfg_.settled_index) {
          a.sq_err += e * e;
          ++a.err_n;
        }
        if (k == cfg_.nees_index) a.nees.add(estimation::nees(s, det.truth), 6.0);
        if (keep_err) {
          c.error.x.push_back(m.t - t0);
          c.error.y.push_back(e);
        }
        if (keep_traj) {
          c.truth.x.push_back(det.truth(0));
          c.truth.y.push_back(det.truth(1));
        }
        if (ro.live) ro.live({static_cast<double>(a.sample), e, have && fused ? nis : -1.0});
      }
      if (keep_traj) {
        c.estimate.x.push_back(s.x()(0));
        c.estimate.y.push_back(s.x()(1));
      }
      if (k == half) half_state = s;
      if (det_csv != nullptr) {
        const auto& x = s.x();
        det_csv->rowText({"tune", std::to_string(f), std::to_string(m.id), std::to_string(m.camera), std::to_string(m.t),
                          std::to_string(m.uv.x()), std::to_string(m.uv.y()), det.outlier ? "1" : "0",
                          out ? tracking::toString(out->fate) : "refused", std::to_string(det.truth[0]),
                          std::to_string(det.truth[1]), std::to_string(det.truth[2]), std::to_string(x[0]),
                          std::to_string(x[1]), std::to_string(x[2]), std::to_string(x[3]), std::to_string(x[4]),
                          std::to_string(x[5])});
      }
    }
    // Outlier decisions (final fates) and restarts.
    if (fl.has_truth) {
      for (const tracking::MeasurementOutcome& o : tracker.outcomes()) {
        const auto it = std::find_if(fl.dets.begin(), fl.dets.end(), [&](const auto& d) { return d.m.id == o.m.id; });
        if (it == fl.dets.end()) continue;
        const bool rejected = o.fate != tracking::Fate::Fused;
        if (it->outlier) {
          ++a.outliers;
          a.outliers_rejected += rejected;
        } else {
          ++a.inliers;
          a.inliers_rejected += rejected;
        }
      }
      if (std::isfinite(last_err)) {
        a.final_err += last_err;
        ++a.flights;
      }
      // Prediction from the state at mid-flight to the last detection's time.
      if (half_state && half_state->dim() == 6) {
        const tracking::Vector6 x0 = half_state->x();
        const double th = half_state->t();
        const DartDetection& last = fl.dets.back();
        if (last.m.t > th) {
          a.pred_err += (model.propagate(x0, last.m.t - th).head<3>() - last.truth.head<3>()).norm();
          ++a.pred_n;
          if (keep_traj) {
            for (std::size_t k = half; k < fl.dets.size(); ++k) {
              const tracking::Vector6 xp = model.propagate(x0, std::max(0.0, fl.dets[k].m.t - th));
              c.prediction.x.push_back(xp(0));
              c.prediction.y.push_back(xp(1));
            }
          }
        }
      }
    }
    a.restarts += static_cast<std::size_t>(tracker.trackState().restarts);
    if (series != nullptr) c.moveInto(*series);
  }

  std::vector<core::Camera> cams_;
};

}  // namespace

void registerDartAdapter(AdapterRegistry& registry) {
  registry.add(detail::makeAdapter(
      {"dart", "dart flights of [L] VI seen by the viewline tracker (measurement level; config/dart_tracking.yaml)",
       "dart_tracking", "--runs 500 --summary dart_summary.json", "rmse_position_m", true,
       {"rmse_position_m", "final_error_m", "prediction_error_m", "nees_mean", "nis_mean", "outlier_rejected_fraction",
        "inlier_rejected_fraction", "restarts_per_flight"}},
      dartOptions(), [](const io::ConfigNode& config, const DartOptions& o) {
        DartScenarioConfig cfg = scenarios::dartScenarioFromNode(config);
        if (o.clock == DartClockMode::Alternating && cfg.cameras.size() < 2)
          throw core::InvalidInput(config.fileName() + ": adapter option clock: alternating needs two cameras");
        return std::make_unique<DartInstance>(std::move(cfg), o);
      }));
}

}  // namespace viewline::tuning
