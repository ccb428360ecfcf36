// Pan-tilt scenario adapter ([T]): runs scenarios::runPanTilt (rendered images, [T] detection, the
// predictive controller; the ViSP baseline is not run in sweeps) in-process, with the config read by
// the scenario's own loader (loadPanTiltScenarioConfig: strict keys), so a config the tuning tool
// accepts or writes is one pan_tilt_tracking reads.
//
// Innovations. A live run reports them to a runtime::MemorySink: for every detected frame the
// controller's gate decision, d = z − p̂(t|t−) and S = P_pos(t|t−) + R (2 dof) of its filter, and its
// estimate after the update; the truth and the image error of every frame. NIS samples once a track
// has `burn_in` accepted measurements; NEES (2 dof, screen position) against the truth, one sample
// every `nees_spacing_s` seconds (spaced so that they are nearly independent). Replays with other
// noise parameters (auto-tuning) re-run the same filter (tracking::PlanarTargetFilter, same
// measurements, time stamps and R, the controller's reacquisition rule: re-initialise after
// control.coast_time without an accepted measurement) on the recorded frames.
//
// Noise parameters: process q = filter.q (CV: m²/s³, CA: m²/s⁵) and a measurement-noise scale
// (the filter's R = scale² × the scenario's R). The scenario gives the filter the true R
// (measurement_noise_fraction × path amplitude, carried by each observation) and has no key that
// changes the filter's R alone, so the scale is estimated (≈ 1 confirms the noise model) but only
// q can be written to the config and used in live runs. Needed hook (for the scenario's owner): a
// key such as filter.measurement_noise_scale multiplying TargetObservation::plane_cov inside the
// controller.

#include <Eigen/Cholesky>
#include <atomic>
#include <cmath>
#include <filesystem>
#include <limits>
#include <map>
#include <optional>

#include "adapter_util.h"
#include "pan_tilt_recording.h"
#include "viewline/control/pan_tilt_servo.h"
#include "viewline/core/error.h"
#include "viewline/core/random.h"
#include "viewline/io/log.h"
#include "viewline/runtime/telemetry.h"
#include "viewline/scenarios/pan_tilt_scenario.h"
#include "viewline/tuning/scenario.h"

