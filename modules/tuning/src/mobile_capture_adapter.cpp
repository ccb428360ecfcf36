// Mobile-capture scenario adapter ([K]): runs scenarios::runMobileCapture (rendered head camera,
// red-blob detection, ground back-projection, the unicycle track, LS predictor, capture planner,
// base and head control, grasp; and the oracle on the same object path) in-process, with the
// config read by the scenario's own loader (loadMobileCaptureConfig: strict keys), so a config the
// tuning tool accepts or writes is one mobile_capture reads. One run = one chase (seed).
//
// Consistency: the run's own position NEES (2 dof, against P_s + B, one sample every
// scenarios::kNeesSpacing s once the track has been valid kConsistencySettle s: MobileCaptureRun),
// and the NIS from the run's telemetry (a runtime::MemorySink; no files): the track's own
// innovation records (2 dof, accepted or gated out) once the track has been valid for `settle_s`
// (default the loop's kConsistencySettle, so the two agree).
//
// Noise auto-tuning: the noise parameters are the track's random walks q_v, q_w and the white
// blob-centre noise σ_px (R = σ_px² J Jᵀ, J the ground-projection Jacobian of each detection). A
// recording keeps every detection's floor point, J Jᵀ and time stamp; the replay runs a fresh
// unicycle track (same start, gate and restart rule) on them. The head aims the camera at the
// filter's prediction, so which frames see the object depends on the filter that ran: the
// likelihood of the recorded innovations is still the prediction-error decomposition of what was
// measured (the camera's aim is a function of earlier measurements only), but a noise far from the
// recording's would have aimed the camera differently; hence the fresh-seed check of the session,
// a live run of the tuned config.
//
// From a recording (mobile_capture --record DIR: session.json and run_iii/, or one run's folder),
// with no robot, simulator, seed or truth: a detection becomes the track's measurement only through
// the head camera's pose at its frame, which head.csv holds per frame (the base's odometry pose and
// the pan/tilt joints the loop read, scenarios::headTableColumns()). Each recorded frame goes
// through the loop's own screens, detector (windowed around the config's track) and floor
// measurement with the camera at that reading (scenarios::mobileCaptureRecordedMeasurements); with
// the recording's config these are the live run's detections bit for bit. The replay then runs
// on them as on live ones; truth.csv is not read (NIS only). The frame faults of the config, if
// any, are drawn from a fixed seed, as in a footage session.

#include <cmath>
#include <limits>
#include <map>
#include <memory>

#include "adapter_util.h"
#include "recorded_units.h"
#include "viewline/core/error.h"
#include "viewline/runtime/telemetry.h"
#include "viewline/scenarios/mobile_capture.h"
#include "viewline/tuning/scenario.h"
#include "viewline/tracking/unicycle_tracker.h"
// The camera view lives in the viz module; it is shown when this library links viz.
#if __has_include("viewline/viz/mobile_capture_display.h")
#include "viewline/viz/mobile_capture_display.h"
#define VIEWLINE_MOBILE_CAPTURE_VIEW 1
#endif

namespace viewline::tuning {

namespace {

/// The adapter options (declared with their defaults and ranges in registerMobileCaptureAdapter).
struct MobileOptions {
  double max_time;      ///< s; 0: the config's world.max_time
  double settle;        ///< s of valid track before NIS samples
};

/// The adapter options: type, range, default and help of each, bound to its field.
detail::OptionTable<MobileOptions> mobileOptions() {
  detail::OptionTable<MobileOptions> options;
  options.number("max_time", &MobileOptions::max_time, "0", 0.0, detail::kUnbounded,
                 "s, time limit of a chase (0: the config's world.max_time)")
      .number("settle_s", &MobileOptions::settle, "2", 0.0, detail::kUnbounded,
              "s a track must have been valid before its NIS samples count");
  return options;
}

/// One detection as the track saw it (the replay's input).
struct Detection {
  double t = 0.0;                                          ///< s, capture time
  Eigen::Vector2d z = Eigen::Vector2d::Zero();             ///< m, floor point
  Eigen::Matrix2d unit_pixel_cov = Eigen::Matrix2d::Zero();  ///< m²/px², J Jᵀ
};
using Chase = std::vector<Detection>;
/// Seed of the frame faults (if the config has any) when a recording is replayed.
constexpr std::uint64_t kRecordingSeed = 1;
using MobileReplayData = detail::Recording<Chase>;
std::size_t chaseDetections(const Chase& c) { return c.size(); }

const detail::SeriesLabels kLabels{"t [s]", "object position error |p_hat - p| [m]", "t [s]", 2.0, "floor x [m]",
                                   "floor y [m] (black: object and robot paths)"};

class MobileInstance final : public detail::ConfiguredInstance<scenarios::MobileCaptureConfig, MobileOptions> {
public:
  /// `cfg` as its reader validated it; the options only set a positive time limit.
  MobileInstance(scenarios::MobileCaptureConfig cfg, MobileOptions opt) : ConfiguredInstance(std::move(cfg), opt) {
    if (opt_.max_time > 0.0) cfg_.max_time = opt_.max_time;
  }

