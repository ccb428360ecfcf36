// Ball-catching scenario adapter ([L] §VI.C, issue 5): runs scenarios::runBallCatching (throws
// with drag, free-running rendered cameras, blob detection, the ViewlineTracker, the catch
// planner and the robot) in-process, with the config read by the scenario's own loader
// (loadBallCatchingConfig: strict keys), so a config the tuning tool accepts or writes is one
// ball_catching reads. One run = `throws` throws (adapter option), throw i from deriveSeed(seed, i),
// exactly as ball_catching --throws N --seed S; the summary metrics are the scenario's own
// (CatchSummary). The scenario's thread pool is set to one thread: the sweep runs settings in
// parallel instead.
//
// Innovations. runBallCatching does not expose its tracker; with a log folder it writes every
// measurement it submits (throw, stamp, camera, pixel, σ_px, fused). A run therefore logs to a
// private temporary folder and the adapter re-runs a ViewlineTracker with the same cameras (the
// camera models of the frames, from the on_frame hook) and config on the same measurements in the
// same order: the innovation before each submit is formed as the tracker forms it (see
// adapter_util.h: d = y − C x̂(t|t−), S = R2 + C P Cᵀ, 2 dof). NIS: fused, non-seed measurements
// once the track has `burn_in` fused images. The log keeps 12 significant digits, so the replay
// can in principle differ from the loop; the metric replay_fate_mismatch counts measurements
// whose fused/rejected fate differs (a self-check; expected 0).
// NEES (6 dof, position and velocity) against the true flight: one sample per throw, after the
// `nees_fused`-th fused image, truth from sim::DragFlight re-integrated from the throw's release
// point and launch velocity (the scenario's own flight, deterministic RK4). Only for
// object: ball (a dart's tracked point is its flights, not the centre of mass).
//
// Noise auto-tuning is not offered: the detector's search window follows the tracker's predicted
// pixel, so which blobs are detected depends on the filter being tuned, and the measurement σ is
// per detection (blob covariance, floored by detector.sigma_px_floor) rather than one config
// value. Sweeps of tracker.accel_psd, tracker gates and detector.sigma_px_floor work.

#include <algorithm>
#include <cmath>
#include <map>
#include <optional>

#include "adapter_util.h"
#include "viewline/core/error.h"
#include "viewline/estimation/consistency.h"
#include "viewline/scenarios/ball_catching.h"
#include "viewline/scenarios/ball_catching_display.h"
#include "viewline/tuning/scenario.h"

namespace viewline::tuning {

namespace {

struct CatchOptions {
  int throws = 10;
  int burn_in = 4;
  int nees_fused = 8;
};

struct LoggedMeasurement {
  tracking::ImageMeasurement m;
  bool fused = false;
};

class CatchInstance final : public ScenarioInstance {
public:
  CatchInstance(scenarios::BallCatchingConfig cfg, CatchOptions opt) : cfg_(std::move(cfg)), opt_(opt) {
    cfg_.threads = 1;
    cfg_.finalize();
    cfg_.validate();
  }

  std::string autotuneUnsupported() const override {
    return "the ball-catching detector searches a window around the tracker's predicted pixel, so the "
           "measurements depend on the filter being tuned and cannot be replayed honestly, and the measurement "
           "sigma is per detection (blob covariance, floor detector.sigma_px_floor), not one config value; "
           "sweep tracker.accel_psd / the gates instead";
  }

