#include "dart_config.h"

#include "viewline/core/frames.h"
#include "viewline/io/config_edit.h"

namespace viewline::apps {

namespace {

tracking::DartScenarioConfig fromNode(const io::ConfigNode& root) {
  tracking::DartScenarioConfig cfg = tracking::defaultDartScenario();
  if (root.has("cameras")) {
    cfg.cameras.clear();
    for (const io::ConfigNode& c : root.childList("cameras")) {
      tracking::DartCameraConfig cam;
      cam.name = c.getOr<std::string>("name", cam.name);
      cam.eye_w = c.get<Eigen::Vector3d>("eye");
      cam.target_w = c.get<Eigen::Vector3d>("target");
      cam.hfov_rad = c.getAngle("hfov_deg");
      cam.width = c.getOr<unsigned>("width", cam.width);
      cam.height = c.getOr<unsigned>("height", cam.height);
      cam.kud = c.getOr<double>("kud", cam.kud);
      cam.rate_hz = c.getOr<double>("rate_hz", cam.rate_hz);
      cam.clock_drift_std = c.getOr<double>("clock_drift_std", cam.clock_drift_std);
      cam.jitter_std_s = c.getOr<double>("jitter_std_s", cam.jitter_std_s);
      if (!(cam.rate_hz > 0)) c.fail("rate_hz", "a positive number");
      cfg.cameras.push_back(cam);
    }
    if (cfg.cameras.empty()) root.fail("cameras", "at least one camera");
  }
  cfg.gravity_w = root.getOr<Eigen::Vector3d>("gravity", cfg.gravity_w);
  if (root.has("throw")) {
    const io::ConfigNode t = root.child("throw");
    cfg.release_mean = t.getOr<Eigen::Vector3d>("release_mean", cfg.release_mean);
    cfg.release_std = t.getOr<Eigen::Vector3d>("release_std", cfg.release_std);
    cfg.board_center = t.getOr<Eigen::Vector3d>("board_center", cfg.board_center);
    cfg.aim_std = t.getOr<double>("aim_std", cfg.aim_std);
    cfg.speed_min = t.getOr<double>("speed_min", cfg.speed_min);
    cfg.speed_max = t.getOr<double>("speed_max", cfg.speed_max);
    cfg.truth_accel_psd = t.getOr<double>("truth_accel_psd", cfg.truth_accel_psd);
  }
  cfg.pixel_noise_px = root.getOr<double>("pixel_noise_px", cfg.pixel_noise_px);
  cfg.outlier_rate = root.getOr<double>("outlier_rate", cfg.outlier_rate);
  if (root.has("tracker")) {
    const io::ConfigNode t = root.child("tracker");
    tracking::TrackerConfig& tc = cfg.tracker;
    if (t.has("prior_position")) tc.prior_mean.head<3>() = t.get<Eigen::Vector3d>("prior_position");
    if (t.has("prior_velocity")) tc.prior_mean.tail<3>() = t.get<Eigen::Vector3d>("prior_velocity");
    if (t.has("prior_std")) {
      const double s = t.get<double>("prior_std");
      if (!(s > 0)) t.fail("prior_std", "a positive number (m and m/s)");
      tc.prior_cov = s * s * tracking::Matrix6::Identity();
    }
    tc.model.accel_psd = t.getOr<double>("accel_psd", tc.model.accel_psd);
    if (t.has("gate")) {
      tc.gate.kind = tracking::gateKindFromString(t.getChoice("gate", {"none", "directional", "mahalanobis"}),
                                                  t.keyPath("gate"));
    }
    tc.gate.directional_p = t.getOr<double>("directional_p", tc.gate.directional_p);
    tc.gate.mahalanobis_alpha = t.getOr<double>("mahalanobis_alpha", tc.gate.mahalanobis_alpha);
    tc.restart_after_rejections = t.getOr<int>("restart_after_rejections", tc.restart_after_rejections);
    tc.max_coast = t.getOr<double>("max_coast_s", tc.max_coast);
    tc.history_capacity = t.getOr<unsigned>("history_capacity", static_cast<unsigned>(tc.history_capacity));
    tc.min_depth = t.getOr<double>("min_depth", tc.min_depth);
    tc.max_forward_gap = t.getOr<double>("max_forward_gap_s", tc.max_forward_gap);
    tc.image_margin_px = t.getOr<double>("image_margin_px", tc.image_margin_px);
    cfg.dt_offset_period = t.getOr<double>("dt_offset_period_s", cfg.dt_offset_period);
  }
  if (root.has("experiments")) {
    const io::ConfigNode e = root.child("experiments");
    cfg.alternate_step = e.getOr<double>("alternate_step_s", cfg.alternate_step);
    cfg.late_max_delay = e.getOr<double>("late_max_delay_s", cfg.late_max_delay);
    cfg.late_horizon = e.getOr<double>("late_horizon_s", cfg.late_horizon);
    cfg.single_camera = e.getOr<unsigned>("single_camera", static_cast<unsigned>(cfg.single_camera));
    cfg.single_offset_max = e.getOr<double>("single_offset_max", cfg.single_offset_max);
    cfg.single_prior_std = e.getOr<double>("single_prior_std", cfg.single_prior_std);
    cfg.single_tolerance = e.getOr<double>("single_tolerance", cfg.single_tolerance);
    cfg.nees_index = e.getOr<unsigned>("nees_index", static_cast<unsigned>(cfg.nees_index));
    cfg.settled_index = e.getOr<unsigned>("settled_index", static_cast<unsigned>(cfg.settled_index));
    cfg.confidence = e.getOr<double>("confidence", cfg.confidence);
  }
  root.finish();
  cfg.tracker.model.gravity_w = cfg.gravity_w;
  try {
    cfg.validate();
  } catch (const core::InvalidInput& ex) {
    throw core::InvalidInput(root.fileName() + ": " + ex.what());
  }
  return cfg;
}

nlohmann::json interval(const core::Interval& i) { return nlohmann::json::array({i.lo, i.hi}); }

nlohmann::json gateJson(const tracking::GateFigures& g) {
  return {{"gate", g.gate},
          {"outliers", g.outliers},
          {"outliers_rejected", g.outliers_rejected},
          {"inliers", g.inliers},
          {"inliers_rejected", g.inliers_rejected},
          {"outlier_rejected_fraction", g.outlier_rejected_fraction},
          {"inlier_rejected_fraction", g.inlier_rejected_fraction},
          {"rmse_position_m", g.rmse_position}};
}

}  // namespace

tracking::DartScenarioConfig loadDartScenario(const std::string& path, const std::vector<std::string>& key_values) {
  return fromNode(io::loadConfigWithValues(path, key_values));
}

tracking::DartScenarioConfig dartScenarioFromString(const std::string& yaml, const std::string& name) {
  return fromNode(io::ConfigNode::fromString(yaml, name));
}

nlohmann::json summaryToJson(const tracking::DartSummary& s, const tracking::DartScenarioConfig& cfg) {
  nlohmann::json j;
  j["description"] = "dart_tracking (measurement-level: pixels generated from the true flights, no rendering)";
  j["seed"] = s.seed;
  j["runs"] = s.runs;
  j["measurements_per_flight"] = s.measurements_per_flight;
  j["nees_mean"] = s.nees_mean;
  j["nees_bounds"] = interval(s.nees_bounds);
  j["nees_dof"] = 6;
  j["nees_samples"] = s.nees_samples;
  j["nees_convention"] = "alternating cameras, no outliers; one full-state NEES per run at measurement index " +
                         std::to_string(cfg.nees_index) + " (independent samples); two-sided " +
                         std::to_string(cfg.confidence) + " chi-square band of the mean";
  j["nees_position_mean"] = s.nees_position_mean;
  j["nees_position_bounds"] = interval(s.nees_position_bounds);
  j["rmse_position_m"] = s.rmse_position;
  j["pcrlb_position_m"] = s.pcrlb_position;
  j["rmse_to_pcrlb"] = s.rmse_to_pcrlb;
  j["rmse_to_pcrlb_final"] = s.rmse_to_pcrlb_final;
  j["rmse_to_pcrlb_convention"] =
      "outlier-free alternating runs; sqrt(mean |p_hat - p|^2) / sqrt(mean trace PCRLB_pp), pooled over measurements "
      "with index >= " + std::to_string(cfg.settled_index) + "; PCRLB from the true states with the pixel Jacobian";
  j["outlier_rejected_fraction"] = s.outlier_rejected_fraction;
  j["inlier_rejected_fraction"] = s.inlier_rejected_fraction;
  j["better_gate"] = s.better_gate;
  j["gates"] = {gateJson(s.gate_directional), gateJson(s.gate_mahalanobis)};
  j["rmse_image_ekf_alternating_m"] = s.rmse_image_ekf_alternating;
  j["async"] = {{"rmse_exact_m", s.rmse_async_exact},
                {"rmse_dt_offset_m", s.rmse_async_dt_offset},
                {"rmse_image_ekf_m", s.rmse_async_image_ekf},
                {"nees_position_exact", s.nees_async_exact},
                {"nees_position_dt_offset", s.nees_async_dt_offset},
                {"update_time_us", s.update_time_us}};
  j["scenario"] = gateJson(s.scenario_gate);
  j["late_vs_inorder_max_diff"] = s.late_vs_inorder_max_diff;
  j["late_inserted"] = s.late_inserted;
  j["late_outcome_mismatches"] = s.late_outcome_mismatches;
  j["late_refused"] = s.late_refused;
  j["single_camera_convergence_p95"] = s.single_camera_convergence_p95;
  j["single_camera_convergence_median"] = s.single_camera_convergence_median;
  j["single_camera_not_converged"] = s.single_camera_not_converged;
  j["runtime_s"] = s.runtime_s;
  return j;
}

}  // namespace viewline::apps