  std::vector<NoiseParameter> noiseParameters() const override {
    return {{"process", "q_v", "m^2/s^3", "filter.q_v", "random-walk intensity of the object's speed", cfg_.filter.model.q_v},
            {"process_turn", "q_w", "rad^2/s^3", "filter.q_w", "random-walk intensity of the object's turn rate",
             cfg_.filter.model.q_w},
            {"measurement", "sigma_px", "px", "detector.pixel_sigma", "white blob-centre noise (R = sigma^2 J J')",
             cfg_.pixel_sigma}};
  }

  std::unique_ptr<ReplayData> record(std::uint64_t seed, int runs) const override {
    auto d = std::make_unique<MobileReplayData>("chases", "detections", &chaseDetections);
    for (int i = 0; i < runs; ++i) {
      d->items.emplace_back();
      Chase& chase = d->items.back();
      scenarios::MobileCaptureHooks hooks;
      hooks.on_frame = [&](const scenarios::MobileCaptureFrame& f) {
        if (f.measurement) chase.push_back({f.t, f.measurement->z, f.measurement->unit_pixel_cov});
      };
      scenarios::runMobileCapture(cfg_, core::deriveSeed(seed, static_cast<std::uint64_t>(i)), &hooks);
    }
    d->source = detail::liveSource(runs, seed);
    return d;
  }

  std::unique_ptr<ReplayData> loadLog(const std::string&) const override {
    throw core::InvalidInput(
        "mobile_capture: auto-tuning from a --log folder is not supported (the log has no ground-projection Jacobian "
        "of each detection); record live runs instead (viewline_tune autotune without --log, --record-seed N)");
  }

  /// A recording's runs (header comment): every frame through the loop's perception, placed on
  /// the floor with the head camera at its head.csv reading; the detections the track was given kept.
  std::unique_ptr<ReplayData> loadRecording(const std::string& dir) const override {
    const std::vector<std::string> run_dirs = detail::recordedUnitDirs(dir, "mobile_capture", "run");
    auto d = std::make_unique<MobileReplayData>("chases", "detections", &chaseDetections);
    std::size_t frames = 0;
    for (std::size_t i = 0; i < run_dirs.size(); ++i) {
      const scenarios::RecordedMobileCaptureRun run = scenarios::mobileCaptureRecordedMeasurements(
          cfg_, run_dirs[i], core::deriveSeed(kRecordingSeed, static_cast<std::uint64_t>(i)));
      frames += run.frames;
      Chase chase;
      for (const scenarios::RecordedFloorMeasurement& m : run.measurements)
        chase.push_back({m.t, m.floor.z, m.floor.unit_pixel_cov});
      d->items.push_back(std::move(chase));
    }
    if (d->measurements() == 0)
      throw core::InvalidInput(dir + ": the object was detected in none of the recording's frames");
    d->source = "recording " + dir + " (" + std::to_string(run_dirs.size()) + " run(s), " + std::to_string(frames) +
                " frames through the loop's detector, placed with the head readings of head.csv)";
    return d;
  }