namespace viewline::tuning {

namespace {

namespace fs = std::filesystem;

struct Frame {
  double t = 0.0;
  bool detected = false;
  Eigen::Vector2d z = Eigen::Vector2d::Zero(), truth = Eigen::Vector2d::Zero();
  double error_px = 0.0;
};

struct Recorded {
  std::vector<Frame> frames;
  Eigen::Matrix2d R = Eigen::Matrix2d::Identity();
  bool has_truth = true;
};

using PanTiltReplayData = detail::Recording<Recorded>;

std::size_t detectedFrames(const Recorded& r) {
  std::size_t n = 0;
  for (const auto& f : r.frames) n += f.detected;
  return n;
}

std::unique_ptr<PanTiltReplayData> newReplayData() {
  return std::make_unique<PanTiltReplayData>("pan-tilt run(s)", "measurements", &detectedFrames);
}

std::vector<Frame> readFrames(const std::string& path) {
  const detail::CsvTable csv = detail::CsvTable::read(path, "predictive_frames.csv of pan_tilt_tracking --log");
  const std::size_t ct = csv.col("t"), cd = csv.col("detected"), cx = csv.col("meas_x"), cy = csv.col("meas_y"),
                    tx = csv.col("truth_x"), ty = csv.col("truth_y"), ce = csv.col("error_px");
  std::vector<Frame> frames;
  for (std::size_t row = 0; row < csv.rows(); ++row) {
    Frame fr;
    fr.t = csv.number(row, ct);
    fr.detected = csv.number(row, cd) > 0.5;
    if (fr.detected) fr.z = Eigen::Vector2d(csv.number(row, cx), csv.number(row, cy));
    fr.truth = Eigen::Vector2d(csv.number(row, tx), csv.number(row, ty));
    fr.error_px = csv.number(row, ce);
    frames.push_back(fr);
  }
  return frames;
}

/// The adapter options (declared with their defaults and ranges in registerPanTiltAdapter).
struct PanTiltOptions {
  double duration;       ///< s; 0: the config's
  int burn_in;           ///< accepted measurements of a track before its innovations count
  double nees_spacing;   ///< s between NEES samples
  std::uint64_t log_seed;
};

/// The adapter options: type, range, default and help of each, bound to its field.
detail::OptionTable<PanTiltOptions> panTiltOptions() {
  detail::OptionTable<PanTiltOptions> options;
  options.number("duration", &PanTiltOptions::duration, "0", 0.0, detail::kUnbounded, "s of each run (0: the config's run.duration)")
      .integer("burn_in", &PanTiltOptions::burn_in, "5", 1, 1e6, "accepted measurements of a track before its innovations count")
      .number("nees_spacing_s", &PanTiltOptions::nees_spacing, "2", 1e-9, detail::kUnbounded, "s between NEES samples (nearly independent)")
      .integer("log_seed", &PanTiltOptions::log_seed, "1", 0, 1e15,
               "seed of the run a --log folder comes from (its path amplitude gives R; a --recording carries its R)");
  return options;
}

using Accum = detail::InnovationTally;

const detail::SeriesLabels kLabels{"t [s]", "image error |true target - image centre| [px]", "t [s]", 2.0,
                                   "screen x (right) [m]", "screen y (down) [m]"};
constexpr double kHorizon = 0.2;  // s, the prediction drawn in the trajectory plot

detail::TrackCurves makeCurves() {
  detail::TrackCurves c;
  c.prediction.name = "prediction 0.2 s ahead";
  return c;
}

/// The live error curve of a run (RunOptions::live), fed frame by frame.
class LiveCurve : public scenarios::pan_tilt::FrameSink {
public:
  explicit LiveCurve(std::function<void(const LiveSample&)> live) : live_(std::move(live)) {}
  void frame(const scenarios::pan_tilt::FrameRecord& r) override {
    if (live_) live_({r.t, r.error_px, -1.0});
  }

private:
  std::function<void(const LiveSample&)> live_;
};

class PanTiltInstance final : public detail::ConfiguredInstance<scenarios::PanTiltScenarioConfig, PanTiltOptions> {
public:
  PanTiltInstance(scenarios::PanTiltScenarioConfig cfg, PanTiltOptions opt, double r_scale)
      : ConfiguredInstance(std::move(cfg), opt), r_scale_(r_scale) {
    cfg_.run_baseline = false;
    if (opt_.duration > 0.0) cfg_.duration = opt_.duration;
  }

  /// The R the scenario gives the filter for a seed (its own helpers: the same path and amplitude).
  Eigen::Matrix2d trueR(std::uint64_t seed) const {
    namespace pt = scenarios::pan_tilt;
    return pt::noiseCovariance(pt::noiseSigma(cfg_, pt::makePath(cfg_, seed)));
  }

  /// One live run of ours: its metrics and telemetry (in `sink`), and the frames a replay needs.
  Recorded recordOne(std::uint64_t seed, const RunOptions& ro, scenarios::PanTiltRunMetrics* metrics,
                     runtime::MemorySink& sink) const {
    // The live error curve during the run (--display: the camera view lives in the viz module,
    // which the tuning module does not link), and with a log the frames CSV pan_tilt_tracking writes.
    LiveCurve live(ro.live);
    std::optional<scenarios::pan_tilt::FrameCsvSink> csv;
    scenarios::pan_tilt::FrameFanout frames;
    if (ro.live) frames.add(&live);
    if (detail::logging(ro)) frames.add(&csv.emplace(*ro.log));
    scenarios::PanTiltRunIo io;
    io.telemetry = &sink;
    io.frames = frames.empty() ? nullptr : &frames;
    io.progress = ro.progress;
    const scenarios::PanTiltRunMetrics m = scenarios::runPanTilt(cfg_, seed, scenarios::PanTiltControllerKind::Predictive, io);
    if (metrics != nullptr) *metrics = m;
    const std::string name = m.controller;
    Recorded rec;
    std::map<std::uint64_t, std::size_t> frame_of;  // measurement id -> frame
    std::size_t i = 0;
    for (const auto& t : sink.measurements) {
      if (t.channel != scenarios::truthChannel(name)) continue;
      Frame fr;
      fr.t = t.t;
      fr.truth = t.z.head<2>();
      frame_of[t.id] = rec.frames.size();
      rec.frames.push_back(fr);
    }
    for (const auto& e : sink.scalars)
      if (e.channel == scenarios::imageErrorChannel(name) && i < rec.frames.size()) rec.frames[i++].error_px = e.value;
    for (const auto& z : sink.measurements) {
      if (z.channel != name) continue;
      Frame& fr = rec.frames.at(frame_of.at(z.id));
      fr.detected = true;
      fr.z = z.z.head<2>();
    }
    rec.R = trueR(seed);
    return rec;
  }