  RunResult run(std::uint64_t seed, const RunOptions& ro) const override {
    const detail::TempLogDir tmp;
    std::map<std::size_t, core::Camera> cams_seen;
    std::unique_ptr<scenarios::BallCatchingDisplay> view;
    if (ro.display && detail::xDisplayAvailable()) {
      try {
        view = std::make_unique<scenarios::BallCatchingDisplay>(cfg_);
      } catch (const std::exception&) {
        view.reset();  // no X display: headless
      }
    }
    scenarios::CatchSummary sum;
    {
      io::LogDirectory log(tmp.dir());
      scenarios::CatchHooks hooks;
      hooks.log = &log;
      hooks.on_frame = [&](const scenarios::CatchFrame& f) {
        if (f.camera_model != nullptr && !cams_seen.count(f.camera)) cams_seen.emplace(f.camera, *f.camera_model);
        if (view) view->show(f);
      };
      if (ro.progress) hooks.progress = [&ro](int done, int total) { ro.progress(static_cast<double>(done) / total); };
      sum = scenarios::runBallCatching(cfg_, opt_.throws, seed, hooks);
      log.flush();
    }
    std::vector<core::Camera> cams;
    for (std::size_t i = 0; !cams_seen.empty() && i <= cams_seen.rbegin()->first; ++i) {
      const auto it = cams_seen.find(i);
      cams.push_back(it != cams_seen.end() ? it->second : cams_seen.begin()->second);  // unseen: never measured
    }
    const std::map<int, std::vector<LoggedMeasurement>> meas = readMeasurements(tmp.file("measurements.csv"));

    RunResult r;
    r.seed = seed;
    std::shared_ptr<RunSeries> series;
    if (ro.series) series = makeSeries();
    io::CsvWriter* inn_csv = nullptr;
    if (ro.log != nullptr && ro.log->enabled())
      inn_csv = &ro.log->stream("innovations", {"throw", "id", "camera", "t", "d0", "d1", "S00", "S01", "S11", "nis",
                                                "fused", "in_statistics"});
    std::size_t mismatch = 0, sample = 0;
    for (const scenarios::ThrowResult& tr : sum.results) {
      const auto it = meas.find(tr.index);
      if (it == meas.end() || cams.empty()) continue;
      replayThrow(tr, it->second, cams, r, series.get(), inn_csv, mismatch, sample, ro);
    }
    auto& m = r.metrics;
    m["catch_rate_all"] = sum.catch_rate_all;
    m["catch_rate_reachable"] = sum.reachable_throws > 0 ? sum.catch_rate_reachable : std::nan("");
    m["reachable_fraction"] = static_cast<double>(sum.reachable_throws) / sum.throws;
    m["prediction_error_mm_median"] = sum.prediction_error_mm_median;
    m["prediction_error_mm_p95"] = sum.prediction_error_mm_p95;
    m["prediction_error_lead_mm_median"] = sum.predictions_at_lead > 0 ? sum.prediction_error_lead_mm_median : std::nan("");
    m["decision_time_s_median"] = sum.decisions > 0 ? sum.decision_time_s_median : std::nan("");
    m["miss_distance_mm_median_reachable"] = sum.miss_distance_mm_median_reachable;
    m["gave_up_reachable_fraction"] = static_cast<double>(sum.gave_up_reachable) / sum.throws;
    m["detection_rate"] = sum.detection_rate;
    m["limit_violations"] = static_cast<double>(sum.limit_violations);
    m["replay_fate_mismatch"] = static_cast<double>(mismatch);
    m["nis_mean"] = r.nis.mean();
    m["nees_mean"] = r.nees.mean();
    r.verdict = combinedVerdict(r.nees, r.nis, confidence());
    r.series = series;
    return r;
  }

private:
  static std::map<int, std::vector<LoggedMeasurement>> readMeasurements(const std::string& path) {
    std::map<int, std::vector<LoggedMeasurement>> out;
    const detail::CsvTable csv = detail::CsvTable::read(path, "measurements.csv of a ball_catching log");
    const std::size_t cth = csv.col("throw"), ct = csv.col("t"), cc = csv.col("camera"), cu = csv.col("u"),
                      cv = csv.col("v"), cs = csv.col("sigma_px"), cf = csv.col("fused");
    for (std::size_t row = 0; row < csv.rows(); ++row) {
      auto& list = out[static_cast<int>(csv.number(row, cth))];
      LoggedMeasurement lm;
      lm.m.id = list.size() + 1;  // the scenario numbers each throw's measurements from 1
      lm.m.camera = static_cast<std::size_t>(csv.number(row, cc));
      lm.m.t = csv.number(row, ct);
      lm.m.uv = Eigen::Vector2d(csv.number(row, cu), csv.number(row, cv));
      lm.m.sigma_px = csv.number(row, cs);
      lm.fused = csv.number(row, cf) > 0.5;
      list.push_back(lm);
    }
    return out;
  }

