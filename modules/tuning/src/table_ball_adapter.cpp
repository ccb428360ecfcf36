// Table-ball scenario adapter ([M]): runs scenarios::runTableBall (rendered images, table and
// ball detection, the rolling-ball observer, the LQR balancer) in-process, with the config read
// by the scenario's own loader (tableBallConfigFromYaml: strict keys), so a config the tuning
// tool accepts or writes is one table_ball_balancing reads.
//
// Innovations. The loop reports every update of the observer's filter to its telemetry sink
// with the update's own diagnostics (runtime::InnovationRecord: d = y − C x̂(t|t−),
// S = C P(t|t−) Cᵀ + σv² I, NIS, the gate decision); a run reads them from a runtime::MemorySink,
// nothing is recomputed. NIS samples once the track has `burn_in` measurements; NEES (2 dof,
// ball position on the table) of the observer's estimate (x̂, P from the sink) against the truth
// at the capture instant, one sample every `nees_spacing_s` after metrics.warmup.
//
// Noise auto-tuning: the filter's measurements (y, a_xy, t) do not depend on σw, σv within a
// replay (the closed loop changes the ball's path only in live runs), so the maximum-likelihood
// search replays the logged measurements through tracking::RollingBallTracker built as the loop
// builds it (TableBallConfig::trackerConfig) with other σw (observer.sigma_w) and σv
// (observer.sigma_v), each replayed update reporting its own innovation, S and NIS (with the
// stationary gain, S uses the DARE's a-priori covariance). Gross outliers: uniform over the
// reachable square (L − 2r)². From a log: the files table_ball_balancing --log writes through
// its runtime::CsvSink, measurements_ball_acceleration.csv (every frame: t, the filter's input
// a_xy) and measurements_ball.csv (t, the ball on the table when found).
//
// Timing metrics (frame_time_ratio_to_reference) are wall-clock and would make results depend on
// the machine load, so sweeps run with metrics.time_reference off.

#include <cmath>
#include <filesystem>
#include <optional>

#include "adapter_util.h"
#include "viewline/core/error.h"
#include "viewline/core/random.h"
#include "viewline/runtime/telemetry.h"
#include "viewline/scenarios/table_ball.h"
#include "viewline/scenarios/table_ball/observer.h"
#include "viewline/tracking/rolling_ball_tracker.h"
#include "viewline/tuning/scenario.h"
#include "viewline/viz/table_ball_display.h"

namespace viewline::tuning {

namespace {

namespace fs = std::filesystem;

struct BallFrame {
  double t = 0.0;
  Eigen::Vector2d a_xy = Eigen::Vector2d::Zero();
  std::optional<Eigen::Vector2d> y;
  bool has_truth = false;
  Eigen::Vector2d truth = Eigen::Vector2d::Zero();
  std::optional<Eigen::Vector2d> prediction;  ///< the loop observer's N-th predicted position
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
    runtime::MemorySink telemetry;
    const scenarios::TableBallResult res = simulate(seed, ro, frames, &telemetry);
    RunResult r;
    r.seed = seed;
    std::shared_ptr<RunSeries> series;
    if (ro.series) series = makeSeries();
    Accum a;
    io::CsvWriter* inn = nullptr;
    if (ro.log != nullptr && ro.log->enabled())
      inn = &ro.log->stream("innovations", {"t", "d0", "d1", "S00", "S01", "S11", "nis", "in_statistics"});
    consistency(frames, telemetry, a, series.get(), inn);
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
      simulate(core::deriveSeed(seed, static_cast<std::uint64_t>(i)), {}, d->runs.back(), nullptr);
    }
    d->source = "live: " + std::to_string(runs) + " run(s) from seed " + std::to_string(seed);
    return d;
  }