  RunResult run(std::uint64_t seed, const RunOptions& ro) const override {
    scenarios::PanTiltRunMetrics m;
    runtime::MemorySink sink;
    const Recorded rec = recordOne(seed, ro, &m, sink);
    RunResult r;
    r.seed = seed;
    const std::shared_ptr<RunSeries> series = detail::newSeries(ro.series, kLabels);
    Accum a;
    io::CsvWriter* inn =
        detail::logStream(ro, "innovations", {"t", "d0", "d1", "S00", "S01", "S11", "nis", "accepted", "in_statistics"});
    scoreRun(rec, sink, m.controller, a, series.get(), inn);
    r.nis = a.nis;
    r.nees = a.nees;
    r.metrics["image_error_rms_px"] = m.image_error_rms_px;
    r.metrics["image_error_max_px"] = m.image_error_max_px;
    r.metrics["rmse_filtered_x_cm"] = m.rmse_filtered_cm.x();
    r.metrics["rmse_filtered_y_cm"] = m.rmse_filtered_cm.y();
    r.metrics["rmse_filtered_cm"] = std::sqrt(0.5 * (m.rmse_filtered_cm.squaredNorm()));
    r.metrics["rmse_measured_cm"] = std::sqrt(0.5 * (m.rmse_measured_cm.squaredNorm()));
    r.metrics["reacquisition_delay_s"] = m.reacquisition_delay_s;
    r.metrics["nis_mean"] = a.nis.mean();
    r.metrics["nees_mean"] = a.nees.mean();
    r.verdict = combinedVerdict(r.nees, r.nis, 0.99);
    r.series = series;
    return r;
  }

  std::vector<NoiseParameter> noiseParameters() const override {
    // The IMM / CT filters have several process-noise densities (per mode); filter.q alone barely
    // changes their likelihood (measured: the search drifts to q -> 0), so they are not auto-tuned.
    // The waypoint particle filter has no process noise at all (its model is the path's generator).
    if (cfg_.control.filter.model == tracking::TargetModel::WaypointParticles)
      throw core::InvalidInput("pan-tilt auto-tuning: filter.model waypoint_particles has no process noise to tune (its "
                               "model is the random path's generator); sweeps work with every model");
    if (cfg_.control.filter.model == tracking::TargetModel::Imm ||
        cfg_.control.filter.model == tracking::TargetModel::CoordinatedTurn)
      throw core::InvalidInput(std::string("pan-tilt auto-tuning: filter.model ") + tracking::toString(cfg_.control.filter.model) +
                               " has one process noise per mode; auto-tuning supports constant_velocity, "
                               "constant_acceleration and singer (e.g. config/sweeps/scenarios/pan_tilt_circle_ca.yaml); "
                               "sweeps work with every model");
    // The mixture (the shipped model) tunes its cv part's q (acceleration density, as constant_velocity):
    // the density of its plain CV steps before the first constant-speed leg (the legs have no process
    // noise); the ct part's ct_q_accel and ct_q_omega are left as configured.
    const tracking::TargetModel model = cfg_.control.filter.model;
    const bool mixture = model == tracking::TargetModel::Mixture;
    return {{"process", "q",
             model == tracking::TargetModel::ConstantVelocity || mixture ? "m^2/s^3" : "m^2/s^5", "filter.q",
             mixture ? "process noise density of the mixture's cv part (before its first constant-speed leg)"
                     : "process noise density of the target filter",
             cfg_.control.filter.q},
            {"measurement", "R_scale", "x", "",
             "filter R = R_scale^2 x the scenario's R (estimated; no config key: see the adapter's note)", r_scale_}};
  }

