// Table-ball scenario adapter ([M], issue 7): runs scenarios::runTableBall (rendered images,
// table and ball detection, the rolling-ball observer, the LQR balancer) in-process, with the
// config read by the scenario's own loader (tableBallConfigFromYaml: strict keys), so a config the
// tuning tool accepts or writes is one table_ball_balancing reads.
//
// Innovations. runTableBall reports every frame to its on_frame hook (capture time, the
// observer's measured in-plane acceleration a_xy, the ball measurement y when found, the
// observer's state, the true ball position). The observer's filter is the public
// scenarios::RollingBallTracker, deterministic, so the adapter re-runs one built exactly as
// runTableBall builds it (observer section of the config, the table's L and r, nominal period
// 1 / camera.rate_hz) on the same (t, a_xy, y) sequence: its states equal the loop's (checked on
// every frame; a difference > 1e-9 m fails the run). Before each update the innovation is
//   d = y − C x̂(t|t−),  S = C P(t|t−) Cᵀ + σv² I  (2 dof, C selects (p_x, p_y)),
// with x̂(t|t−), P(t|t−) from a copy of the tracker stepped without the measurement (the time
// update incl. the border clamp, exactly what step() does before its update); with
// observer.stationary_gain P(t|t−) is the DARE's a-priori covariance. NIS samples once the
// track has `burn_in` measurements; NEES (2 dof, ball position on the table) against the truth
// at the capture instant, one sample every `nees_spacing_s` after metrics.warmup.
//
// Noise auto-tuning: the filter's measurements (y, a_xy, t) do not depend on σw, σv within a
// replay (the closed loop changes the ball's path only in live runs), so the maximum-likelihood
// search replays the logged measurements honestly: process σw (observer.sigma_w) and measurement
// σv (observer.sigma_v). Gross outliers: uniform over the reachable square (L − 2r)².
// From a log: the measurements.csv that table_ball_balancing --log writes (t, ball_found, mx, my,
// ax, ay).
//
// Timing metrics (frame_time_ratio_to_reference) are wall-clock and would make results depend on
// the machine load, so sweeps run with metrics.time_reference off.

#include <Eigen/Cholesky>
#include <cmath>
#include <filesystem>
#include <optional>

#include "adapter_util.h"
#include "viewline/core/error.h"
#include "viewline/core/random.h"
#include "viewline/scenarios/table_ball.h"
#include "viewline/scenarios/table_ball_display.h"
#include "viewline/scenarios/table_ball_observer.h"
#include "viewline/tuning/scenario.h"

namespace viewline::tuning {

namespace {

namespace fs = std::filesystem;

struct BallFrame {
  double t = 0.0;
  Eigen::Vector2d a_xy = Eigen::Vector2d::Zero();
  std::optional<Eigen::Vector2d> y;
  bool has_truth = false;
  Eigen::Vector2d truth = Eigen::Vector2d::Zero();
  bool estimate_valid = false;               ///< the loop's observer (for the replay check)
  Eigen::Vector2d estimate = Eigen::Vector2d::Zero();
};

class TableBallReplayData : public ReplayData {
public:
  std::vector<std::vector<BallFrame>> runs;
  std::string source;
  std::size_t measurements() const override {
    std::size_t n = 0;
    for (const auto& r : runs)
      for (const auto& f : r) n += f.y.has_value();
    return n;
  }
  std::string describe() const override {
    return std::to_string(runs.size()) + " table-ball run(s), " + std::to_string(measurements()) +
           " ball measurements (" + source + ")";
  }
};

struct TableBallOptions {
  double duration = 0.0;      ///< 0: the config's
  int burn_in = 5;
  double nees_spacing = 0.5;  ///< s
};

struct Accum {
  double cost = 0.0;
  std::size_t terms = 0;
  Consistency nis, nees;
  double max_replay_dev = 0.0;  ///< m, replayed vs loop estimate
};

class TableBallInstance final : public ScenarioInstance {
public:
  TableBallInstance(scenarios::TableBallConfig cfg, TableBallOptions opt) : cfg_(std::move(cfg)), opt_(opt) {
    cfg_.time_reference = false;
    if (opt_.duration > 0.0) cfg_.duration = opt_.duration;
    cfg_.validate();
  }

