#include "viewline/scenarios/pan_tilt/replay.h"

#include <algorithm>
#include <cmath>
#include <cstdlib>
#include <fstream>
#include <iomanip>
#include <optional>
#include <sstream>
#include <tuple>
#include <vector>

#include "viewline/tracking/planar_target/waypoint_particles.h"
#include "viewline/core/error.h"
#include "viewline/core/random.h"
#include "viewline/scenarios/pan_tilt/metrics.h"
#include "viewline/scenarios/pan_tilt/world.h"

namespace viewline::scenarios {

using Eigen::Vector2d;

nlohmann::json PanTiltReplayMetrics::toJson() const {
  return {{"measurements", measurements},
          {"jumps", jumps},
          {"rmse_measured_cm", {rmse_measured_cm.x(), rmse_measured_cm.y()}},
          {"rmse_filtered_cm", {rmse_filtered_cm.x(), rmse_filtered_cm.y()}},
          {"horizon_s", horizon_s},
          {"rmse_predicted_cm", {rmse_predicted_cm.x(), rmse_predicted_cm.y()}},
          {"predicted_error_px", predicted_error_px},
          {"frame_horizon_s", frame_horizon_s},
          {"frame_predicted_error_px", frame_predicted_error_px},
          {"region_dropped", region_dropped},
          {"corner_settings", {{"min_samples", min_samples}, {"corner_sigma_m", corner_sigma}}},
          {"consistency", consistency.toJson()}};
}

void writeSyntheticPanTiltFrames(const PanTiltScenarioConfig& cfg, std::uint64_t seed, const std::string& frames_csv) {
  cfg.validate();
  const sim::ScreenPath path = pan_tilt::makePath(cfg, seed);
  const Vector2d sigma = pan_tilt::noiseSigma(cfg, path);
  core::Rng rng(core::deriveSeed(seed, 79));  // not the closed loop's noise stream: a study of its own
  std::ofstream out(frames_csv);
  if (!out) throw core::InvalidInput(frames_csv + ": cannot write");
  out << std::setprecision(17) << "t,truth_x,truth_y,detected,meas_x,meas_y\n";
  const double occ0 = cfg.occlusion_start >= 0.0 ? cfg.occlusion_start : 1e300;
  const double occ1 = occ0 + cfg.occlusion_duration;
  const auto frames = static_cast<std::size_t>(std::floor(cfg.duration * cfg.fps));
  for (std::size_t k = 0; k < frames; ++k) {
    const double t = static_cast<double>(k) / cfg.fps;
    const Vector2d p = path.position(t);
    const Vector2d n(core::gaussian(rng, sigma.x()), core::gaussian(rng, sigma.y()));  // drawn every frame
    const bool seen = !(t >= occ0 && t < occ1);
    out << t << "," << p.x() << "," << p.y() << "," << (seen ? 1 : 0) << ",";
    if (seen) out << p.x() + n.x() << "," << p.y() + n.y() << "\n";
    else out << "nan,nan\n";
  }
  if (!out) throw core::IoError(frames_csv + ": write failed");
}

PanTiltReplayMetrics replayPanTiltFilter(const PanTiltScenarioConfig& cfg, std::uint64_t seed,
                                         const std::string& frames_csv, PanTiltReplayEstimator estimator,
                                         io::LogDirectory* log, std::size_t particles) {
  const bool oracle_corners = estimator == PanTiltReplayEstimator::OracleCorners;
  cfg.validate();
  const sim::ScreenPath path = pan_tilt::makePath(cfg, seed);  // the run's path and [T] noise
  const sim::ScreenPathParams& pp = cfg.path;
  const Eigen::Matrix2d R = pan_tilt::noiseCovariance(pan_tilt::noiseSigma(cfg, path));

  std::ifstream in(frames_csv);
  if (!in) throw core::InvalidInput(frames_csv + ": cannot read (predictive_frames.csv of pan_tilt_tracking --log)");
  std::string line;
  std::getline(in, line);
  std::vector<std::string> header;
  {
    std::stringstream ss(line);
    std::string f;
    while (std::getline(ss, f, ',')) header.push_back(f);
  }
  const auto col = [&](const std::string& name) {
    const auto it = std::find(header.begin(), header.end(), name);
    if (it == header.end()) throw core::InvalidInput(frames_csv + ": no column '" + name + "'");
    return static_cast<std::size_t>(it - header.begin());
  };
  const std::size_t ct = col("t"), cd = col("detected"), cx = col("meas_x"), cy = col("meas_y");
  // The log's own truth (when it has it) must be the path of `seed`: a log of another seed, path or
  // speed would otherwise be scored against the wrong truth without a word.
  const auto has = [&](const std::string& name) { return std::find(header.begin(), header.end(), name) != header.end(); };
  const bool check_truth = has("truth_x") && has("truth_y");
  const std::size_t ctx = check_truth ? col("truth_x") : 0, cty = check_truth ? col("truth_y") : 0;

  control::PredictiveConfig pc = cfg.control;
  pc.filter.particle_seed = core::deriveSeed(seed, 78);  // as runPanTilt: a replay reproduces the run
  control::PredictivePanTiltController ctrl(pc, cfg.unit.limits, cfg.unit.latency, pan_tilt::screenPose(cfg));
  // Oracle (a bound, not a controller): constant-speed legs started at the path's true corner times with
  // the true speed; jump detection off. Only the leg directions, the corners' positions and the speed's
  // leg-to-leg variation (none) remain to be estimated from the measurements.
  std::optional<tracking::PlanarTargetFilter> oracle;
  std::vector<double> corners;
  std::size_t next_corner = 0;
  if (oracle_corners) {
    if (pp.shape == sim::PathShape::Circle) throw core::InvalidInput("--oracle-corners: the circle has no corners");
    if (pp.corner_radius > 0.0)
      throw core::InvalidInput("--oracle-corners: the path's corners are rounded (path.corner_radius > 0); the oracle's "
                               "legs are straight");
    tracking::TargetFilterConfig fc;
    fc.model = tracking::TargetModel::ConstantVelocity;
    fc.q = 1e-5;  // the first leg (before the first corner), a plain CV filter
    fc.init_velocity_sigma = cfg.control.filter.init_velocity_sigma;
    fc.gate_probability = cfg.control.filter.gate_probability;
    fc.reinit_after = cfg.control.filter.reinit_after;
    fc.jump_window = 1.0;
    fc.jump_threshold = 1e300;  // never fires
    fc.constant_speed = true;
    fc.constant_speed_sigma = 0.0;
    fc.turn_prior_weight = cfg.control.filter.turn_prior_weight;  // the config's learnt-turn prior, if any
    fc.turn_prior_sigma_deg = cfg.control.filter.turn_prior_sigma_deg;
    fc.region_center = cfg.control.filter.region_center;  // and its waypoint region, if any
    fc.region_size = cfg.control.filter.region_size;
    oracle.emplace(fc);
    corners = path.cornerTimes(cfg.duration);
  }
  // Reference (not a controller): the waypoint particle filter, the posterior mean under the random
  // path's generator. It knows the generator's box (filter.region) and minimum leg, not the path.
  std::optional<tracking::WaypointParticleFilter> pf;
  if (estimator == PanTiltReplayEstimator::WaypointParticles) {
    if (pp.shape != sim::PathShape::Random || pp.corner_radius > 0.0)
      throw core::InvalidInput("--particles: the model is the random path's (sharp corners, "
                               "path.corner_radius 0)");
    const auto& fcfg = cfg.control.filter;
    if (!(fcfg.region_size.x() > 0.0 && fcfg.region_size.y() > 0.0))
      throw core::InvalidInput("--particles: needs the waypoint region (filter.region: {center, size})");
    tracking::WaypointParticleConfig wc;
    wc.particles = particles;
    wc.region_center = fcfg.region_center;
    wc.region_size = fcfg.region_size;
    wc.min_leg = 0.1 * std::min(fcfg.region_size.x(), fcfg.region_size.y());  // as sim::ScreenPath
    wc.speed_min = wc.speed_max = pp.speed;  // given, as to the oracle (our filter learns it in the first legs)
    wc.seed = core::deriveSeed(seed, 77);
    pf.emplace(wc);
  }
  const auto filterReady = [&]() {
    return pf ? pf->initialized() : oracle ? oracle->initialized() : ctrl.filter().initialized();
  };
  const auto filterAt = [&](double t) {
    return pf ? pf->predict(t) : oracle ? Vector2d(oracle->at(t).p) : Vector2d(ctrl.filter().at(t).p);
  };
  const double occ0 = cfg.occlusion_start >= 0.0 ? cfg.occlusion_start : 1e300;
  const double occ1 = cfg.occlusion_start >= 0.0 ? cfg.occlusion_start + cfg.occlusion_duration : 1e300;
  PanTiltReplayMetrics out;
  out.horizon_s = cfg.processing_delay + cfg.unit.latency + cfg.control.lead;
  out.frame_horizon_s = (std::floor((cfg.processing_delay + cfg.unit.latency) * cfg.fps + 1e-9) + 1.0) / cfg.fps;
  pan_tilt::SquareSum mx, my, fx_, fy_, px_, py_, frame_p;
  io::CsvWriter* csv = nullptr;
  if (log != nullptr && log->enabled())
    csv = &log->stream("replay_frames", {"t", "truth_x", "truth_y", "detected", "meas_x", "meas_y", "filt_x", "filt_y",
                                         "accepted", "jumps"});
  std::size_t row = 1;
  while (std::getline(in, line)) {
    ++row;
    if (line.empty()) continue;
    std::vector<double> v;
    std::stringstream ss(line);
    std::string f;
    while (std::getline(ss, f, ',')) {
      if (f.empty() || f == "nan") {
        v.push_back(std::nan(""));
        continue;
      }
      // A field that is not a whole number is refused with its row and column (strtod alone would
      // read "abc" as 0 and replay a different run without a word).
      char* end = nullptr;
      const double x = std::strtod(f.c_str(), &end);
      if (end == f.c_str() || *end != '\0')
        throw core::InvalidInput(frames_csv + ":" + std::to_string(row) + ": column " + std::to_string(v.size() + 1) +
                                 " is '" + f + "' (expected a number or nan)");
      v.push_back(x);
    }
    if (v.size() != header.size()) throw core::InvalidInput(frames_csv + ":" + std::to_string(row) + ": wrong number of columns");
    const double t = v[ct];
    // A missing or infinite time stamp would reach the filter as NaN/inf (every measurement carries its time).
    if (!std::isfinite(t))
      throw core::InvalidInput(frames_csv + ":" + std::to_string(row) + ": column " + std::to_string(ct + 1) +
                               " (t) is '" + (std::isnan(t) ? std::string("nan") : std::string("inf")) +
                               "' (expected a finite time, s)");
    if (t >= cfg.duration) break;
    if (check_truth && (path.position(t) - Vector2d(v[ctx], v[cty])).norm() > 1e-6)
      throw core::InvalidInput(frames_csv + ":" + std::to_string(row) + ": the logged truth (" + std::to_string(v[ctx]) +
                               ", " + std::to_string(v[cty]) + ") is not the path of seed " + std::to_string(seed) +
                               " at t = " + std::to_string(t) +
                               " s: replay with the --seed and the path settings the log was made with");
    control::TargetObservation obs;
    obs.stamp = t;
    obs.detected = v[cd] > 0.5;
    if (obs.detected) {
      obs.plane = Vector2d(v[cx], v[cy]);
      obs.plane_cov = R;
      ++out.measurements;
    }
    bool accepted = false;
    Vector2d filtered = Vector2d::Constant(std::nan(""));  // scored on every detected frame, as in the closed loop
    if (pf) {
      if (obs.detected) {
        pf->update(t, obs.plane, R);
        accepted = true;
        filtered = pf->mean();
      } else {
        pf->propagateTo(t);
      }
    } else if (oracle) {
      while (next_corner < corners.size() && corners[next_corner] <= t) {
        if (oracle->initialized() && corners[next_corner] >= oracle->state().t()) {
          oracle->setSpeed(pp.speed, 1e-12);
          oracle->startLeg(corners[next_corner]);
        }
        ++next_corner;
      }
      if (obs.detected) {
        accepted = oracle->update(t, obs.plane, R).accepted;
        filtered = accepted ? Vector2d(oracle->estimate().x().head<2>()) : Vector2d(oracle->at(t).p);
      }
    } else {
      const bool had_track = ctrl.filter().initialized();
      const std::size_t restarts = ctrl.reacquisitions();
      ctrl.observe(obs);
      accepted = ctrl.lastUpdate().accepted;
      const auto& u = ctrl.lastUpdate();
      if (obs.detected && had_track && ctrl.reacquisitions() == restarts && u.decision &&
          (*u.decision == tracking::GateDecision::Accept || *u.decision == tracking::GateDecision::Reject) &&
          t >= cfg.metrics_start && !(t >= occ0 && t < occ1 + 2.0)) {
        // As the closed loop's Scorer::consistency: NIS of every tested measurement, NEES when fused.
        const estimation::StateEstimate& est = ctrl.filter().estimate();
        Eigen::Vector4d truth;
        truth << path.position(t), path.velocity(t);
        out.consistency.fps = cfg.fps;
        out.consistency.addNis(u.nis);
        if (*u.decision == tracking::GateDecision::Accept)
          out.consistency.addNees(est.x().head<4>(), est.P().topLeftCorner<4, 4>(), truth);
      }
      if (obs.detected && ctrl.filter().initialized())
        filtered = accepted ? ctrl.filteredPlane() : Vector2d(ctrl.filter().at(t).p);
    }
    if (csv != nullptr) {
      const Vector2d truth = path.position(t);
      const double nan = std::nan("");
      csv->row({t, truth.x(), truth.y(), obs.detected ? 1.0 : 0.0, obs.detected ? obs.plane.x() : nan,
                obs.detected ? obs.plane.y() : nan, filtered.x(), filtered.y(),
                accepted ? 1.0 : 0.0, static_cast<double>(oracle ? next_corner : ctrl.filter().jumps())});
    }
    if (!(t >= cfg.metrics_start && !(t >= occ0 && t < occ1 + 2.0))) continue;
    const Vector2d truth = path.position(t);
    if (obs.detected) {
      mx.add(std::pow(obs.plane.x() - truth.x(), 2));
      my.add(std::pow(obs.plane.y() - truth.y(), 2));
      if (std::isfinite(filtered.x())) {
        fx_.add(std::pow(filtered.x() - truth.x(), 2));
        fy_.add(std::pow(filtered.y() - truth.y(), 2));
      }
    }
    if (filterReady()) {
      const Vector2d e = filterAt(t + out.horizon_s) - path.position(t + out.horizon_s);
      px_.add(e.x() * e.x());
      py_.add(e.y() * e.y());
      frame_p.add((filterAt(t + out.frame_horizon_s) - path.position(t + out.frame_horizon_s)).squaredNorm());
    }
  }
  out.jumps = pf ? 0 : oracle ? corners.size() : ctrl.filter().jumps();
  out.region_dropped = pf ? false : oracle ? oracle->regionDropped() : ctrl.filter().regionDropped();
  if (!pf && !oracle) std::tie(out.min_samples, out.corner_sigma) = pan_tilt::cornerSettings(ctrl.filter());
  out.rmse_measured_cm = 100.0 * Vector2d(mx.rms(), my.rms());
  out.rmse_filtered_cm = 100.0 * Vector2d(fx_.rms(), fy_.rms());
  out.rmse_predicted_cm = 100.0 * Vector2d(px_.rms(), py_.rms());
  out.predicted_error_px = std::hypot(px_.rms(), py_.rms()) * cfg.fx / cfg.screen_distance;
  out.frame_predicted_error_px = frame_p.rms() * cfg.fx / cfg.screen_distance;
  return out;
}

}  // namespace viewline::scenarios
