#include "viewline/scenarios/dart/metrics.h"

#include <cstdarg>
#include <cstdio>

#include "viewline/estimation/consistency.h"

namespace viewline::scenarios {

double PooledError::rmse() const { return n ? core::rmsFromSum(se, static_cast<long>(n)) : 0.0; }

void PooledError::add(const estimation::StateEstimate& s, const tracking::Vector6& truth) {
  se += (s.x().head<3>() - truth.head<3>()).squaredNorm();
  nees += estimation::nees(s, truth, {0, 1, 2});
  ++n;
}

void countGate(GateFigures& g, const tracking::ViewlineTracker& tracker, const DartFlight& flight) {
  for (const DartDetection& d : flight.detections) {
    const auto o = tracker.outcome(d.m.id);
    if (!o) continue;  // refused before processing (e.g. outside the image)
    const bool rejected = o->fate != tracking::Fate::Fused;
    if (d.outlier) {
      ++g.outliers;
      if (rejected) ++g.outliers_rejected;
    } else {
      ++g.inliers;
      if (rejected) ++g.inliers_rejected;
    }
  }
}

void finishGate(GateFigures& g, const PooledError& p) {
  g.outlier_rejected_fraction = g.outliers ? static_cast<double>(g.outliers_rejected) / static_cast<double>(g.outliers) : 1.0;
  g.inlier_rejected_fraction = g.inliers ? static_cast<double>(g.inliers_rejected) / static_cast<double>(g.inliers) : 0.0;
  g.rmse_position = p.rmse();
  const std::size_t settled = p.n + p.unreported;
  g.reported_fraction = settled ? static_cast<double>(p.n) / static_cast<double>(settled) : 1.0;
}

namespace {

nlohmann::json interval(const core::Interval& i) { return nlohmann::json::array({i.lo, i.hi}); }

nlohmann::json gateJson(const GateFigures& g) {
  return {{"gate", g.gate},
          {"outliers", g.outliers},
          {"outliers_rejected", g.outliers_rejected},
          {"inliers", g.inliers},
          {"inliers_rejected", g.inliers_rejected},
          {"outlier_rejected_fraction", g.outlier_rejected_fraction},
          {"inlier_rejected_fraction", g.inlier_rejected_fraction},
          {"rmse_position_m", g.rmse_position},
          {"reported_fraction", g.reported_fraction},
          {"restarts", g.restarts}};
}

}  // namespace

namespace {
void appendf(std::string& out, const char* format, ...) __attribute__((format(printf, 2, 3)));
void appendf(std::string& out, const char* format, ...) {
  char line[512];
  va_list args;
  va_start(args, format);
  std::vsnprintf(line, sizeof line, format, args);
  va_end(args);
  out += line;
}
}  // namespace

std::string dartSummaryText(const DartSummary& s) {
  std::string o;
  appendf(o, "dart_tracking: %d runs, seed %llu, %.1f detections/flight (measurement-level scenario)\n", s.runs,
          static_cast<unsigned long long>(s.seed), s.measurements_per_flight);
  appendf(o, "  NEES (6-dof, alternating, 1/run)  %.3f  band [%.3f, %.3f]  %s\n", s.nees_mean, s.nees_bounds.lo,
          s.nees_bounds.hi, s.nees_bounds.contains(s.nees_mean) ? "inside" : "OUTSIDE");
  appendf(o, "  position RMSE / PCRLB              %.4f m / %.4f m = %.3f (final %.3f)\n", s.rmse_position,
          s.pcrlb_position, s.rmse_to_pcrlb, s.rmse_to_pcrlb_final);
  for (const auto* g : {&s.gate_directional, &s.gate_mahalanobis})
    appendf(o, "  gate %-12s outliers rejected %.4f (%zu/%zu)  inliers rejected %.4f (%zu/%zu)  RMSE %.4f m\n",
            g->gate.c_str(), g->outlier_rejected_fraction, g->outliers_rejected, g->outliers,
            g->inlier_rejected_fraction, g->inliers_rejected, g->inliers, g->rmse_position);
  appendf(o, "  better gate: %s (RMSE %.2fx outlier-free, reported %.4f);  image-space EKF RMSE %.4f m\n",
          s.better_gate.c_str(), s.rmse_outliers_to_outlier_free,
          s.better_gate == "directional" ? s.gate_directional.reported_fraction : s.gate_mahalanobis.reported_fraction,
          s.rmse_image_ekf_alternating);
  appendf(o, "  async RMSE  exact %.4f m  dt-offset %.4f m  image EKF %.4f m;  update %.1f us\n", s.rmse_async_exact,
          s.rmse_async_dt_offset, s.rmse_async_image_ekf, s.update_time_us);
  appendf(o, "  full scenario (%s gate): outliers rejected %.4f  inliers rejected %.4f  RMSE %.4f m\n",
          s.scenario_gate.gate.c_str(), s.scenario_gate.outlier_rejected_fraction,
          s.scenario_gate.inlier_rejected_fraction, s.scenario_gate.rmse_position);
  appendf(o, "  late vs in-order max diff %.3g (%zu late insertions, %zu outcome mismatches)\n",
          s.late_vs_inorder_max_diff, s.late_inserted, s.late_outcome_mismatches);
  appendf(o, "  single camera, prior <= 70 m off: converged after p95 %.0f (median %.0f) measurements\n",
          s.single_camera_convergence_p95, s.single_camera_convergence_median);
  appendf(o, "    information limit (ideal filters, true depth): p95 %.0f (median %.0f)\n",
          s.single_camera_convergence_bound_p95, s.single_camera_convergence_bound_median);
  appendf(o, "  runtime %.1f s\n", s.runtime_s);
  return o;
}

nlohmann::json summaryToJson(const DartSummary& s, const DartScenarioConfig& cfg) {
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
  j["reported_fraction"] = s.reported_fraction;
  j["reported_convention"] =
      "RMSE, PCRLB and NEES pool the estimates the tracker reports: after a measurement that leaves a confirmed track "
      "(tracker.start: a tentative track is confirmed once confirm_images images are jointly consistent); "
      "reported_fraction = reported / settled measurements";
  j["rmse_to_pcrlb_convention"] =
      "outlier-free alternating runs; sqrt(mean |p_hat - p|^2) / sqrt(mean trace PCRLB_pp), pooled over measurements "
      "with index >= " + std::to_string(cfg.settled_index) + "; PCRLB from the true states with the pixel Jacobian";
  j["outlier_rejected_fraction"] = s.outlier_rejected_fraction;
  j["inlier_rejected_fraction"] = s.inlier_rejected_fraction;
  j["better_gate"] = s.better_gate;
  j["gates"] = {gateJson(s.gate_directional), gateJson(s.gate_mahalanobis)};
  j["rmse_image_ekf_alternating_m"] = s.rmse_image_ekf_alternating;
  j["rmse_outliers_to_outlier_free"] = s.rmse_outliers_to_outlier_free;
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
  j["single_camera_convergence_bound_p95"] = s.single_camera_convergence_bound_p95;
  j["single_camera_convergence_bound_median"] = s.single_camera_convergence_bound_median;
  j["runtime_s"] = s.runtime_s;
  return j;
}

}  // namespace viewline::scenarios