  std::unique_ptr<ReplayData> record(std::uint64_t seed, int runs) const override {
    auto d = newReplayData();
    for (int i = 0; i < runs; ++i) {
      runtime::MemorySink sink;
      d->items.push_back(recordOne(core::deriveSeed(seed, static_cast<std::uint64_t>(i)), {}, nullptr, sink));
    }
    d->source = detail::liveSource(runs, seed);
    return d;
  }

  std::unique_ptr<ReplayData> loadLog(const std::string& dir) const override {
    auto d = newReplayData();
    Recorded rec;
    rec.frames = readFrames((fs::path(dir) / "predictive_frames.csv").string());
    rec.R = trueR(opt_.log_seed);
    d->items.push_back(rec);
    d->source = dir + "/predictive_frames.csv (R from the config, seed option log_seed)";
    return d;
  }

  /// A recording's frames through the scenario's detector and back-projection at the recorded joint
  /// readings (pan_tilt_recording.h): no unit, no simulator, no seed; NIS only (a recording of a real
  /// rig has no truth).
  std::unique_ptr<ReplayData> loadRecording(const std::string& dir) const override {
    const detail::PanTiltRecordedMeasurements m = detail::panTiltRecordedMeasurements(cfg_, dir);
    Recorded rec;
    rec.R = m.R;
    rec.has_truth = false;
    const double nan = std::nan("");
    for (const detail::PanTiltRecordedFrame& f : m.frames) {
      Frame fr;
      fr.t = f.t;
      fr.detected = f.detected;
      fr.z = f.z;
      fr.truth = Eigen::Vector2d::Constant(nan);
      fr.error_px = nan;
      rec.frames.push_back(fr);
    }
    auto d = newReplayData();
    d->items.push_back(std::move(rec));
    d->source = "recording " + m.dir + " (" + std::to_string(m.grabs) +
                " grabs through the scenario's detector, back-projected at the unit readings of its ptu.csv)";
    return d;
  }

  ReplayResult replay(const ReplayData& data, const std::vector<double>& noise, double outlier_prior,
                      bool want_series) const override {
    return detail::replayRecording<Recorded, Accum>(
        data, noise, 2, "pan-tilt", want_series, kLabels, [&](const PanTiltReplayData& d, Accum& a, RunSeries* series) {
          for (const auto& rec : d.items) replayRun(rec, noise[0], noise[1], outlier_prior, a, series, nullptr, {});
        });
  }