  RunResult run(std::uint64_t seed, const RunOptions& ro) const override {
    std::vector<BallFrame> frames;
    const scenarios::TableBallResult res = simulate(seed, ro, frames);
    RunResult r;
    r.seed = seed;
    std::shared_ptr<RunSeries> series;
    if (ro.series) series = makeSeries();
    Accum a;
    io::CsvWriter* inn = nullptr;
    if (ro.log != nullptr && ro.log->enabled())
      inn = &ro.log->stream("innovations", {"t", "d0", "d1", "S00", "S01", "S11", "nis", "in_statistics"});
    replayRun(frames, cfg_.observer.tracker.model.sigma_w, cfg_.observer.tracker.model.sigma_v, 0.0, a, series.get(), inn);
    if (a.max_replay_dev > 1e-9)
      throw core::NumericalError("table_ball adapter: the replayed observer filter differs from the loop's by " +
                                 std::to_string(1e3 * a.max_replay_dev) + " mm (scenario changed? see the adapter's note)");
    r.nis = a.nis;
    r.nees = a.nees;
    auto& m = r.metrics;
    m["observer_rmse_mm"] = res.observer_rmse_mm;
    m["measurement_rmse_mm"] = res.measurement_rmse_mm;
    m["prediction_rmse_mm_10"] = res.prediction_rmse_mm_10;
    m["tilt_rmse_deg"] = res.tilt_rmse_deg;
    m["overshoot_pct"] = res.overshoot_pct;
    m["settling_time_s"] = res.settling_time_s;
    m["steady_state_error_mm"] = res.steady_state_error_mm;
    m["push_recovery_s"] = res.push_recovery_s;
    m["max_commanded_angle_deg"] = res.max_commanded_angle_deg;
    m["limits_respected"] = res.limits_respected ? 1.0 : 0.0;
    m["ball_detection_rate"] = res.frames > 0 ? static_cast<double>(res.ball_detections) / res.frames : std::nan("");
    if (cfg_.compare_tunings) {
      m["observer_rmse_mm_M_sw1_sv0005"] = res.observer_rmse_mm_M_sw1_sv0005;
      m["observer_rmse_mm_M_sw1_sv1"] = res.observer_rmse_mm_M_sw1_sv1;
      m["observer_rmse_mm_stationary"] = res.observer_rmse_mm_stationary;
    }
    m["nis_mean"] = a.nis.mean();
    m["nees_mean"] = a.nees.mean();
    r.verdict = combinedVerdict(r.nees, r.nis, confidence());
    r.series = series;
    return r;
  }

  std::vector<NoiseParameter> noiseParameters() const override {
    const auto& mdl = cfg_.observer.tracker.model;
    return {{"process", "sigma_w", "m/s^1.5", "observer.sigma_w",
             "disturbance intensity of the rolling-ball filter (w1 density sigma_w^2, w2 std sigma_w)", mdl.sigma_w},
            {"measurement", "sigma_v", "m", "observer.sigma_v", "std of the measured ball position on the table", mdl.sigma_v}};
  }

  std::unique_ptr<ReplayData> record(std::uint64_t seed, int runs) const override {
    auto d = std::make_unique<TableBallReplayData>();
    for (int i = 0; i < runs; ++i) {
      d->runs.emplace_back();
      simulate(core::deriveSeed(seed, static_cast<std::uint64_t>(i)), {}, d->runs.back());
    }
    d->source = "live: " + std::to_string(runs) + " run(s) from seed " + std::to_string(seed);
    return d;
  }

  std::unique_ptr<ReplayData> loadLog(const std::string& dir) const override {
    const std::string path = (fs::path(dir) / "measurements.csv").string();
    const detail::CsvTable csv = detail::CsvTable::read(path, "the measurements.csv of table_ball_balancing --log");
    const std::size_t ct = csv.col("t"), cb = csv.col("ball_found"), cx = csv.col("mx"), cy = csv.col("my"),
                      ax = csv.col("ax"), ay = csv.col("ay");
    auto d = std::make_unique<TableBallReplayData>();
    d->runs.emplace_back();
    for (std::size_t row = 0; row < csv.rows(); ++row) {
      BallFrame f;
      f.t = csv.number(row, ct);
      f.a_xy = Eigen::Vector2d(csv.number(row, ax), csv.number(row, ay));
      if (csv.number(row, cb) > 0.5) f.y = Eigen::Vector2d(csv.number(row, cx), csv.number(row, cy));
      if (!d->runs.back().empty() && !(f.t > d->runs.back().back().t))
        throw core::InvalidInput(csv.where(row) + ": time stamps must increase");
      d->runs.back().push_back(f);
    }
    if (d->measurements() == 0) throw core::InvalidInput(path + ": no ball measurements");
    d->source = path;
    return d;
  }

  ReplayResult replay(const ReplayData& data, const std::vector<double>& noise, double outlier_prior,
                      bool want_series) const override {
    const TableBallReplayData& d = detail::replayInput<TableBallReplayData>(data, noise, 2, "table_ball");
    Accum a;
    std::shared_ptr<RunSeries> series;
    if (want_series) series = makeSeries();
    for (const auto& run : d.runs) replayRun(run, noise[0], noise[1], outlier_prior, a, series.get(), nullptr);
    return detail::replayResult(a.cost, a.terms, a.nis, series);
  }

