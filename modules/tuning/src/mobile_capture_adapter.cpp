// Mobile-capture scenario adapter ([K], issue 8): runs scenarios::runMobileCapture (rendered head
// camera, red-blob detection, ground back-projection, the curvilinear EKF, LS predictor, capture
// planner, base and head control, grasp; and the oracle on the same object path) in-process, with
// the config read by the scenario's own loader (loadMobileCaptureConfig: strict keys), so a config
// the tuning tool accepts or writes is one mobile_capture reads. One run = one chase (seed).
//
// Consistency. The scenario's EKF (x, y, θ, v, ω) is private to the scenario; what it exposes is
// its --log output: per vision step the truth (object pose, v, ω) and the estimate with its
// standard deviations (the covariance diagonal). A run therefore logs to a private temporary
// folder. NEES: the full covariance is not exposed, but each marginal is exact — for a consistent
// filter e_i² / P_ii ~ χ²(1) — so every `nees_spacing_s` seconds (nearly independent samples) the
// adapter takes one 1-dof sample, cycling through the components x, y, θ (wrapped), v, ω, once the
// track has been valid for `settle_s`. NIS: the gate's d' S⁻¹ d of every measurement tested
// against the track (MobileCaptureFrame::nis, 2 dof, fused or gated out), once the track has been
// valid for `settle_s`.
//
// Noise auto-tuning is not offered: the head points the camera at the filter's own prediction, so
// which frames see the object depends on the filter being tuned (the measurements cannot be
// replayed honestly). Sweeps of filter.q_v, filter.q_w, filter.gate_probability, the planner and
// control keys work, with NEES and NIS beside the metrics.

#include <cmath>
#include <map>

#include "adapter_util.h"
#include "viewline/core/error.h"
#include "viewline/scenarios/mobile_capture.h"
#include "viewline/scenarios/mobile_capture_display.h"
#include "viewline/tuning/scenario.h"

namespace viewline::tuning {

namespace {

constexpr double kPi = 3.14159265358979323846;

struct MobileOptions {
  double max_time = 0.0;      ///< 0: the config's world.max_time
  double nees_spacing = 1.0;  ///< s
  double settle = 2.0;        ///< s of valid track before NEES samples
};

class MobileInstance final : public ScenarioInstance {
public:
  MobileInstance(scenarios::MobileCaptureConfig cfg, MobileOptions opt) : cfg_(std::move(cfg)), opt_(opt) {
    if (opt_.max_time > 0.0) cfg_.max_time = opt_.max_time;
    cfg_.validate();
  }

  std::string autotuneUnsupported() const override {
    return "the head aims the camera at the mobile-capture EKF's own prediction, so the measurements depend on the "
           "filter being tuned and cannot be replayed honestly; sweep filter.q_v / filter.q_w instead (NEES and NIS "
           "are reported per setting)";
  }