  std::shared_ptr<RunSeries> makeSeries() const {
    auto s = std::make_shared<RunSeries>();
    s->time_label = "time since release [s]";
    s->error_label = "tracker position error |p_hat - p| [m]";
    s->nis_x_label = "innovation number (in the run)";
    s->nis_dof = 2.0;
    s->traj_x_label = "world x (towards the box) [m]";
    s->traj_y_label = "world y [m]";
    return s;
  }

  void replayThrow(const scenarios::ThrowResult& tr, const std::vector<LoggedMeasurement>& list,
                   const std::vector<core::Camera>& cams, RunResult& r, RunSeries* series, io::CsvWriter* inn_csv,
                   std::size_t& mismatch, std::size_t& sample, const RunOptions& ro) const {
    const bool truth = cfg_.object == "ball";
    const double t_end = tr.t_cross + cfg_.post_crossing_s + 0.3;
    const sim::DragFlight flight({tr.release, tr.launch_velocity}, 0.0, t_end, cfg_.throws.body);
    auto trueState = [&](double t) {
      const sim::FlightState s = flight.state(std::clamp(t, 0.0, t_end));
      Eigen::VectorXd x(6);
      x << s.p, s.v;
      return x;
    };
    tracking::ViewlineTracker tracker(cams, cfg_.tracker);
    const bool keep_err = series != nullptr && tr.index < 30;
    const bool keep_traj = series != nullptr && tr.index < 5;
    Curve err{"throw " + std::to_string(tr.index), {}, {}}, tru{"truth", {}, {}}, est{"estimate", {}, {}};
    int fused_count = 0;
    std::optional<estimation::StateEstimate> half_state;  // the prediction drawn: from mid-flight on
    std::vector<double> est_t;
    for (const LoggedMeasurement& lm : list) {
      if (lm.m.camera >= cams.size()) throw core::InvalidInput("ball_catching replay: camera index beyond the cameras seen");
      const detail::ViewlineInnovation inn = detail::viewlineInnovation(tracker, cams, cfg_.tracker, lm.m, opt_.burn_in);
      const tracking::Refusal refusal = tracker.submit(lm.m);
      const auto out = refusal == tracking::Refusal::None ? tracker.outcome(lm.m.id) : std::nullopt;
      const bool fused = out && out->fate == tracking::Fate::Fused;
      mismatch += fused != lm.fused;
      const bool counted = inn.valid && fused && !out->seed;
      if (counted) {
        r.nis.add(inn.nis, 2.0);
        if (series != nullptr) {
          series->nis_t.push_back(static_cast<double>(sample));
          series->nis.push_back(inn.nis);
        }
        ++sample;
      }
      if (inn_csv != nullptr) {
        const double nan = std::nan("");
        inn_csv->row({static_cast<double>(tr.index), static_cast<double>(lm.m.id), static_cast<double>(lm.m.camera), lm.m.t,
                      inn.valid ? inn.d(0) : nan, inn.valid ? inn.d(1) : nan, inn.valid ? inn.S(0, 0) : nan,
                      inn.valid ? inn.S(0, 1) : nan, inn.valid ? inn.S(1, 1) : nan, inn.valid ? inn.nis : nan,
                      fused ? 1.0 : 0.0, counted ? 1.0 : 0.0});
      }
      if (!fused || !tracker.initialised()) continue;
      ++fused_count;
      const estimation::StateEstimate& s = tracker.state();
      const Eigen::VectorXd xt = trueState(s.t());
      if (truth && fused_count == opt_.nees_fused) r.nees.add(estimation::nees(s, xt), 6.0);
      const double e = (s.x().head<3>() - xt.head<3>()).norm();
      if (ro.live) ro.live({s.t(), e, counted ? inn.nis : -1.0});
      if (keep_err) {
        err.x.push_back(s.t());
        err.y.push_back(e);
      }
      if (keep_traj) {
        tru.x.push_back(xt(0));
        tru.y.push_back(xt(1));
        est.x.push_back(s.x()(0));
        est.y.push_back(s.x()(1));
        est_t.push_back(s.t());
        if (!half_state && 2 * fused_count >= tr.fused) half_state = s;
      }
    }
    if (series == nullptr) return;
    if (truth && !err.x.empty()) series->error.push_back(err);
    if (truth && !tru.x.empty()) series->truth.push_back(tru);
    if (!est.x.empty()) series->estimate.push_back(est);
    if (half_state && half_state->dim() == 6) {
      // The tracker's own (drag-free ballistic) model rolled forward from its mid-flight state.
      Curve pre{"prediction from mid-flight", {}, {}};
      const tracking::Vector6 x0 = half_state->x();
      for (double t : est_t) {
        if (t < half_state->t()) continue;
        const tracking::Vector6 xp = cfg_.tracker.model.propagate(x0, t - half_state->t());
        pre.x.push_back(xp(0));
        pre.y.push_back(xp(1));
      }
      if (!pre.x.empty()) series->prediction.push_back(pre);
    }
  }