  std::unique_ptr<ScenarioInstance> withNoise(const std::vector<double>& noise) const override {
    if (noise.size() != 2) throw core::InvalidInput("table_ball: expected (sigma_w, sigma_v)");
    scenarios::TableBallConfig c = cfg_;
    c.observer.tracker.model.sigma_w = noise[0];
    c.observer.tracker.model.sigma_v = noise[1];
    return std::make_unique<TableBallInstance>(c, opt_);
  }

private:
  /// The observer's filter configuration as runTableBall builds it.
  scenarios::RollingBallTrackerConfig trackerConfig(double sigma_w, double sigma_v) const {
    scenarios::RollingBallTrackerConfig tc = cfg_.observer.tracker;
    tc.model.table_side = cfg_.table_side;
    tc.model.ball_radius = cfg_.ball_radius;
    tc.model.sigma_w = sigma_w;
    tc.model.sigma_v = sigma_v;
    tc.nominal_period = 1.0 / cfg_.rate_hz;
    return tc;
  }

  scenarios::TableBallResult simulate(std::uint64_t seed, const RunOptions& ro, std::vector<BallFrame>& frames) const {
    std::unique_ptr<scenarios::TableBallDisplay> view;
    if (ro.display && detail::xDisplayAvailable()) {
      try {
        view = std::make_unique<scenarios::TableBallDisplay>(cfg_.table_side, cfg_.ball_radius);
      } catch (const std::exception&) {
        view.reset();  // no X display: headless
      }
    }
    scenarios::TableBallHooks hooks;
    hooks.log = ro.log != nullptr && ro.log->enabled() ? ro.log : nullptr;
    hooks.on_frame = [&](const scenarios::TableBallFrameView& v) {
      const scenarios::ObserverFrame& of = *v.observer;
      BallFrame f;
      f.t = of.t;
      f.a_xy = of.a_xy;
      if (of.ball_found) f.y = of.measured;
      f.has_truth = true;
      f.truth = v.truth;
      f.estimate_valid = of.estimate_valid;
      if (of.estimate_valid) f.estimate = Eigen::Vector2d(of.x[0], of.x[2]);
      frames.push_back(f);
      if (view) view->show(v);
      if (ro.live) {
        const double e = of.estimate_valid ? 1e3 * (f.estimate - v.truth).norm() : std::nan("");
        ro.live({of.t, e, -1.0});
      }
    };
    if (ro.progress) hooks.on_progress = [&ro](double t, double duration) { ro.progress(t / duration); };
    return scenarios::runTableBall(cfg_, seed, hooks);
  }

  std::shared_ptr<RunSeries> makeSeries() const {
    auto s = std::make_shared<RunSeries>();
    s->error_label = "ball position error |p_hat - p| [mm]";
    s->nis_dof = 2.0;
    s->traj_x_label = "table x [m]";
    s->traj_y_label = "table y [m]";
    return s;
  }