  ReplayResult replay(const ReplayData& data, const std::vector<double>& noise, double outlier_prior,
                      bool want_series) const override {
    return detail::replayRecording<Chase, detail::InnovationTally>(
        data, noise, 3, "mobile_capture", want_series, kLabels,
        [&](const MobileReplayData& d, detail::InnovationTally& a, RunSeries* series) {
          for (const Chase& c : d.items) replayChase(c, noise, outlier_prior, a, series);
        });
  }

  std::unique_ptr<ScenarioInstance> withNoise(const std::vector<double>& noise) const override {
    if (noise.size() != 3) throw core::InvalidInput("mobile_capture: expected (q_v, q_w, sigma_px)");
    scenarios::MobileCaptureConfig c = cfg_;
    c.filter.model.q_v = noise[0];
    c.filter.model.q_w = noise[1];
    c.pixel_sigma = noise[2];
    return std::make_unique<MobileInstance>(c, opt_);
  }

  RunResult run(std::uint64_t seed, const RunOptions& ro) const override {
#ifdef VIEWLINE_MOBILE_CAPTURE_VIEW
    std::unique_ptr<viz::MobileCaptureDisplay> view;
    if (ro.display && detail::xDisplayAvailable()) {
      try {
        view = std::make_unique<viz::MobileCaptureDisplay>(cfg_);
      } catch (const std::exception&) {
        view.reset();
      }
    }
#endif
    const std::shared_ptr<RunSeries> series = detail::newSeries(ro.series, kLabels);
    Curve err{"position error", {}, {}}, obj{"object", {}, {}}, robot{"robot", {}, {}}, est{"estimate", {}, {}};
    double sq = 0.0;
    std::size_t n = 0;
    double next_prediction = 5.0;
    runtime::MemorySink memory;
    std::unique_ptr<runtime::CsvSink> csv;
    runtime::FanoutSink sinks;
    sinks.add(&memory);
    if (ro.log) {
      csv = std::make_unique<runtime::CsvSink>(*ro.log);
      sinks.add(csv.get());
    }
    scenarios::MobileCaptureHooks hooks;
    hooks.telemetry = &sinks;
    hooks.on_frame = [&](const scenarios::MobileCaptureFrame& f) {
#ifdef VIEWLINE_MOBILE_CAPTURE_VIEW
      if (view) view->show(f);
#endif
      double e = std::nan("");
      if (f.estimate_valid && f.estimate.size() >= 2) {
        e = (f.estimate.head<2>() - f.object_true).norm();
        sq += e * e;
        ++n;
      }
      if (ro.progress) ro.progress(std::min(1.0, f.t / cfg_.max_time));
      if (ro.live) ro.live({f.t, e, -1.0});
      if (!series) return;
      obj.x.push_back(f.object_true.x());
      obj.y.push_back(f.object_true.y());
      robot.x.push_back(f.robot.x);
      robot.y.push_back(f.robot.y);
      if (!std::isfinite(e)) return;
      err.x.push_back(f.t);
      err.y.push_back(e);
      est.x.push_back(f.estimate(0));
      est.y.push_back(f.estimate(1));
      if (f.t >= next_prediction && !f.prediction.empty()) {
        Curve p{"prediction at t = " + std::to_string(static_cast<int>(f.t)) + " s", {}, {}};
        for (const auto& q : f.prediction) {
          p.x.push_back(q.x());
          p.y.push_back(q.y());
        }
        series->prediction.push_back(p);
        next_prediction = f.t + 10.0;
      }
    };
    const scenarios::MobileCaptureRun res = scenarios::runMobileCapture(cfg_, seed, &hooks);
    RunResult r;
    r.seed = seed;
    consistency(memory, r.nis, series.get());
    r.nees.sum = res.nees_sum;
    r.nees.dof_sum = 2.0 * static_cast<double>(res.nees_count);
    r.nees.count = static_cast<std::size_t>(res.nees_count);
    auto& m = r.metrics;
    m["captured"] = res.captured ? 1.0 : 0.0;
    m["capture_time_s"] = res.capture_time;
    m["oracle_captured"] = res.oracle_captured ? 1.0 : 0.0;
    m["capture_time_ratio_to_oracle"] =
        res.captured && res.oracle_captured && res.oracle_time > 0.0 ? res.capture_time / res.oracle_time : std::nan("");
    m["grasp_attempts"] = res.grasp_attempts;
    m["detection_rate"] = res.frames > 0 ? static_cast<double>(res.detections) / res.frames : std::nan("");
    m["longest_lost_s"] = res.longest_lost;
    m["localization_rmse_mm"] =
        res.localization.count > 0 ? 1e3 * std::sqrt(res.localization.sse_exact / res.localization.count) : std::nan("");
    m["estimate_rmse_mm"] = n > 0 ? 1e3 * std::sqrt(sq / static_cast<double>(n)) : std::nan("");
    m["nees_mean"] = r.nees.mean();
    m["nis_mean"] = r.nis.mean();
    r.verdict = combinedVerdict(r.nees, r.nis, confidence());
    if (series) {
      series->error.push_back(err);
      series->truth.push_back(obj);
      series->truth.push_back(robot);
      series->estimate.push_back(est);
      r.series = series;
    }
    return r;
  }

private:
  /// The track of the loop on one chase's detections with noise (q_v, q_w, σ_px): the NIS of every
  /// tested detection once its track has been valid for settle_s, and its cost term (a gross
  /// outlier is uniform over the image: density 1 / (W H |det J|) on the floor).
  void replayChase(const Chase& chase, const std::vector<double>& noise, double eps, detail::InnovationTally& a,
                   RunSeries* series) const {
    tracking::UnicycleTrackerConfig tc = cfg_.filter;
    tc.model.q_v = noise[0];
    tc.model.q_w = noise[1];
    tracking::UnicycleTracker track(tc);
    const double log_image = std::log(static_cast<double>(cfg_.width) * static_cast<double>(cfg_.height));
    double since = 0.0;
    for (const Detection& m : chase) {
      const bool was_valid = track.valid();
      const tracking::UnicycleUpdate u = track.update(m.t, m.z, noise[2] * noise[2] * m.unit_pixel_cov);
      if (!was_valid && track.valid()) since = m.t;
      if (!was_valid || !std::isfinite(u.report.nis) || m.t - since < opt_.settle) continue;
      const double log_u = -log_image - 0.5 * std::log(m.unit_pixel_cov.determinant());
      a.addCost(u.report.nis, std::log(u.report.S.determinant()), 2, eps, log_u);
      detail::addNis(a.nis, u.report.nis, 2.0, m.t, series);
    }
  }

