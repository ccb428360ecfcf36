#include "viewline/scenarios/pan_tilt/metrics.h"

#include <algorithm>
#include <tuple>
#include <utility>

#include "viewline/core/frames.h"
#include "viewline/core/statistics.h"

namespace viewline::scenarios {

using Eigen::Vector2d;

TTable1Row tTable1(sim::PathShape shape) {
  TTable1Row r;
  if (shape == sim::PathShape::Rectangle) {
    r.available = true;
    r.measured = Vector2d(3.8032, 3.3711);
    r.kalman = Vector2d(2.0601, 2.0674);
  } else if (shape == sim::PathShape::Circle) {
    r.available = true;
    r.measured = Vector2d(3.1147, 2.6701);
    r.kalman = Vector2d(1.5741, 1.1785);
  }
  return r;
}

nlohmann::json PanTiltRunMetrics::toJson() const {
  auto xy = [](const Vector2d& v) {
    return nlohmann::json{{"x", std::isfinite(v.x()) ? nlohmann::json(v.x()) : nlohmann::json()},
                          {"y", std::isfinite(v.y()) ? nlohmann::json(v.y()) : nlohmann::json()}};
  };
  auto num = [](double v) { return std::isfinite(v) ? nlohmann::json(v) : nlohmann::json(); };
  nlohmann::json j = {{"controller", controller},
          {"frames", frames},
          {"detections", detections},
          {"metric_frames", metric_frames},
          {"image_error_rms_px", num(image_error_rms_px)},
          {"image_error_max_px", num(image_error_max_px)},
          {"rmse_measured_cm", xy(rmse_measured_cm)},
          {"rmse_filtered_cm", xy(rmse_filtered_cm)},
          {"noise_sigma_cm", xy(noise_sigma_cm)},
          {"detection_pixel_rmse_px", num(detection_pixel_rmse_px)},
          {"limits",
           {{"commands", commands},
            {"unsafe_commands", unsafe_commands},
            {"rate_violations", rate_violations},
            {"limit_hits", limit_hits},
            {"max_rate_fraction", max_rate_fraction},
            {"min_limit_distance_deg", {{"pan", min_limit_distance_deg.x()}, {"tilt", min_limit_distance_deg.y()}}},
            {"pan_range_deg", {pan_range_deg.x(), pan_range_deg.y()}},
            {"tilt_range_deg", {tilt_range_deg.x(), tilt_range_deg.y()}}}},
          {"occlusion",
           {{"present", occlusion},
            {"reacquired", reacquired},
            {"reacquisition_delay_s", num(reacquisition_delay_s)},
            {"reacquisitions", reacquisitions},
            {"frames_searching", frames_searching}}},
          {"filter_jumps", filter_jumps},
          {"filter_region_dropped", filter_region_dropped},
          {"filter_corner_settings", {{"min_samples", filter_min_samples}, {"corner_sigma_m", filter_corner_sigma}}},
          {"wall_ms_per_frame", wall_ms_per_frame}};
  if (!scored) j["truth"] = "not scored (the frame source has no truth)";  // only then: reference summaries unchanged
  if (consistency.nis.count() > 0) j["consistency"] = consistency.toJson();
  if (!faults.empty()) j["faults"] = runtime::toJson(faults);  // only with injected faults (the same reason)
  if (live) j["live"] = runtime::toJson(*live);                  // only on a live source (the same reason)
  return j;
}

void FilterConsistency::addNis(double value) {
  if (std::isfinite(value)) nis.add(value, 2.0);
}

void FilterConsistency::addNees(const Eigen::Vector4d& estimate, const Eigen::Matrix4d& P, const Eigen::Vector4d& truth) {
  const estimation::StateEstimate s(Eigen::VectorXd(estimate), Eigen::MatrixXd(P), 0.0);
  const double v = estimation::nees(s, Eigen::VectorXd(truth));
  if (std::isfinite(v)) nees.add(v, 4.0);
}

core::Interval FilterConsistency::nisBand() const {
  if (nis.count() == 0) return {std::nan(""), std::nan("")};
  return core::averagedChiSquareInterval(2.0, static_cast<double>(nis.count()), 0.99);
}

core::Interval FilterConsistency::neesBand() const {
  const double n = std::floor(static_cast<double>(nees.count()) / fps);
  if (n < 1.0) return {std::nan(""), std::nan("")};
  return core::averagedChiSquareInterval(4.0, n, 0.99);
}

nlohmann::json FilterConsistency::toJson() const {
  auto num = [](double v) { return std::isfinite(v) ? nlohmann::json(v) : nlohmann::json(); };
  const core::Interval a = nisBand(), b = neesBand();
  return {{"nis_mean", num(nis.mean())},
          {"nis_samples", nis.count()},
          {"nis_band_99", {num(a.lo), num(a.hi)}},
          {"nis_inside", nis.count() > 0 && a.contains(nis.mean())},
          {"nees_mean", num(nees.mean())},
          {"nees_samples", nees.count()},
          {"nees_band_99", {num(b.lo), num(b.hi)}},
          {"nees_band_samples", std::floor(static_cast<double>(nees.count()) / fps)},
          {"nees_inside", nees.count() > 0 && std::isfinite(b.lo) && b.contains(nees.mean())}};
}

nlohmann::json PanTiltComparison::toJson(const PanTiltScenarioConfig& cfg) const {
  nlohmann::json j;
  auto xy = [](const Vector2d& v) {
    return nlohmann::json{{"x", std::isfinite(v.x()) ? nlohmann::json(v.x()) : nlohmann::json()},
                          {"y", std::isfinite(v.y()) ? nlohmann::json(v.y()) : nlohmann::json()}};
  };
  j["scenario"] = "pan_tilt";
  j["path"] = path;
  j["seed"] = seed;
  j["duration_s"] = cfg.duration;
  j["metrics_start_s"] = cfg.metrics_start;
  j["camera"] = {{"width", cfg.image_width}, {"height", cfg.image_height}, {"fx", cfg.fx}, {"fy", cfg.fy}, {"fps", cfg.fps}};
  j["path_speed_m_s"] = cfg.path.speed;
  j["filter_model"] = tracking::toString(cfg.control.filter.model);
  j["servo_gain"] = cfg.control.servo.gain;  // the baseline's (and ours unless predictive_gain is set)
  j["predictive_gain"] = cfg.control.gain > 0.0 ? cfg.control.gain : cfg.control.servo.gain;
  j["rig"] = cfg.rig_folder;
  j["noise_definition"] =
      "per axis, white Gaussian noise with std = measurement_noise_fraction x (max - min)/2 of the true path "
      "along that axis, added to the measured target position on the screen plane";
  j["noise_fraction"] = cfg.noise_fraction;
  j["noise_sigma_cm"] = xy(ours.noise_sigma_cm);
  j["rmse_measured_cm"] = xy(ours.rmse_measured_cm);
  j["rmse_filtered_cm"] = xy(ours.rmse_filtered_cm);
  const TTable1Row t = tTable1(cfg.path.shape);
  if (t.available) {
    j["t_table1"] = {{"rmse_measured_cm", xy(t.measured)}, {"rmse_kalman_cm", xy(t.kalman)}};
    j["target_rmse_filtered_cm_max"] = xy(0.5 * t.kalman);
    j["meets_filtered_target"] =
        ours.rmse_filtered_cm.x() <= 0.5 * t.kalman.x() && ours.rmse_filtered_cm.y() <= 0.5 * t.kalman.y();
  }
  j["image_error_rms_px"] = ours.image_error_rms_px;
  if (!ours.scored) j["truth"] = "not scored (the frame source has no truth)";
  if (has_baseline) {
    j["baseline_image_error_rms_px"] = baseline.image_error_rms_px;
    j["image_error_ratio_to_baseline"] = ours.image_error_rms_px / baseline.image_error_rms_px;
  }
  j["reacquired_after_occlusion"] = ours.reacquired;
  j["reacquisition_delay_s"] = std::isfinite(ours.reacquisition_delay_s) ? nlohmann::json(ours.reacquisition_delay_s) : nlohmann::json();
  j["commands_outside_limits"] = ours.unsafe_commands + ours.rate_violations + ours.limit_hits +
                                 (has_baseline ? baseline.unsafe_commands + baseline.rate_violations + baseline.limit_hits : 0);
  j["ours"] = ours.toJson();
  if (has_baseline) j["baseline"] = baseline.toJson();
  return j;
}

namespace pan_tilt {

std::pair<int, double> cornerSettings(const tracking::PlanarTargetFilter& f) {
  if (f.config().model == tracking::TargetModel::WaypointParticles || !(f.config().jump_window > 0.0)) return {0, 0.0};
  return {f.minSamples(), f.cornerSigma()};
}

const char* metText(bool met) { return met ? "met" : "not met"; }

Scorer::Scorer(const PanTiltScenarioConfig& config, double occlusion_start, double occlusion_end, const Vector2d& sigma,
               std::string controller)
    : cfg_(config), occ0_(occlusion_start), occ1_(occlusion_end) {
  m_.controller = std::move(controller);
  m_.noise_sigma_cm = 100.0 * sigma;
  m_.occlusion = cfg_.occlusion_start >= 0.0 && cfg_.occlusion_start < cfg_.duration;
}

void Scorer::detectorError(double tc, const Vector2d& detected_px, const Vector2d& truth_px) {
  if (tc >= cfg_.metrics_start) det_px_.add((detected_px - truth_px).squaredNorm());
}

void Scorer::frame(double tc, double err_px, bool detected, const Vector2d& measured, const Vector2d& truth, bool used,
                   const Vector2d& filt) {
  if (detected) ++m_.detections;
  if (used && m_.occlusion && !m_.reacquired && tc >= occ1_) {
    m_.reacquired = true;
    m_.reacquisition_delay_s = tc - occ1_;
  }
  const bool in_metrics = tc >= cfg_.metrics_start && !(tc >= occ0_ && tc < occ1_ + 2.0);
  if (!in_metrics) return;
  ++m_.metric_frames;
  img_.add(err_px * err_px);
  m_.image_error_max_px = std::max(m_.image_error_max_px, err_px);
  if (detected) {
    mx_.add(std::pow(measured.x() - truth.x(), 2));
    my_.add(std::pow(measured.y() - truth.y(), 2));
    if (std::isfinite(filt.x())) {
      fx_.add(std::pow(filt.x() - truth.x(), 2));
      fy_.add(std::pow(filt.y() - truth.y(), 2));
    }
  }
}

void Scorer::command(const robots::PanTiltLimits& limits, const Vector2d& q, const Vector2d& qdot, bool safe,
                     bool searching) {
  ++m_.commands;
  if (!safe) ++m_.unsafe_commands;
  m_.max_rate_fraction = std::max(m_.max_rate_fraction, qdot.cwiseAbs().cwiseQuotient(limits.qdot_max).maxCoeff());
  if (searching) ++m_.frames_searching;
  pan_rng_ = Vector2d(std::min(pan_rng_(0), q(0)), std::max(pan_rng_(1), q(0)));
  tilt_rng_ = Vector2d(std::min(tilt_rng_(0), q(1)), std::max(tilt_rng_(1), q(1)));
  for (int i = 0; i < 2; ++i) {
    m_.min_limit_distance_deg(i) =
        std::min(m_.min_limit_distance_deg(i), core::rad2deg(std::min(q(i) - limits.q_min(i), limits.q_max(i) - q(i))));
  }
}

void Scorer::consistency(double tc, double nis, bool fused, const Eigen::Vector4d& estimate, const Eigen::Matrix4d& P,
                         const Eigen::Vector4d& truth) {
  if (!(tc >= cfg_.metrics_start && !(tc >= occ0_ && tc < occ1_ + 2.0))) return;
  m_.consistency.fps = cfg_.fps;
  m_.consistency.addNis(nis);
  if (fused) m_.consistency.addNees(estimate, P, truth);
}

void Scorer::decision(tracking::GateDecision d) {
  switch (d) {
    case tracking::GateDecision::Start: ++m_.gate.starts; break;
    case tracking::GateDecision::Accept: ++m_.gate.accepted; break;
    case tracking::GateDecision::Reject: ++m_.gate.rejected; break;
    case tracking::GateDecision::Restart: ++m_.gate.restarts; break;
  }
}

PanTiltRunMetrics Scorer::finish(const control::PredictivePanTiltController* ours, const robots::SimulatedPanTiltUnit& unit,
                                 double wall_ms) {
  PanTiltRunMetrics m = m_;
  m.image_error_rms_px = img_.rms();
  m.rmse_measured_cm = 100.0 * Vector2d(mx_.rms(), my_.rms());
  if (ours != nullptr) {
    m.rmse_filtered_cm = 100.0 * Vector2d(fx_.rms(), fy_.rms());
    m.reacquisitions = ours->reacquisitions();
    m.filter_jumps = ours->filter().jumps();
    m.filter_region_dropped = ours->filter().regionDropped();
    std::tie(m.filter_min_samples, m.filter_corner_sigma) = cornerSettings(ours->filter());
  }
  m.detection_pixel_rmse_px = det_px_.rms();
  m.rate_violations = unit.rateViolations();
  m.limit_hits = unit.limitHits();
  m.pan_range_deg = Vector2d(core::rad2deg(pan_rng_(0)), core::rad2deg(pan_rng_(1)));
  m.tilt_range_deg = Vector2d(core::rad2deg(tilt_rng_(0)), core::rad2deg(tilt_rng_(1)));
  m.wall_ms_per_frame = m.frames ? wall_ms / static_cast<double>(m.frames) : 0.0;
  return m;
}

}  // namespace pan_tilt
}  // namespace viewline::scenarios