  scenarios::BallCatchingConfig cfg_;
  CatchOptions opt_;
};

}  // namespace

void registerBallCatchingAdapter(AdapterRegistry& registry) {
  detail::AdapterInfo info;
  info.name = "ball_catching";
  info.description = "ball catching of [L] VI.C (rendered free-running cameras, viewline tracker, catch planner, robot; "
                     "config/ball_catching.yaml)";
  info.app = "ball_catching";
  info.app_arguments = "--throws 100 --headless --summary ball_catching_summary.json";
  info.default_metric = "catch_rate_reachable";
  info.minimize = false;
  info.metrics = {"catch_rate_all", "catch_rate_reachable", "reachable_fraction", "prediction_error_mm_median",
                  "prediction_error_mm_p95", "prediction_error_lead_mm_median", "decision_time_s_median",
                  "miss_distance_mm_median_reachable", "gave_up_reachable_fraction", "detection_rate", "limit_violations",
                  "replay_fate_mismatch", "nis_mean", "nees_mean"};
  info.options = {{"throws", "10", {}, "throws per run (throw i from deriveSeed(seed, i), as ball_catching --throws)"},
                  {"burn_in", "4", {}, "fused images of a track before its innovations count in NIS"},
                  {"nees_fused", "8", {}, "the NEES sample of a throw is taken after this many fused images"}};
  registry.add(detail::makeAdapter(std::move(info), [](const std::string& yaml, const std::string& name,
                                                       const AdapterOptions& options) {
    scenarios::BallCatchingConfig cfg = scenarios::loadBallCatchingConfig(detail::scenarioConfig(yaml, name));
    CatchOptions o;
    const double throws = optionNumber(options, "throws");
    if (!(throws >= 1.0 && throws <= 1e5)) throw core::InvalidInput("adapter option 'throws': expected 1 to 1e5");
    o.throws = static_cast<int>(throws);
    o.burn_in = static_cast<int>(optionNumber(options, "burn_in"));
    o.nees_fused = static_cast<int>(optionNumber(options, "nees_fused"));
    if (o.burn_in < 1 || o.nees_fused < 1) throw core::InvalidInput("adapter options burn_in, nees_fused: expected >= 1");
    return std::unique_ptr<ScenarioInstance>(std::make_unique<CatchInstance>(std::move(cfg), o));
  }));
}

}  // namespace viewline::tuning