  /// NIS: the track's innovation records once the track has been valid for settle s (a track is
  /// valid at the times it has an estimate record; a gap of more than a frame is a restart).
  void consistency(const runtime::MemorySink& mem, Consistency& nis, RunSeries* series) const {
    namespace channel = scenarios::mobile_capture::channel;
    std::map<double, double> valid_since;  // frame time -> start of the track valid then
    double since = -1.0, last_t = -1e300;
    for (const auto& e : mem.estimates) {
      if (e.channel != channel::kObject) continue;
      const double t = e.t;
      if (t - last_t > 1.5 * cfg_.vision_period) since = t;  // the track (re)started
      last_t = t;
      valid_since[t] = since;
    }
    for (const auto& i : mem.innovationsOf(channel::kObject)) {
      const auto v = valid_since.find(i.t);
      if (!std::isfinite(i.nis) || v == valid_since.end() || i.t - v->second < opt_.settle) continue;
      detail::addNis(nis, i.nis, 2.0, i.t, series);
    }
  }
};

}  // namespace

void registerMobileCaptureAdapter(AdapterRegistry& registry) {
  registry.add(detail::makeAdapter(
      {"mobile_capture",
       "mobile capture of [K] (rendered head camera, curvilinear EKF, capture planner, grasp; config/mobile_capture.yaml)",
       "mobile_capture", "--headless --summary mobile_capture_summary.json", "capture_time_s", true,
       {"captured", "capture_time_s", "oracle_captured", "capture_time_ratio_to_oracle", "grasp_attempts", "detection_rate",
        "longest_lost_s", "localization_rmse_mm", "estimate_rmse_mm", "nees_mean"}},
      mobileOptions(), [](const io::ConfigNode& config, const MobileOptions& o) {
        return std::make_unique<MobileInstance>(scenarios::loadMobileCaptureConfig(config), o);
      }));
}

}  // namespace viewline::tuning