  std::unique_ptr<ScenarioInstance> withNoise(const std::vector<double>& noise) const override {
    scenarios::PanTiltScenarioConfig c = cfg_;
    c.control.filter.q = noise.at(0);
    return std::make_unique<PanTiltInstance>(c, opt_, noise.at(1));
  }

private:
  /// NIS, NEES and the innovation cost of a live run, read from its telemetry: the controller's own
  /// gate decisions, innovations and estimates (nothing re-run).
  void scoreRun(const Recorded& rec, const runtime::MemorySink& sink, const std::string& name, Accum& a,
                RunSeries* series, io::CsvWriter* inn) const {
    using tracking::GateDecision;
    const double u = 1.0 / (cfg_.screen_width * cfg_.screen_height);
    detail::TrackCurves c = makeCurves();
    if (series != nullptr)
      for (const Frame& f : rec.frames) addFrame(c, f);
    std::vector<const runtime::EstimateRecord*> estimates;
    for (const auto& e : sink.estimates)
      if (e.channel == name) estimates.push_back(&e);
    std::map<std::uint64_t, Eigen::Vector2d> truth;  // by measurement id (the frame's)
    for (const auto& t : sink.measurements)
      if (t.channel == scenarios::truthChannel(name)) truth[t.id] = t.z.head<2>();
    double next_nees = cfg_.metrics_start;
    int accepted_in_track = 0;
    std::size_t k = 0;
    for (const runtime::InnovationRecord& r : sink.innovations) {
      if (r.channel != name) continue;
      const runtime::EstimateRecord& e = *estimates.at(k++);
      const GateDecision d = r.decision;
      bool have = false;
      double nis = 0.0;
      if (d != GateDecision::Start && accepted_in_track >= opt_.burn_in && r.innovation.size() == 2) {
        const Eigen::LLT<Eigen::Matrix2d> llt(Eigen::Matrix2d(r.S));
        if (llt.info() == Eigen::Success) {
          const Eigen::Vector2d dv = r.innovation;
          nis = dv.dot(llt.solve(dv));
          have = std::isfinite(nis);
        }
      }
      if (d == GateDecision::Start || d == GateDecision::Restart) accepted_in_track = 0;
      const bool accepted = tracking::uses(d);
      if (accepted) ++accepted_in_track;
      if (have) {
        a.addCost(nis, std::log(Eigen::Matrix2d(r.S).determinant()), 2, 0.0, std::log(u));
        if (d == GateDecision::Accept) detail::addNis(a.nis, nis, 2.0, r.t, series);
      }
      if (inn != nullptr) {
        const double nan = std::nan("");
        inn->row({r.t, have ? r.innovation(0) : nan, have ? r.innovation(1) : nan, have ? r.S(0, 0) : nan,
                  have ? r.S(0, 1) : nan, have ? r.S(1, 1) : nan, have ? nis : nan, accepted ? 1.0 : 0.0,
                  have && accepted ? 1.0 : 0.0});
      }
      const Eigen::Vector2d p = e.x.head<2>(), v = e.x.segment<2>(2);
      const auto t = truth.find(r.id);
      if (rec.has_truth && t != truth.end() && d != GateDecision::Start && accepted && r.t >= next_nees &&
          accepted_in_track >= opt_.burn_in) {
        const Eigen::Vector2d ex = p - t->second;
        a.nees.add(ex.dot(Eigen::Matrix2d(e.P).ldlt().solve(ex)), 2.0);
        next_nees = r.t + opt_.nees_spacing;
      }
      if (series != nullptr)
        addEstimate(c, p, p + kHorizon * v);  // constant velocity from the published estimate
    }
    if (series != nullptr) c.moveInto(*series);
  }

  static void addFrame(detail::TrackCurves& c, const Frame& f) {
    c.error.x.push_back(f.t);
    c.error.y.push_back(f.error_px);
    c.truth.x.push_back(f.truth.x());
    c.truth.y.push_back(f.truth.y());
  }

  static void addEstimate(detail::TrackCurves& c, const Eigen::Vector2d& p, const Eigen::Vector2d& ahead) {
    c.estimate.x.push_back(p.x());
    c.estimate.y.push_back(p.y());
    c.prediction.x.push_back(ahead.x());
    c.prediction.y.push_back(ahead.y());
  }

