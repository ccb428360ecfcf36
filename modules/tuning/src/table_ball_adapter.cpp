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
// a_xy) and measurements_ball.csv (t, the ball on the table when found). From a recording
// (table_ball_balancing --record DIR, or a rig's): its frames through the observer as a footage
// session runs them (scenarios::runTableBallOnRecording: each frame's PnP table pose, the head at
// its calibrated rest pose, since a recording holds neither the head's sway nor the wrist's tilt),
// the same (y, a_xy, t) read from the session's telemetry; NIS only. The σv fitted there is the
// per-frame pose's, not the filtered pose's of a simulated run (table_pose_time_constant).
//
// Timing metrics (frame_time_ratio_to_reference) are wall-clock and would make results depend on
// the machine load, so sweeps run with metrics.time_reference off.

#include <cmath>
#include <filesystem>
#include <limits>
#include <map>
#include <optional>

#include "adapter_util.h"
#include "viewline/core/error.h"
#include "viewline/core/random.h"
#include "viewline/runtime/telemetry.h"
#include "viewline/scenarios/table_ball.h"
#include "viewline/scenarios/table_ball/footage.h"
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

using BallRun = std::vector<BallFrame>;
using TableBallReplayData = detail::Recording<BallRun>;

std::size_t ballMeasurements(const BallRun& run) {
  std::size_t n = 0;
  for (const auto& f : run) n += f.y.has_value();
  return n;
}

std::unique_ptr<TableBallReplayData> newReplayData() {
  return std::make_unique<TableBallReplayData>("table-ball run(s)", "ball measurements", &ballMeasurements);
}

/// The adapter options (declared with their defaults and ranges in registerTableBallAdapter).
struct TableBallOptions {
  double duration;      ///< s; 0: the config's
  int burn_in;          ///< ball measurements of the track before its innovations count
  double nees_spacing;  ///< s between NEES samples
};

/// The adapter options: type, range, default and help of each, bound to its field.
detail::OptionTable<TableBallOptions> tableBallOptions() {
  detail::OptionTable<TableBallOptions> options;
  options.number("duration", &TableBallOptions::duration, "0", 0.0, detail::kUnbounded, "s of each run (0: the config's duration)")
      .integer("burn_in", &TableBallOptions::burn_in, "5", 1, 1e6, "ball measurements of the track before its innovations count")
      .number("nees_spacing_s", &TableBallOptions::nees_spacing, "0.5", 1e-9, detail::kUnbounded,
              "s between NEES samples (nearly independent)");
  return options;
}

using Accum = detail::InnovationTally;

/// The metrics that are a field of the scenario's result, by name (the rest are formed in run()).
using ResultMetric = std::pair<const char*, double scenarios::TableBallResult::*>;
const ResultMetric kResultMetrics[] = {
    {"observer_rmse_mm", &scenarios::TableBallResult::observer_rmse_mm},
    {"measurement_rmse_mm", &scenarios::TableBallResult::measurement_rmse_mm},
    {"prediction_rmse_mm_10", &scenarios::TableBallResult::prediction_rmse_mm_10},
    {"tilt_rmse_deg", &scenarios::TableBallResult::tilt_rmse_deg},
    {"overshoot_pct", &scenarios::TableBallResult::overshoot_pct},
    {"settling_time_s", &scenarios::TableBallResult::settling_time_s},
    {"steady_state_error_mm", &scenarios::TableBallResult::steady_state_error_mm},
    {"push_recovery_s", &scenarios::TableBallResult::push_recovery_s},
    {"max_commanded_angle_deg", &scenarios::TableBallResult::max_commanded_angle_deg}};
/// The observer's RMSE under the compared tunings (metrics.compare_tunings).
const ResultMetric kComparedTunings[] = {
    {"observer_rmse_mm_M_sw1_sv0005", &scenarios::TableBallResult::observer_rmse_mm_M_sw1_sv0005},
    {"observer_rmse_mm_M_sw1_sv1", &scenarios::TableBallResult::observer_rmse_mm_M_sw1_sv1},
    {"observer_rmse_mm_stationary", &scenarios::TableBallResult::observer_rmse_mm_stationary}};

/// Every metric a run reports, in the order the tool lists them.
std::vector<std::string> metricNames() {
  std::vector<std::string> names;
  for (const auto& m : kResultMetrics) names.emplace_back(m.first);
  names.insert(names.end(), {"limits_respected", "ball_detection_rate"});
  for (const auto& m : kComparedTunings) names.emplace_back(m.first);
  names.insert(names.end(), {"nis_mean", "nees_mean"});
  return names;
}