  void replayRun(const std::vector<BallFrame>& frames, double sigma_w, double sigma_v, double eps, Accum& a,
                 RunSeries* series, io::CsvWriter* inn) const {
    const scenarios::RollingBallTrackerConfig tc = trackerConfig(sigma_w, sigma_v);
    scenarios::RollingBallTracker trk(tc);
    std::optional<estimation::StationaryFilter> sf;
    if (tc.stationary_gain) sf = tc.model.stationaryFilter(tc.nominal_period);
    const double side = tc.model.table_side - 2.0 * tc.model.ball_radius;
    const double log_u = -std::log(side * side);
    const Eigen::Matrix2d R = sigma_v * sigma_v * Eigen::Matrix2d::Identity();
    Curve err{"error", {}, {}}, tru{"truth", {}, {}}, est{"estimate", {}, {}}, pre{"prediction", {}, {}};
    int measured = 0;
    double next_nees = cfg_.warmup;
    for (const BallFrame& f : frames) {
      bool have = false;
      double nis = 0.0;
      Eigen::Vector2d d = Eigen::Vector2d::Zero();
      Eigen::Matrix2d S = Eigen::Matrix2d::Identity();
      if (f.y && trk.initialized() && measured >= opt_.burn_in) {
        scenarios::RollingBallTracker prior = trk;  // the time update step() performs before its update
        prior.step(f.t, f.a_xy, std::nullopt);
        const Eigen::MatrixXd P = sf ? sf->P : prior.P();
        Eigen::Matrix2d Pp;
        Pp << P(0, 0), P(0, 2), P(2, 0), P(2, 2);
        d = *f.y - prior.position();
        S = Pp + R;
        const Eigen::LLT<Eigen::Matrix2d> llt(S);
        if (llt.info() == Eigen::Success) {
          nis = d.dot(llt.solve(d));
          have = std::isfinite(nis);
        }
      }
      trk.step(f.t, f.a_xy, f.y);
      if (f.y) ++measured;
      if (have) {
        a.cost += detail::innovationCost(nis, std::log(S.determinant()), 2, eps, log_u);
        ++a.terms;
        a.nis.add(nis, 2.0);
        if (series != nullptr) {
          series->nis_t.push_back(f.t);
          series->nis.push_back(nis);
        }
      }
      if (inn != nullptr)
        inn->row({f.t, have ? d(0) : std::nan(""), have ? d(1) : std::nan(""), have ? S(0, 0) : std::nan(""),
                  have ? S(0, 1) : std::nan(""), have ? S(1, 1) : std::nan(""), have ? nis : std::nan(""),
                  have ? 1.0 : 0.0});
      if (!trk.initialized()) continue;
      if (f.estimate_valid) a.max_replay_dev = std::max(a.max_replay_dev, (trk.position() - f.estimate).norm());
      if (f.has_truth && f.t >= next_nees && measured >= opt_.burn_in) {
        const Eigen::MatrixXd P = trk.P();
        Eigen::Matrix2d Pp;
        Pp << P(0, 0), P(0, 2), P(2, 0), P(2, 2);
        const Eigen::Vector2d e = trk.position() - f.truth;
        a.nees.add(e.dot(Pp.ldlt().solve(e)), 2.0);
        next_nees = f.t + opt_.nees_spacing;
      }
      if (series != nullptr) {
        if (f.has_truth) {
          err.x.push_back(f.t);
          err.y.push_back(1e3 * (trk.position() - f.truth).norm());
          tru.x.push_back(f.truth.x());
          tru.y.push_back(f.truth.y());
        }
        est.x.push_back(trk.position().x());
        est.y.push_back(trk.position().y());
        if (!trk.predictions().empty()) {
          pre.x.push_back(trk.predictions().back().x());
          pre.y.push_back(trk.predictions().back().y());
        }
      }
    }
    if (series != nullptr) {
      if (!err.x.empty()) series->error.push_back(err);
      if (!tru.x.empty()) series->truth.push_back(tru);
      series->estimate.push_back(est);
      pre.name = "prediction " + std::to_string(tc.model.prediction_steps) + " frames ahead";
      series->prediction.push_back(pre);
    }
  }

  scenarios::TableBallConfig cfg_;
  TableBallOptions opt_;
};

}  // namespace

void registerTableBallAdapter(AdapterRegistry& registry) {
  detail::AdapterInfo info;
  info.name = "table_ball";
  info.description = "table-ball balancing of [M] (rendered table and ball, rolling-ball observer, LQR; config/table_ball.yaml)";
  info.app = "table_ball_balancing";
  info.app_arguments = "--headless --summary table_ball_summary.json";
  info.default_metric = "observer_rmse_mm";
  info.metrics = {"observer_rmse_mm", "measurement_rmse_mm", "prediction_rmse_mm_10", "tilt_rmse_deg", "overshoot_pct",
                  "settling_time_s", "steady_state_error_mm", "push_recovery_s", "max_commanded_angle_deg",
                  "limits_respected", "ball_detection_rate", "observer_rmse_mm_M_sw1_sv0005", "observer_rmse_mm_M_sw1_sv1",
                  "observer_rmse_mm_stationary", "nis_mean", "nees_mean"};
  info.options = {{"duration", "0", {}, "s of each run (0: the config's duration)"},
                  {"burn_in", "5", {}, "ball measurements of the track before its innovations count"},
                  {"nees_spacing_s", "0.5", {}, "s between NEES samples (nearly independent)"}};
  registry.add(detail::makeAdapter(std::move(info), [](const std::string& yaml, const std::string& name,
                                                       const AdapterOptions& options) {
    scenarios::TableBallConfig cfg = scenarios::tableBallConfigFromYaml(detail::scenarioConfig(yaml, name));
    TableBallOptions o;
    o.duration = optionNumber(options, "duration");
    o.burn_in = static_cast<int>(optionNumber(options, "burn_in"));
    o.nees_spacing = optionNumber(options, "nees_spacing_s");
    if (!(o.duration >= 0.0) || o.burn_in < 1 || !(o.nees_spacing > 0.0))
      throw core::InvalidInput("table_ball adapter options: duration >= 0, burn_in >= 1, nees_spacing_s > 0");
    return std::unique_ptr<ScenarioInstance>(std::make_unique<TableBallInstance>(std::move(cfg), o));
  }));
}

}  // namespace viewline::tuning