  RunResult run(std::uint64_t seed, const RunOptions& ro) const override {
    const detail::TempLogDir tmp;
    std::unique_ptr<scenarios::MobileCaptureDisplay> view;
    if (ro.display && detail::xDisplayAvailable()) {
      try {
        view = std::make_unique<scenarios::MobileCaptureDisplay>(cfg_);
      } catch (const std::exception&) {
        view.reset();
      }
    }
    std::shared_ptr<RunSeries> series;
    if (ro.series) series = makeSeries();
    Curve err{"position error", {}, {}}, obj{"object", {}, {}}, robot{"robot", {}, {}}, est{"estimate", {}, {}};
    double sq = 0.0;
    std::size_t n = 0;
    double next_prediction = 5.0, valid_since = -1.0;
    Consistency nis;
    scenarios::MobileCaptureRun res;
    {
      io::LogDirectory log(tmp.dir());
      scenarios::MobileCaptureHooks hooks;
      hooks.log = &log;
      hooks.on_frame = [&](const scenarios::MobileCaptureFrame& f) {
        if (view) view->show(f);
        if (!f.estimate_valid) valid_since = -1.0;
        else if (valid_since < 0.0) valid_since = f.t;
        if (std::isfinite(f.nis) && valid_since >= 0.0 && f.t - valid_since >= opt_.settle) {
          nis.add(f.nis, 2.0);
          if (series) {
            series->nis_t.push_back(f.t);
            series->nis.push_back(f.nis);
          }
        }
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
      res = scenarios::runMobileCapture(cfg_, seed, &hooks);
      log.flush();
    }
    RunResult r;
    r.seed = seed;
    neesFromLog(tmp, r.nees);
    r.nis = nis;
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
  std::shared_ptr<RunSeries> makeSeries() const {
    auto s = std::make_shared<RunSeries>();
    s->error_label = "object position error |p_hat - p| [m]";
    s->nis_dof = 2.0;
    s->traj_x_label = "floor x [m]";
    s->traj_y_label = "floor y [m] (black: object and robot paths)";
    return s;
  }

  /// One 1-dof marginal NEES sample every nees_spacing s, cycling over (x, y, θ, v, ω).
  void neesFromLog(const detail::TempLogDir& tmp, Consistency& nees) const {
    const detail::CsvTable truth = detail::CsvTable::read(tmp.file("truth.csv"), "truth.csv of a mobile_capture log");
    const detail::CsvTable est = detail::CsvTable::read(tmp.file("estimates.csv"), "estimates.csv of a mobile_capture log");
    std::map<std::string, std::size_t> truth_row;  // by the exact text of t (both written at the same step)
    const std::size_t tt = truth.col("t");
    for (std::size_t i = 0; i < truth.rows(); ++i) truth_row[truth.text(i, tt)] = i;
    const char* true_cols[5] = {"object_x", "object_y", "object_theta", "object_v", "object_omega"};
    const char* est_cols[5] = {"x", "y", "theta", "v", "omega"};
    const char* sd_cols[5] = {"sx", "sy", "stheta", "sv", "somega"};
    std::size_t tc[5], ec[5], sc[5];
    for (int k = 0; k < 5; ++k) {
      tc[k] = truth.col(true_cols[k]);
      ec[k] = est.col(est_cols[k]);
      sc[k] = est.col(sd_cols[k]);
    }
    const std::size_t et = est.col("t");
    double valid_since = -1.0, last_t = -1e300, next = -1e300;
    std::size_t component = 0;
    for (std::size_t i = 0; i < est.rows(); ++i) {
      const double t = est.number(i, et);
      if (t - last_t > 1.5 * cfg_.vision_period) valid_since = t;  // the track (re)started
      last_t = t;
      const auto it = truth_row.find(est.text(i, et));
      if (it == truth_row.end() || t - valid_since < opt_.settle || t < next) continue;
      const std::size_t k = component % 5;
      double e = est.number(i, ec[k]) - truth.number(it->second, tc[k]);
      if (k == 2) e = std::remainder(e, 2.0 * kPi);
      const double sd = est.number(i, sc[k]);
      if (!(sd > 0.0)) continue;
      nees.add(e * e / (sd * sd), 1.0);
      ++component;
      next = t + opt_.nees_spacing;
    }
  }

  scenarios::MobileCaptureConfig cfg_;
  MobileOptions opt_;
};

}  // namespace

void registerMobileCaptureAdapter(AdapterRegistry& registry) {
  detail::AdapterInfo info;
  info.name = "mobile_capture";
  info.description = "mobile capture of [K] (rendered head camera, curvilinear EKF, capture planner, grasp; "
                     "config/mobile_capture.yaml)";
  info.app = "mobile_capture";
  info.app_arguments = "--headless --summary mobile_capture_summary.json";
  info.default_metric = "capture_time_s";
  info.metrics = {"captured", "capture_time_s", "oracle_captured", "capture_time_ratio_to_oracle", "grasp_attempts",
                  "detection_rate", "longest_lost_s", "localization_rmse_mm", "estimate_rmse_mm", "nees_mean"};
  info.options = {{"max_time", "0", {}, "s, time limit of a chase (0: the config's world.max_time)"},
                  {"nees_spacing_s", "1", {}, "s between the 1-dof NEES samples (nearly independent)"},
                  {"settle_s", "2", {}, "s a track must have been valid before its NEES samples count"}};
  registry.add(detail::makeAdapter(std::move(info), [](const std::string& yaml, const std::string& name,
                                                       const AdapterOptions& options) {
    scenarios::MobileCaptureConfig cfg = scenarios::loadMobileCaptureConfig(detail::scenarioConfig(yaml, name));
    MobileOptions o;
    o.max_time = optionNumber(options, "max_time");
    o.nees_spacing = optionNumber(options, "nees_spacing_s");
    o.settle = optionNumber(options, "settle_s");
    if (!(o.max_time >= 0.0) || !(o.nees_spacing > 0.0) || !(o.settle >= 0.0))
      throw core::InvalidInput("mobile_capture adapter options: max_time >= 0, nees_spacing_s > 0, settle_s >= 0");
    return std::unique_ptr<ScenarioInstance>(std::make_unique<MobileInstance>(std::move(cfg), o));
  }));
}

}  // namespace viewline::tuning