/// Seed of a session over a recording: it draws only the config's injected faults.
constexpr std::uint64_t kRecordingSeed = 1;

const detail::SeriesLabels kLabels{"t [s]", "ball position error |p_hat - p| [mm]", "t [s]", 2.0, "table x [m]",
                                   "table y [m]"};

class TableBallInstance final : public detail::ConfiguredInstance<scenarios::TableBallConfig, TableBallOptions> {
public:
  /// `cfg` as its reader validated it; the options only turn the wall-clock reference off and
  /// set a positive duration (nothing validate() would refuse).
  TableBallInstance(scenarios::TableBallConfig cfg, TableBallOptions opt) : ConfiguredInstance(std::move(cfg), opt) {
    cfg_.time_reference = false;
    if (opt_.duration > 0.0) cfg_.duration = opt_.duration;
  }

  RunResult run(std::uint64_t seed, const RunOptions& ro) const override {
    std::vector<BallFrame> frames;
    runtime::MemorySink telemetry;
    const scenarios::TableBallResult res = simulate(seed, ro, frames, &telemetry);
    RunResult r;
    r.seed = seed;
    const std::shared_ptr<RunSeries> series = detail::newSeries(ro.series, kLabels);
    Accum a;
    io::CsvWriter* inn = detail::logStream(ro, "innovations", {"t", "d0", "d1", "S00", "S01", "S11", "nis", "in_statistics"});
    consistency(frames, telemetry, a, series.get(), inn);
    r.nis = a.nis;
    r.nees = a.nees;
    auto& m = r.metrics;
    for (const auto& [name, field] : kResultMetrics) m[name] = res.*field;
    m["limits_respected"] = res.limits_respected ? 1.0 : 0.0;
    m["ball_detection_rate"] = res.frames > 0 ? static_cast<double>(res.ball_detections) / res.frames : std::nan("");
    if (cfg_.compare_tunings)
      for (const auto& [name, field] : kComparedTunings) m[name] = res.*field;
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
    auto d = newReplayData();
    for (int i = 0; i < runs; ++i) {
      d->items.emplace_back();
      simulate(core::deriveSeed(seed, static_cast<std::uint64_t>(i)), {}, d->items.back(), nullptr);
    }
    d->source = detail::liveSource(runs, seed);
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
    auto d = newReplayData();
    d->items.emplace_back();
    auto& run = d->items.back();
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

  /// A recording's frames through the observer as a footage session runs them
  /// (scenarios::runTableBallOnRecording): the same measurements (y, a_xy, t) a rig's footage gives
  /// the filter, from the frames alone; NIS only (a recording of a rig has no truth).
  std::unique_ptr<ReplayData> loadRecording(const std::string& dir) const override {
    if (!fs::exists(fs::path(dir) / "recording.csv"))
      throw core::InvalidInput(dir + ": not a recording (no recording.csv, as table_ball_balancing --record DIR writes)");
    runtime::MemorySink sink;
    scenarios::TableBallHooks hooks;
    hooks.telemetry = &sink;
    // The seed draws only the config's injected faults (faults:), as in a footage session.
    const scenarios::TableBallFootageSummary sum = scenarios::runTableBallOnRecording(cfg_, kRecordingSeed, dir, hooks);
    std::map<double, Eigen::Vector2d> balls;  // a frame's ball measurement, by its stamp
    for (const runtime::MeasurementRecord& z : sink.measurements)
      if (z.channel == "ball") balls[z.t] = z.z.head<2>();
    auto d = newReplayData();
    d->items.emplace_back();
    BallRun& run = d->items.back();
    for (const runtime::MeasurementRecord& z : sink.measurements) {  // every processed frame has its input
      if (z.channel != "ball_acceleration") continue;
      BallFrame f;
      f.t = z.t;
      f.a_xy = z.z.head<2>();
      if (const auto b = balls.find(z.t); b != balls.end()) f.y = b->second;
      run.push_back(f);
    }
    if (d->measurements() == 0)
      throw core::InvalidInput(dir + ": the ball was found in none of the recording's " + std::to_string(sum.frames) +
                               " frames (nothing to replay)");
    d->source = "recording " + dir + " (" + std::to_string(sum.frames) +
                " frames through the observer as on footage: each frame's PnP table pose, the head at its calibrated "
                "rest pose)";
    return d;
  }

  ReplayResult replay(const ReplayData& data, const std::vector<double>& noise, double outlier_prior,
                      bool want_series) const override {
    return detail::replayRecording<BallRun, Accum>(
        data, noise, 2, "table_ball", want_series, kLabels, [&](const TableBallReplayData& d, Accum& a, RunSeries* series) {
          for (const auto& run : d.items) replayRun(run, noise[0], noise[1], outlier_prior, a, series);
        });
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
    if (detail::logging(ro)) sinks.add(&csv.emplace(*ro.log));
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
        a.addCost(u.nis, std::log(S.determinant()), 2, 0.0, log_u);
        detail::addNis(a.nis, u.nis, 2.0, u.t, series);
      }
      if (inn != nullptr)
        inn->row({u.t, counted ? u.innovation[0] : std::nan(""), counted ? u.innovation[1] : std::nan(""), S(0, 0),
                  S(0, 1), S(1, 1), counted ? u.nis : std::nan(""), counted ? 1.0 : 0.0});
    }
    std::vector<const runtime::EstimateRecord*> estimates;
    for (const auto& e : telemetry.estimates)
      if (e.channel == "ball") estimates.push_back(&e);
    detail::TrackCurves c = makeCurves();
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
      Eigen::Matrix2d Pp;
      Pp << P(0, 0), P(0, 2), P(2, 0), P(2, 2);
      sample(f, p, Pp, f.prediction, measured, next_nees, a, series != nullptr ? &c : nullptr);
    }
    if (series != nullptr) c.moveInto(*series);
  }

  detail::TrackCurves makeCurves() const {
    detail::TrackCurves c;
    c.prediction.name = "prediction " + std::to_string(cfg_.observer.tracker.model.prediction_steps) + " frames ahead";
    return c;
  }

  /// The NEES sample (one every nees_spacing s once the track has burn_in measurements) and the
  /// curves of one frame's estimate: ball position `p` on the table, its covariance `Pp`.
  void sample(const BallFrame& f, const Eigen::Vector2d& p, const Eigen::Matrix2d& Pp,
              const std::optional<Eigen::Vector2d>& prediction, int measured, double& next_nees, Accum& a,
              detail::TrackCurves* c) const {
    if (f.has_truth && f.t >= next_nees && measured >= opt_.burn_in) {
      const Eigen::Vector2d d = p - f.truth;
      a.nees.add(d.dot(Pp.ldlt().solve(d)), 2.0);
      next_nees = f.t + opt_.nees_spacing;
    }
    if (c == nullptr) return;
    if (f.has_truth) {
      c->error.x.push_back(f.t);
      c->error.y.push_back(1e3 * (p - f.truth).norm());
      c->truth.x.push_back(f.truth.x());
      c->truth.y.push_back(f.truth.y());
    }
    c->estimate.x.push_back(p.x());
    c->estimate.y.push_back(p.y());
    if (prediction) {
      c->prediction.x.push_back(prediction->x());
      c->prediction.y.push_back(prediction->y());
    }
  }

  /// Replays logged measurements through the observer's filter with (σw, σv).
  void replayRun(const std::vector<BallFrame>& frames, double sigma_w, double sigma_v, double eps, Accum& a,
                 RunSeries* series) const {
    const tracking::RollingBallTrackerConfig tc = trackerConfig(sigma_w, sigma_v);
    tracking::RollingBallTracker trk(tc);
    const double side = tc.model.table_side - 2.0 * tc.model.ball_radius;
    const double log_u = -std::log(side * side);
    detail::TrackCurves c = makeCurves();
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
        a.addCost(nis, std::log(Eigen::Matrix2d(u->report.S).determinant()), 2, eps, log_u);
        detail::addNis(a.nis, nis, 2.0, f.t, series);
      }
      if (!trk.initialized()) continue;
      const Eigen::MatrixXd P = trk.P();
      Eigen::Matrix2d Pp;
      Pp << P(0, 0), P(0, 2), P(2, 0), P(2, 2);
      const std::optional<Eigen::Vector2d> prediction =
          trk.predictions().empty() ? std::nullopt : std::optional<Eigen::Vector2d>(trk.predictions().back());
      sample(f, trk.position(), Pp, prediction, measured, next_nees, a, series != nullptr ? &c : nullptr);
    }
    if (series != nullptr) c.moveInto(*series);
  }
};

}  // namespace

void registerTableBallAdapter(AdapterRegistry& registry) {
  registry.add(detail::makeAdapter(
      {"table_ball", "table-ball balancing of [M] (rendered table and ball, rolling-ball observer, LQR; config/table_ball.yaml)",
       "table_ball_balancing", "--headless --summary table_ball_summary.json", "observer_rmse_mm", true, metricNames()},
      tableBallOptions(), [](const io::ConfigNode& config, const TableBallOptions& o) {
        return std::make_unique<TableBallInstance>(scenarios::tableBallConfigFromYaml(config), o);
      }));
}

}  // namespace viewline::tuning