  void replayRun(const Recorded& rec, double q, double r_scale, double eps, Accum& a, RunSeries* series,
                 io::CsvWriter* inn, const RunOptions& ro) const {
    tracking::TargetFilterConfig fc = cfg_.control.filter;
    fc.q = q;
    tracking::PlanarTargetFilter filter(fc);
    const Eigen::Matrix2d R = r_scale * r_scale * rec.R;
    const double u = 1.0 / (cfg_.screen_width * cfg_.screen_height);
    detail::TrackCurves c = makeCurves();
    double last_accepted = -1e300, next_nees = cfg_.metrics_start;
    int accepted_in_track = 0;
    for (const Frame& f : rec.frames) {
      if (series != nullptr) addFrame(c, f);
      if (!f.detected) {
        if (ro.live) ro.live({f.t, f.error_px, -1.0});
        continue;
      }
      if (filter.initialized() && f.t - last_accepted > cfg_.control.coast_time) {
        filter.reset(f.t, f.z, R);  // reacquisition after a loss (the controller's rule)
        accepted_in_track = 1;
        last_accepted = f.t;
        continue;
      }
      bool have = false;
      double nis = 0.0;
      Eigen::Vector2d d = Eigen::Vector2d::Zero();
      Eigen::Matrix2d S = Eigen::Matrix2d::Identity();
      if (filter.initialized() && accepted_in_track >= opt_.burn_in) {
        const tracking::PlanarTargetFilter::Kinematics k = filter.at(f.t);
        d = f.z - k.p;
        S = k.P_pos + R;
        const Eigen::LLT<Eigen::Matrix2d> llt(S);
        if (llt.info() == Eigen::Success) {
          nis = d.dot(llt.solve(d));
          have = std::isfinite(nis);
        }
      }
      const tracking::PlanarTargetFilter::Update up = filter.update(f.t, f.z, R);
      if (up.reinitialized) accepted_in_track = 0;
      if (up.accepted) {
        ++accepted_in_track;
        last_accepted = f.t;
      }
      if (have) {
        a.addCost(nis, std::log(S.determinant()), 2, eps, std::log(u));
        if (up.accepted && !up.reinitialized) detail::addNis(a.nis, nis, 2.0, f.t, series);
      }
      if (inn != nullptr)
        inn->row({f.t, have ? d(0) : std::nan(""), have ? d(1) : std::nan(""), have ? S(0, 0) : std::nan(""),
                  have ? S(0, 1) : std::nan(""), have ? S(1, 1) : std::nan(""), have ? nis : std::nan(""),
                  up.accepted ? 1.0 : 0.0, have && up.accepted ? 1.0 : 0.0});
      if (ro.live) ro.live({f.t, f.error_px, have && up.accepted ? nis : -1.0});
      if (filter.initialized() && rec.has_truth && up.accepted && f.t >= next_nees && accepted_in_track >= opt_.burn_in) {
        const tracking::PlanarTargetFilter::Kinematics k = filter.at(f.t);
        const Eigen::Vector2d e = k.p - f.truth;
        a.nees.add(e.dot(k.P_pos.ldlt().solve(e)), 2.0);
        next_nees = f.t + opt_.nees_spacing;
      }
      if (series != nullptr && filter.initialized()) addEstimate(c, filter.at(f.t).p, filter.at(f.t + kHorizon).p);
    }
    if (series != nullptr) c.moveInto(*series);
  }

  double r_scale_ = 1.0;
};

}  // namespace

void registerPanTiltAdapter(AdapterRegistry& registry) {
  registry.add(detail::makeAdapter(
      {"pan_tilt", "pan-tilt tracking of [T] (rendered screen target, predictive controller; config/pan_tilt_*.yaml)",
       "pan_tilt_tracking", "--headless --summary pan_tilt_summary.json", "image_error_rms_px", true,
       {"image_error_rms_px", "image_error_max_px", "rmse_filtered_cm", "rmse_filtered_x_cm", "rmse_filtered_y_cm",
        "rmse_measured_cm", "reacquisition_delay_s", "nis_mean", "nees_mean"}},
      panTiltOptions(), [](const io::ConfigNode& config, const PanTiltOptions& o) {
        // The loader validated the config; the run length the option sets must still cover the
        // metrics' start (run.metrics_start < run.duration, as validate() requires of the file).
        scenarios::PanTiltScenarioConfig cfg = scenarios::loadPanTiltScenarioConfig(config);
        if (o.duration > 0.0 && !(o.duration > cfg.metrics_start))
          throw core::InvalidInput(config.fileName() + ": adapter option duration: expected > run.metrics_start");
        return std::make_unique<PanTiltInstance>(std::move(cfg), o, 1.0);
      }));
}

}  // namespace viewline::tuning
