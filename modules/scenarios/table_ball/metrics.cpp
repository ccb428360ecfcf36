#include "viewline/scenarios/table_ball/metrics.h"

#include <Eigen/Dense>
#include <algorithm>
#include <array>
#include <cmath>
#include <limits>

#include "viewline/core/frames.h"
#include "viewline/core/statistics.h"
#include "viewline/scenarios/table_ball/world.h"

namespace viewline::scenarios {

namespace {

constexpr double kInf = std::numeric_limits<double>::infinity();
constexpr double kNaN = std::numeric_limits<double>::quiet_NaN();
constexpr double kTick = TableBallWorld::kTick;

Eigen::Vector2d positionOf(const Eigen::VectorXd& x) { return {x[0], x[2]}; }

}  // namespace

double TableBallMetrics::Accumulator::rmsMm() const { return 1000.0 * core::rmsFromSum(sum_sq, n); }

TableBallMetrics::TableBallMetrics(const TableBallConfig& config)
    : cfg_(config), period_(config.framePeriod()), side_(config.compare_tunings ? 3 : 0) {
  tick_t_.reserve(static_cast<std::size_t>(cfg_.duration / kTick) + 16);
  tick_p_.reserve(tick_t_.capacity());
}

void TableBallMetrics::command(const Eigen::Vector2d& cmd) {
  TableBallResult& r = counts_;
  if (!cfg_.wrist.withinAngle(cmd, 1e-12)) r.limits_respected = false;
  if (have_cmd_) {
    const double rate = (cmd - last_cmd_).cwiseAbs().maxCoeff() / kTick;
    r.max_commanded_rate_deg_s = std::max(r.max_commanded_rate_deg_s, core::rad2deg(rate));
    if (rate > cfg_.wrist.max_rate * (1.0 + 1e-9) + 1e-12) r.limits_respected = false;
  }
  r.max_commanded_angle_deg = std::max(r.max_commanded_angle_deg, core::rad2deg(cmd.cwiseAbs().maxCoeff()));
  last_cmd_ = cmd;
  have_cmd_ = true;
}

void TableBallMetrics::tick(double t, const Eigen::Vector2d& p) {
  tick_t_.push_back(t);
  tick_p_.push_back(p);
}

void TableBallMetrics::frame(double t, const sim::TiltTableState& truth, const ObserverFrame& of,
                             const tracking::RollingBallTracker& tracker, const SideFilters& side) {
  TableBallResult& r = counts_;
  ++r.frames;
  if (!of.image) ++r.frames_dropped;
  if (of.tracked) ++r.tracked_frames;
  if (of.table_found) ++r.table_detections;
  if (of.ball_found) ++r.ball_detections;
  // Errors against the truth at the capture instant.
  if (t >= cfg_.warmup) {
    if (of.estimate_valid) obs_.add(positionOf(of.x) - truth.p);
    // The raw measurement: the ball on the frame's own table pose (not the filtered pose the
    // observer fuses, step 2b of observer.h).
    if (of.ball_found && of.measured_own_pose.allFinite()) meas_.add(of.measured_own_pose - truth.p);
    if (of.ball_found) fused_meas_.add(of.measured - truth.p);
    if (of.table_found) tilt_.add(of.measured_tilt - truth.tilt);
    for (std::size_t i = 0; i < side.size() && i < side_.size(); ++i) {
      if (side[i].second.initialized()) side_[i].add(side[i].second.position() - truth.p);
    }
    if (of.ball_found && tracker.initialized()) {
      nis_sum_ += tracker.lastNis();
      ++nis_n_;
      if (t >= next_nis_ - 1e-9) {
        counts_.nis_sampled.add(tracker.lastNis(), 2.0);
        next_nis_ = std::max(next_nis_, cfg_.warmup) + cfg_.nis_spacing;
      }
    }
    // NEES sample: a push hits the ball between frames and no image has shown it yet in the frame
    // it lands in (nor is it in the model), so a sample due then waits two frames.
    bool after_push = false;
    for (const auto& p : cfg_.pushes) after_push = after_push || (p.t <= t + 1e-9 && t < p.t + 2.0 * period_ - 1e-9);
    if (of.estimate_valid && t >= next_nees_ - 1e-9 && !after_push) {
      const Eigen::MatrixXd P = tracker.P();
      const std::array<Eigen::Index, 4> idx{0, 1, 2, 3};  // p_x, v_x, p_y, v_y
      Eigen::Vector4d e(of.x[0] - truth.p.x(), of.x[1] - truth.v.x(), of.x[2] - truth.p.y(), of.x[3] - truth.v.y());
      Eigen::Matrix4d Pe;
      for (int i = 0; i < 4; ++i)
        for (int j = 0; j < 4; ++j) Pe(i, j) = P(idx[static_cast<std::size_t>(i)], idx[static_cast<std::size_t>(j)]);
      const Eigen::LDLT<Eigen::Matrix4d> ldlt(Pe);
      if (ldlt.info() == Eigen::Success) counts_.nees.add(e.dot(ldlt.solve(e)), 4.0);
      next_nees_ = std::max(next_nees_, cfg_.warmup) + cfg_.nees_spacing;
    }
  }
  // The N-frame prediction made N periods ago, scored when its frame comes (a dropped or late
  // frame more than a quarter period off is not comparable).
  while (!pending_pred_.empty() && pending_pred_.front().first <= t + 1e-6) {
    if (std::abs(pending_pred_.front().first - t) < 0.25 * period_ && t >= cfg_.warmup) {
      pred_.add(pending_pred_.front().second - truth.p);
    }
    pending_pred_.erase(pending_pred_.begin());
  }
  if (of.estimate_valid && !of.predictions.empty()) {
    pending_pred_.emplace_back(t + static_cast<double>(of.predictions.size()) * period_, of.predictions.back());
  }
}

void TableBallMetrics::timing(double observer_s, double reference_s, double observer_cpu_s, double reference_cpu_s) {
  ref_time_ += reference_s;
  ref_cpu_ += reference_cpu_s;
  obs_time_ += observer_s;
  obs_cpu_ += observer_cpu_s;
  ++timed_;
}

TableBallResult TableBallMetrics::result(std::uint64_t seed) const {
  TableBallResult res = counts_;
  res.seed = seed;
  res.duration = cfg_.duration;
  res.observer_rmse_mm = obs_.rmsMm();
  res.measurement_rmse_mm = meas_.rmsMm();
  res.fused_measurement_rmse_mm = fused_meas_.rmsMm();
  res.prediction_rmse_mm_10 = pred_.rmsMm();
  res.tilt_rmse_deg = core::rad2deg(core::rmsFromSum(tilt_.sum_sq, tilt_.n));
  res.nis_mean = nis_n_ > 0 ? nis_sum_ / nis_n_ : kNaN;
  if (side_.size() == 3) {
    res.observer_rmse_mm_M_sw1_sv0005 = side_[0].rmsMm();
    res.observer_rmse_mm_M_sw1_sv1 = side_[1].rmsMm();
    res.observer_rmse_mm_stationary = side_[2].rmsMm();
  } else {
    res.observer_rmse_mm_M_sw1_sv0005 = res.observer_rmse_mm_M_sw1_sv1 = res.observer_rmse_mm_stationary = kNaN;
  }
  if (timed_ > 0) {
    res.observer_frame_ms = 1000.0 * obs_time_ / timed_;
    res.reference_frame_ms = 1000.0 * ref_time_ / timed_;
    res.frame_time_ratio_to_reference = obs_time_ / ref_time_;
    res.observer_frame_cpu_ms = 1000.0 * obs_cpu_ / timed_;
    res.reference_frame_cpu_ms = 1000.0 * ref_cpu_ / timed_;
    res.frame_cpu_ratio_to_reference = obs_cpu_ / ref_cpu_;
  } else {
    res.observer_frame_ms = res.reference_frame_ms = res.frame_time_ratio_to_reference = kNaN;
    res.observer_frame_cpu_ms = res.reference_frame_cpu_ms = res.frame_cpu_ratio_to_reference = kNaN;
  }
  scoreEvents(res);
  return res;
}

void TableBallMetrics::scoreEvents(TableBallResult& res) const {
  // Event windows: each event is scored up to the next event (set-point change or push).
  std::vector<double> event_times;
  for (const auto& s : cfg_.setpoints) event_times.push_back(s.t);
  for (const auto& p : cfg_.pushes) event_times.push_back(p.t);
  std::sort(event_times.begin(), event_times.end());
  auto windowEnd = [&](double t0) {
    for (double e : event_times) {
      if (e > t0 + 1e-9) return std::min(e, cfg_.duration);
    }
    return cfg_.duration;
  };
  auto idx = [&](double t) {
    return static_cast<std::size_t>(std::lower_bound(tick_t_.begin(), tick_t_.end(), t - 1e-9) - tick_t_.begin());
  };
  for (std::size_t i = 1; i < cfg_.setpoints.size(); ++i) {
    const auto& sp = cfg_.setpoints[i];
    const Eigen::Vector2d delta = sp.xy - cfg_.setpoints[i - 1].xy;
    if (delta.norm() < cfg_.min_step || sp.t >= cfg_.duration) continue;
    const double t_end = windowEnd(sp.t);
    const Eigen::Vector2d u = delta.normalized();
    const double band = cfg_.settle_fraction * delta.norm();
    const double band_2d = std::max(band, cfg_.settle_min_band);  // a few mm of noise never settle a small step
    StepMetrics m;
    m.t = sp.t;
    m.size_m = delta.norm();
    double last_out = sp.t, last_out_2d = sp.t, over = 0.0, ss_sum = 0.0;
    int ss_n = 0;
    for (std::size_t k = idx(sp.t); k < tick_t_.size() && tick_t_[k] < t_end - 1e-9; ++k) {
      const Eigen::Vector2d e = tick_p_[k] - sp.xy;
      over = std::max(over, e.dot(u));
      if (std::abs(e.dot(u)) > band) last_out = tick_t_[k];
      if (e.norm() > band_2d) last_out_2d = tick_t_[k];
      if (tick_t_[k] >= t_end - cfg_.steady_window) {
        ss_sum += e.norm();
        ++ss_n;
      }
    }
    // Settling (classic step-response definition): the last time outside the band; a step still
    // outside it at the window's end never settled.
    m.overshoot_pct = 100.0 * over / delta.norm();
    m.settling_time_s = last_out >= t_end - 2.0 * kTick ? kInf : last_out - sp.t;
    m.settling_time_2d_s = last_out_2d >= t_end - 2.0 * kTick ? kInf : last_out_2d - sp.t;
    m.steady_state_error_mm = ss_n > 0 ? 1000.0 * ss_sum / ss_n : kNaN;
    res.steps.push_back(m);
  }
  for (const auto& p : cfg_.pushes) {
    if (p.t >= cfg_.duration) continue;
    const double t_end = windowEnd(p.t);
    PushMetrics m;
    m.t = p.t;
    m.speed = p.dv.norm();
    double last_out = p.t;
    for (std::size_t k = idx(p.t); k < tick_t_.size() && tick_t_[k] < t_end - 1e-9; ++k) {
      const double e = (tick_p_[k] - cfg_.setpointAt(tick_t_[k])).norm();
      m.peak_excursion_mm = std::max(m.peak_excursion_mm, 1000.0 * e);
      if (e > cfg_.push_band) last_out = tick_t_[k];
    }
    m.recovery_s = last_out >= t_end - 2.0 * kTick ? kInf : last_out - p.t;
    res.pushes.push_back(m);
  }
  const double on_border = 0.5 * cfg_.table_side - cfg_.ball_radius - 1e-9;  // the physics clamps the centre there
  for (const runtime::FaultSpec& f : cfg_.faults.faults) {
    if (f.kind != runtime::FaultKind::RobotSilent && f.kind != runtime::FaultKind::RobotLimitError) continue;
    if (f.from_s >= cfg_.duration) continue;
    const double t_end = windowEnd(f.from_s);
    RobotFaultMetrics m;
    m.kind = runtime::toString(f.kind);
    m.from_s = f.from_s;
    m.to_s = f.to_s;
    double last_out = f.to_s;
    bool out_at_end = false;
    for (std::size_t k = idx(f.from_s); k < tick_t_.size() && tick_t_[k] < t_end - 1e-9; ++k) {
      const double e = (tick_p_[k] - cfg_.setpointAt(tick_t_[k])).norm();
      m.peak_excursion_mm = std::max(m.peak_excursion_mm, 1000.0 * e);
      m.border_contact = m.border_contact || tick_p_[k].cwiseAbs().maxCoeff() >= on_border;
      if (tick_t_[k] >= f.to_s && e > cfg_.push_band) {
        last_out = tick_t_[k];
        out_at_end = last_out >= t_end - 2.0 * kTick;
      }
    }
    m.resettle_s = out_at_end || f.to_s >= t_end ? kInf : last_out - f.to_s;
    res.robot_faults.push_back(m);
  }
  auto worst = [](const auto& v, auto field) {
    double w = v.empty() ? kNaN : -kInf;
    for (const auto& e : v) w = std::max(w, std::isnan(e.*field) ? kInf : e.*field);
    return w;
  };
  res.overshoot_pct = worst(res.steps, &StepMetrics::overshoot_pct);
  res.settling_time_s = worst(res.steps, &StepMetrics::settling_time_s);
  res.settling_time_2d_s = worst(res.steps, &StepMetrics::settling_time_2d_s);
  res.steady_state_error_mm = worst(res.steps, &StepMetrics::steady_state_error_mm);
  res.push_recovery_s = worst(res.pushes, &PushMetrics::recovery_s);
}

// ---------------------------------------------------------------------------------------------

nlohmann::json toJson(const TableBallResult& r) {
  auto num = [](double v) { return std::isfinite(v) ? nlohmann::json(v) : nlohmann::json(nullptr); };
  nlohmann::json j;
  j["scenario"] = "table_ball_balancing";
  j["seed"] = r.seed;
  j["duration_s"] = r.duration;
  j["frames"] = r.frames;
  j["frames_dropped"] = r.frames_dropped;
  j["table_detections"] = r.table_detections;
  j["ball_detections"] = r.ball_detections;
  j["tracked_frames"] = r.tracked_frames;
  j["observer_rmse_mm"] = num(r.observer_rmse_mm);
  j["measurement_rmse_mm"] = num(r.measurement_rmse_mm);
  j["fused_measurement_rmse_mm"] = num(r.fused_measurement_rmse_mm);
  j["tunings"] = {{"M_sigma_w_1_sigma_v_0.005_rmse_mm", num(r.observer_rmse_mm_M_sw1_sv0005)},
                  {"M_sigma_w_1_sigma_v_1_rmse_mm", num(r.observer_rmse_mm_M_sw1_sv1)},
                  {"stationary_gain_rmse_mm", num(r.observer_rmse_mm_stationary)}};
  j["prediction_rmse_mm_10_steps"] = num(r.prediction_rmse_mm_10);
  j["tilt_rmse_deg"] = num(r.tilt_rmse_deg);
  j["nis_mean"] = num(r.nis_mean);
  auto consistency = [&](const estimation::ConsistencyStats& c) {
    nlohmann::json o = {{"samples", c.count()}};
    if (c.count() == 0) return o;
    const core::Interval b = c.bounds(0.99);
    o["mean"] = c.mean();
    o["dof"] = c.meanDof();
    o["band_99"] = {b.lo, b.hi};
    o["inside"] = b.contains(c.mean());
    return o;
  };
  j["nis_sampled"] = consistency(r.nis_sampled);
  j["nees_position_velocity"] = consistency(r.nees);
  j["overshoot_pct"] = num(r.overshoot_pct);
  j["settling_time_s"] = num(r.settling_time_s);
  j["settling_time_2d_s"] = num(r.settling_time_2d_s);
  j["steady_state_error_mm"] = num(r.steady_state_error_mm);
  j["push_recovery_s"] = num(r.push_recovery_s);
  j["frame_time_ratio_to_reference"] = num(r.frame_time_ratio_to_reference);
  j["observer_frame_ms"] = num(r.observer_frame_ms);
  j["reference_frame_ms"] = num(r.reference_frame_ms);
  j["frame_cpu_ratio_to_reference"] = num(r.frame_cpu_ratio_to_reference);
  j["observer_frame_cpu_ms"] = num(r.observer_frame_cpu_ms);
  j["reference_frame_cpu_ms"] = num(r.reference_frame_cpu_ms);
  j["max_commanded_angle_deg"] = r.max_commanded_angle_deg;
  j["max_commanded_rate_deg_s"] = r.max_commanded_rate_deg_s;
  j["limits_respected"] = r.limits_respected;
  if (r.stopped_early) j["stopped_early"] = true;
  nlohmann::json steps = nlohmann::json::array();
  for (const auto& s : r.steps) {
    steps.push_back({{"t", s.t}, {"size_m", s.size_m}, {"overshoot_pct", num(s.overshoot_pct)},
                     {"settling_time_s", num(s.settling_time_s)}, {"settling_time_2d_s", num(s.settling_time_2d_s)}, {"steady_state_error_mm", num(s.steady_state_error_mm)}});
  }
  j["steps"] = steps;
  nlohmann::json pushes = nlohmann::json::array();
  for (const auto& p : r.pushes) {
    pushes.push_back({{"t", p.t}, {"speed_m_s", p.speed}, {"recovery_s", num(p.recovery_s)},
                      {"peak_excursion_mm", num(p.peak_excursion_mm)}});
  }
  j["pushes"] = pushes;
  if (!r.robot_faults.empty()) {  // only with robot faults in the config
    nlohmann::json rf = nlohmann::json::array();
    for (const auto& m : r.robot_faults) {
      rf.push_back({{"kind", m.kind}, {"from_s", m.from_s}, {"to_s", m.to_s}, {"peak_excursion_mm", m.peak_excursion_mm},
                    {"resettle_s", num(m.resettle_s)}, {"border_contact", m.border_contact}});
    }
    j["robot_faults"] = rf;
  }
  j["wall_seconds"] = r.wall_seconds;
  if (!r.faults.empty()) j["faults"] = runtime::toJson(r.faults);  // only with injected faults
  return j;
}

// ---------------------------------------------------------------------------------------------

namespace {

/// printf of a finite figure; otherwise why it has no value.
std::string figure(double v, int decimals, const std::string& why_missing) {
  if (std::isinf(v)) return "never (within its window)";
  if (std::isnan(v)) return why_missing;
  char buf[64];
  std::snprintf(buf, sizeof buf, "%.*f", decimals, v);
  return buf;
}

}  // namespace

void printTableBallSummary(std::FILE* out, const TableBallResult& r, const TableBallConfig& cfg) {
  const std::string unscored = r.duration <= cfg.warmup
                                   ? "not scored (run shorter than the warm-up, metrics.warmup = " +
                                         figure(cfg.warmup, 2, "?") + " s)"
                                   : std::string("not scored (nothing measured after the warm-up)");
  const std::string no_side = cfg.compare_tunings ? unscored : "not run (metrics.compare_tunings: false)";
  const std::string no_steps = "not scored (no set-point step of at least metrics.min_step in the run)";
  const std::string no_timing = cfg.time_reference ? "not timed (no frame)" : "not timed (metrics.time_reference: false)";
  auto f = [](double v, int decimals, const std::string& why) { return figure(v, decimals, why); };

  std::fprintf(out, "table_ball_balancing: %.1f s, seed %llu, %d frames (%d dropped), table found %d, ball found %d%s\n",
               r.duration, static_cast<unsigned long long>(r.seed), r.frames, r.frames_dropped, r.table_detections,
               r.ball_detections, r.stopped_early ? " (stopped early)" : "");
  if (cfg.rig) {
    std::fprintf(out, "  camera: rig %s (renders with truth.yaml; the observer uses rig.yaml + ground.yaml)\n",
                 cfg.rig->folder.c_str());
  } else {
    std::fprintf(out, "  camera: inline config keys (one perfect camera)\n");
  }
  // A line whose figures were all not scored says why once.
  if (std::isnan(r.observer_rmse_mm) && std::isnan(r.measurement_rmse_mm)) {
    std::fprintf(out, "  observer and measurement RMSE: %s\n", unscored.c_str());
  } else {
    std::fprintf(out, "  observer RMSE %s mm (measurements %s mm); [M] tunings: sw=1,sv=0.005 %s mm, sw=sv=1 %s mm; "
                 "stationary gain %s mm\n",
                 f(r.observer_rmse_mm, 2, unscored).c_str(), f(r.measurement_rmse_mm, 2, unscored).c_str(),
                 f(r.observer_rmse_mm_M_sw1_sv0005, 2, no_side).c_str(),
                 f(r.observer_rmse_mm_M_sw1_sv1, 2, no_side).c_str(),
                 f(r.observer_rmse_mm_stationary, 2, no_side).c_str());
  }
  if (std::isnan(r.prediction_rmse_mm_10) && std::isnan(r.tilt_rmse_deg) && std::isnan(r.nis_mean)) {
    std::fprintf(out, "  prediction and tilt RMSE, NIS mean: %s\n", unscored.c_str());
  } else {
    std::fprintf(out, "  10-step prediction RMSE %s mm, tilt RMSE %s deg, NIS mean %s\n",
                 f(r.prediction_rmse_mm_10, 2, unscored).c_str(), f(r.tilt_rmse_deg, 3, unscored).c_str(),
                 f(r.nis_mean, 2, unscored).c_str());
  }
  auto band = [](const char* name, const estimation::ConsistencyStats& c) {
    if (c.count() == 0) return std::string(name) + " not sampled";
    const core::Interval b = c.bounds(0.99);
    char buf[160];
    std::snprintf(buf, sizeof buf, "%s %.2f (%zu samples, 99 %% band [%.2f, %.2f]: %s)", name, c.mean(), c.count(), b.lo, b.hi,
                  b.contains(c.mean()) ? "inside" : "OUTSIDE");
    return std::string(buf);
  };
  std::fprintf(out, "  consistency: %s; %s\n", band("NIS", r.nis_sampled).c_str(), band("NEES (p, v)", r.nees).c_str());
  const std::string push = f(r.push_recovery_s, 2, "not scored (no push in the run)");
  if (r.steps.empty()) {
    std::fprintf(out, "  steps: %s; push recovery %s%s\n", no_steps.c_str(), push.c_str(), r.pushes.empty() ? "" : " s");
  } else {
    std::fprintf(out, "  steps (worst): overshoot %s %%, settling %s s (2-D %s s), steady-state error %s mm; push recovery %s%s\n",
                 f(r.overshoot_pct, 1, no_steps).c_str(), f(r.settling_time_s, 2, no_steps).c_str(),
                 f(r.settling_time_2d_s, 2, no_steps).c_str(),
                 f(r.steady_state_error_mm, 2, no_steps).c_str(), push.c_str(), r.pushes.empty() ? "" : " s");
  }
  if (std::isnan(r.observer_frame_ms)) {
    std::fprintf(out, "  frame cost: %s\n", no_timing.c_str());
    std::fprintf(out, "  fast path (edge tracking) on %d of %d frames\n", r.tracked_frames, r.frames);
  } else {
    std::fprintf(out, "  frame cost: observer %.3f ms, plain OpenCV reference %.3f ms, ratio %.3f\n", r.observer_frame_ms,
                 r.reference_frame_ms, r.frame_time_ratio_to_reference);
    std::fprintf(out, "  fast path (edge tracking) on %d of %d frames\n", r.tracked_frames, r.frames);
    std::fprintf(out, "  frame CPU time (this thread): observer %.3f ms, reference %.3f ms, ratio %.3f\n",
                 r.observer_frame_cpu_ms, r.reference_frame_cpu_ms, r.frame_cpu_ratio_to_reference);
  }
  std::fprintf(out, "  commands: max |tilt| %.2f deg, max rate %.1f deg/s, limits %s; wall %.1f s\n",
               r.max_commanded_angle_deg, r.max_commanded_rate_deg_s, r.limits_respected ? "respected" : "VIOLATED",
               r.wall_seconds);
  if (!r.faults.empty()) std::fprintf(out, "  %s\n", runtime::summaryLine(r.faults).c_str());
  for (const auto& m : r.robot_faults) {
    const std::string back =
        std::isinf(m.resettle_s) ? "never (before the next event)" : "after " + f(m.resettle_s, 2, "?") + " s";
    std::fprintf(out, "  %s %.3f-%.3f s: largest |p - set point| %.1f mm, back within %.0f mm %s\n", m.kind.c_str(),
                 m.from_s, m.to_s, m.peak_excursion_mm, 1000.0 * cfg.push_band, back.c_str());
    if (m.border_contact) std::fprintf(out, "    the ball reached a border\n");
  }
}

}  // namespace viewline::scenarios