  std::unique_ptr<ReplayData> loadLog(const std::string& dir) const override {
    const std::string inputs_path = (fs::path(dir) / "measurements_ball_acceleration.csv").string();
    const std::string balls_path = (fs::path(dir) / "measurements_ball.csv").string();
    const detail::CsvTable inputs =
        detail::CsvTable::read(inputs_path, "the measurements_ball_acceleration.csv of table_ball_balancing --log");
    const detail::CsvTable balls = detail::CsvTable::read(balls_path, "the measurements_ball.csv of table_ball_balancing --log");
    const std::size_t it = inputs.col("t"), ax = inputs.col("z0"), ay = inputs.col("z1");
    const std::size_t bt = balls.col("t"), bx = balls.col("z0"), by = balls.col("z1");
    auto d = std::make_unique<TableBallReplayData>();
    d->runs.emplace_back();
    auto& run = d->runs.back();
    std::size_t b = 0;  // every frame has an input row; a found ball has a row with the same t
    for (std::size_t row = 0; row < inputs.rows(); ++row) {
      BallFrame f;
      f.t = inputs.number(row, it);
      f.a_xy = Eigen::Vector2d(inputs.number(row, ax), inputs.number(row, ay));
      if (!run.empty() && !(f.t > run.back().t)) throw core::InvalidInput(inputs.where(row) + ": time stamps must increase");
      if (b < balls.rows() && balls.number(b, bt) < f.t)
        throw core::InvalidInput(balls.where(b) + ": a ball measurement without its frame in " + inputs_path);
      if (b < balls.rows() && balls.number(b, bt) == f.t) {
        f.y = Eigen::Vector2d(balls.number(b, bx), balls.number(b, by));
        ++b;
      }
      run.push_back(f);
    }
    if (b < balls.rows()) throw core::InvalidInput(balls.where(b) + ": a ball measurement without its frame in " + inputs_path);
    if (d->measurements() == 0) throw core::InvalidInput(balls_path + ": no ball measurements");
    d->source = balls_path;
    return d;
  }

  ReplayResult replay(const ReplayData& data, const std::vector<double>& noise, double outlier_prior,
                      bool want_series) const override {
    const TableBallReplayData& d = detail::replayInput<TableBallReplayData>(data, noise, 2, "table_ball");
    Accum a;
    std::shared_ptr<RunSeries> series;
    if (want_series) series = makeSeries();
    for (const auto& run : d.runs) replayRun(run, noise[0], noise[1], outlier_prior, a, series.get());
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
  /// The observer's filter as the loop builds it, with other noise intensities.
  tracking::RollingBallTrackerConfig trackerConfig(double sigma_w, double sigma_v) const {
    tracking::RollingBallTrackerConfig tc = cfg_.trackerConfig();
    tc.model.sigma_w = sigma_w;
    tc.model.sigma_v = sigma_v;
    return tc;
  }

  scenarios::TableBallResult simulate(std::uint64_t seed, const RunOptions& ro, std::vector<BallFrame>& frames,
                                      runtime::MemorySink* telemetry) const {
    std::unique_ptr<viz::TableBallDisplay> view;
    if (ro.display && detail::xDisplayAvailable()) {
      try {
        view = std::make_unique<viz::TableBallDisplay>(cfg_.table_side, cfg_.ball_radius);
      } catch (const std::exception&) {
        view.reset();  // no X display: headless
      }
    }
    std::optional<runtime::CsvSink> csv;
    runtime::FanoutSink sinks;
    sinks.add(telemetry);
    if (ro.log != nullptr && ro.log->enabled()) sinks.add(&csv.emplace(*ro.log));
    scenarios::TableBallHooks hooks;
    hooks.telemetry = &sinks;
    hooks.on_frame = [&](const scenarios::TableBallFrameView& v) {
      const scenarios::ObserverFrame& of = *v.observer;
      BallFrame f;
      f.t = of.t;
      f.a_xy = of.a_xy;
      if (of.ball_found) f.y = of.measured;
      f.has_truth = true;
      f.truth = v.truth;
      if (of.estimate_valid && !of.predictions.empty()) f.prediction = of.predictions.back();
      frames.push_back(f);
      const bool go = !view || view->show(v);
      if (ro.live) {
        const double e = of.estimate_valid ? 1e3 * (Eigen::Vector2d(of.x[0], of.x[2]) - v.truth).norm() : std::nan("");
        ro.live({of.t, e, -1.0});
      }
      return go;
    };
    if (ro.progress) hooks.on_progress = [&ro](double t, double duration) { ro.progress(t / duration); };
    return scenarios::runTableBall(cfg_, seed, hooks);
  }

  /// NIS from the loop observer's own update reports, NEES and the curves from its estimates.
  void consistency(const std::vector<BallFrame>& frames, const runtime::MemorySink& telemetry, Accum& a,
                   RunSeries* series, io::CsvWriter* inn) const {
    const double side = cfg_.table_side - 2.0 * cfg_.ball_radius;
    const double log_u = -std::log(side * side);
    std::size_t k = 0;
    for (const runtime::InnovationRecord& u : telemetry.innovationsOf("ball")) {
      const bool counted = k++ >= static_cast<std::size_t>(opt_.burn_in) && u.decision == tracking::GateDecision::Accept &&
                           u.S.rows() == 2 && u.S.cols() == 2 && std::isfinite(u.nis);
      const Eigen::Matrix2d S = counted ? Eigen::Matrix2d(u.S) : Eigen::Matrix2d::Constant(std::nan(""));
      if (counted) {
        a.cost += detail::innovationCost(u.nis, std::log(S.determinant()), 2, 0.0, log_u);
        ++a.terms;
        a.nis.add(u.nis, 2.0);
        if (series != nullptr) {
          series->nis_t.push_back(u.t);
          series->nis.push_back(u.nis);
        }
      }
      if (inn != nullptr)
        inn->row({u.t, counted ? u.innovation[0] : std::nan(""), counted ? u.innovation[1] : std::nan(""), S(0, 0),
                  S(0, 1), S(1, 1), counted ? u.nis : std::nan(""), counted ? 1.0 : 0.0});
    }
    std::vector<const runtime::EstimateRecord*> estimates;
    for (const auto& e : telemetry.estimates)
      if (e.channel == "ball") estimates.push_back(&e);
    Curve err{"error", {}, {}}, tru{"truth", {}, {}}, est{"estimate", {}, {}}, pre{"prediction", {}, {}};
    int measured = 0;
    double next_nees = cfg_.warmup;
    std::size_t e = 0;
    for (const BallFrame& f : frames) {
      if (f.y) ++measured;
      while (e < estimates.size() && estimates[e]->t < f.t) ++e;
      if (e == estimates.size() || estimates[e]->t != f.t) continue;  // no track yet
      const Eigen::VectorXd& x = estimates[e]->x;
      const Eigen::MatrixXd& P = estimates[e]->P;
      const Eigen::Vector2d p(x[0], x[2]);
      if (f.has_truth && f.t >= next_nees && measured >= opt_.burn_in) {
        Eigen::Matrix2d Pp;
        Pp << P(0, 0), P(0, 2), P(2, 0), P(2, 2);
        const Eigen::Vector2d d = p - f.truth;
        a.nees.add(d.dot(Pp.ldlt().solve(d)), 2.0);
        next_nees = f.t + opt_.nees_spacing;
      }
      if (series != nullptr) {
        if (f.has_truth) {
          err.x.push_back(f.t);
          err.y.push_back(1e3 * (p - f.truth).norm());
          tru.x.push_back(f.truth.x());
          tru.y.push_back(f.truth.y());
        }
        est.x.push_back(p.x());
        est.y.push_back(p.y());
        if (f.prediction) {
          pre.x.push_back(f.prediction->x());
          pre.y.push_back(f.prediction->y());
        }
      }
    }
    if (series != nullptr) finishSeries(*series, err, tru, est, pre);
  }

  void finishSeries(RunSeries& series, Curve& err, Curve& tru, Curve& est, Curve& pre) const {
    if (!err.x.empty()) series.error.push_back(err);
    if (!tru.x.empty()) series.truth.push_back(tru);
    series.estimate.push_back(est);
    pre.name = "prediction " + std::to_string(cfg_.observer.tracker.model.prediction_steps) + " frames ahead";
    series.prediction.push_back(pre);
  }

  std::shared_ptr<RunSeries> makeSeries() const {
    auto s = std::make_shared<RunSeries>();
    s->error_label = "ball position error |p_hat - p| [mm]";
    s->nis_dof = 2.0;
    s->traj_x_label = "table x [m]";
    s->traj_y_label = "table y [m]";
    return s;
  }

  /// Replays logged measurements through the observer's filter with (σw, σv).
  void replayRun(const std::vector<BallFrame>& frames, double sigma_w, double sigma_v, double eps, Accum& a,
                 RunSeries* series) const {
    const tracking::RollingBallTrackerConfig tc = trackerConfig(sigma_w, sigma_v);
    tracking::RollingBallTracker trk(tc);
    const double side = tc.model.table_side - 2.0 * tc.model.ball_radius;
    const double log_u = -std::log(side * side);
    Curve err{"error", {}, {}}, tru{"truth", {}, {}}, est{"estimate", {}, {}}, pre{"prediction", {}, {}};
    int measured = 0;
    double next_nees = cfg_.warmup;
    for (const BallFrame& f : frames) {
      // The update's own innovation, S and NIS (RollingBallTracker::lastUpdate), once the track
      // has burn_in measurements.
      const bool counted_track = f.y && measured >= opt_.burn_in;
      trk.step(f.t, f.a_xy, f.y);
      if (f.y) ++measured;
      const auto& u = trk.lastUpdate();
      if (counted_track && u && u->decision == tracking::GateDecision::Accept && std::isfinite(u->report.nis)) {
        const double nis = u->report.nis;
        a.cost += detail::innovationCost(nis, std::log(Eigen::Matrix2d(u->report.S).determinant()), 2, eps, log_u);
        ++a.terms;
        a.nis.add(nis, 2.0);
        if (series != nullptr) {
          series->nis_t.push_back(f.t);
          series->nis.push_back(nis);
        }
      }
      if (!trk.initialized()) continue;
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
    if (series != nullptr) finishSeries(*series, err, tru, est, pre);
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
