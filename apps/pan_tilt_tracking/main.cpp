// Pan-tilt tracking ([T], issue 6): a camera on a simulated FLIR PTU-D46 keeps a dark disc moving
// on a screen at the image centre. Runs our predictive law and ViSP's baseline law on the same
// seed and reports [T]'s Table 1 beside ours. The loop itself is library code
// (viewline/scenarios/pan_tilt_scenario.h).
//
//   pan_tilt_tracking --config config/pan_tilt_circle.yaml --duration 60 --seed 1 --headless --summary out.json
//   pan_tilt_tracking --config <variant>.yaml --seed 1 --replay <log>/predictive_frames.csv   (filter only)
//   pan_tilt_tracking --config <path>.yaml --seed 1 --replay <log>/predictive_frames.csv --oracle-corners
//       (a bound: the filter told the true corner times and speed; rectangle and random paths)
//   pan_tilt_tracking --config config/pan_tilt_random.yaml --seed 1 --replay <log>/predictive_frames.csv --particles
//       (the reference: the waypoint particle filter, posterior mean under the random path's generator)

#include <CLI/CLI.hpp>
#include <cmath>
#include <cstdio>
#include <iostream>
#include <memory>
#include <string>

#include "viewline/core/error.h"
#include "viewline/io/config_edit.h"
#include "viewline/io/files.h"
#include "viewline/io/log.h"
#include "viewline/scenarios/pan_tilt_display.h"
#include "viewline/scenarios/pan_tilt_scenario.h"

using namespace viewline;

namespace {
// " (auto)" when filter.jump_min_samples or jump_corner_sigma is "auto" (then chosen by the filter from
// the noise and the target's step), else "".
std::string cornerSettingsOrigin(const scenarios::PanTiltScenarioConfig& cfg) {
  const auto& f = cfg.control.filter;
  const bool m = !f.jump_min_samples, c = !f.jump_corner_sigma;
  return m && c ? " (auto)" : m ? " (min samples auto)" : c ? " (corner sigma auto)" : "";
}
}  // namespace

int main(int argc, char** argv) {
  CLI::App app{"viewline pan-tilt tracking ([T]): predictive servo vs ViSP's point servo on a simulated FLIR PTU-D46"};
  std::string config_path, log_dir, summary_path, replay_path;
  std::vector<std::string> sets;
  std::uint64_t seed = 1;
  double duration = -1.0;
  bool headless = false, display = false, no_baseline = false, oracle_corners = false, use_particles = false;
  std::size_t particles = 20000;
  app.add_option("--config", config_path, "scenario YAML (config/pan_tilt_*.yaml)")->required();
  app.add_option("--seed", seed, "random seed (path, sensor noise, [T] measurement noise)");
  app.add_option("--set", sets, io::kSetOptionHelp)->take_all();
  app.add_option("--duration", duration, "simulated seconds (overrides run.duration)");
  app.add_flag("--headless", headless, "no window (default)");
  app.add_flag("--display", display, "show the image, target, prediction and error live (vpDisplayX)");
  app.add_option("--log", log_dir, "directory for CSV logs (truth, measurements, estimates, commands; with --replay: replay_frames.csv)");
  app.add_option("--summary", summary_path, "metrics JSON file");
  app.add_flag("--no-baseline", no_baseline, "skip the ViSP baseline run");
  app.add_option("--replay", replay_path,
                 "filter only: re-run this config's target filter on the measurements of a --log run "
                 "(<log>/predictive_frames.csv, same --seed and --duration) instead of simulating");
  app.add_flag("--oracle-corners", oracle_corners,
               "with --replay (rectangle, random): instead of the config's filter, a bound: constant-speed legs "
               "told the path's true corner times and speed");
  app.add_flag("--particles", use_particles,
               "with --replay (random path): instead of the config's filter, the reference: a particle filter of "
               "the path's generator (waypoints uniform in filter.region, one constant speed)");
  app.add_option("--particle-count", particles, "particles of --particles")->check(CLI::Range(10, 10000000));
  CLI11_PARSE(app, argc, argv);
  if ((oracle_corners || use_particles) && replay_path.empty()) {
    std::cerr << (oracle_corners ? "--oracle-corners" : "--particles") << " needs --replay\n";
    return 2;
  }
  if (oracle_corners && use_particles) {
    std::cerr << "--oracle-corners and --particles are exclusive\n";
    return 2;
  }
  const scenarios::PanTiltReplayEstimator estimator =
      oracle_corners  ? scenarios::PanTiltReplayEstimator::OracleCorners
      : use_particles ? scenarios::PanTiltReplayEstimator::WaypointParticles
                      : scenarios::PanTiltReplayEstimator::Filter;
  if (headless && display) {
    std::cerr << "--headless and --display are exclusive\n";
    return 2;
  }
  try {
    scenarios::PanTiltScenarioConfig cfg = scenarios::loadPanTiltScenarioConfig(io::loadConfigWithValues(config_path, sets));
    if (duration > 0.0) {
      cfg.duration = duration;
      if (cfg.metrics_start >= duration) cfg.metrics_start = 0.5 * duration;
    }
    if (no_baseline) cfg.run_baseline = false;
    cfg.validate();
    if (!replay_path.empty()) {
      io::LogDirectory replay_log(log_dir);
      const scenarios::PanTiltReplayMetrics r =
          scenarios::replayPanTiltFilter(cfg, seed, replay_path, estimator, replay_log.enabled() ? &replay_log : nullptr,
                                         particles);
      replay_log.flush();
      nlohmann::json rj = r.toJson();
      if (!sets.empty()) rj["config_set"] = sets;
      if (!summary_path.empty()) io::writeJsonFile(summary_path, rj);
      if (oracle_corners)
        std::printf("replay of %s (seed %llu, oracle: constant-speed legs at the %zu true corners): %zu measurements\n",
                    replay_path.c_str(), static_cast<unsigned long long>(seed), r.jumps, r.measurements);
      else if (use_particles)
        std::printf("replay of %s (seed %llu, reference: waypoint particle filter, %zu particles): %zu measurements\n",
                    replay_path.c_str(), static_cast<unsigned long long>(seed), particles, r.measurements);
      else
        std::printf("replay of %s (seed %llu, filter %s): %zu measurements, %zu velocity jumps detected\n",
                    replay_path.c_str(), static_cast<unsigned long long>(seed),
                    control::toString(cfg.control.filter.model), r.measurements, r.jumps);
      std::printf("  rmse measured (cm)          x %.4f  y %.4f\n", r.rmse_measured_cm.x(), r.rmse_measured_cm.y());
      std::printf("  rmse filtered (cm)          x %.4f  y %.4f\n", r.rmse_filtered_cm.x(), r.rmse_filtered_cm.y());
      std::printf("  rmse predicted %.4f s ahead (cm)  x %.4f  y %.4f  (%.2f px)\n", r.horizon_s, r.rmse_predicted_cm.x(),
                  r.rmse_predicted_cm.y(), r.predicted_error_px);
      std::printf("  predicted %.4f s ahead, what the frames see (px)  %.2f\n", r.frame_horizon_s, r.frame_predicted_error_px);
      if (r.min_samples > 0)
        std::printf("  corner settings%s at the end: %d measurements, %.4f m\n", cornerSettingsOrigin(cfg).c_str(),
                    r.min_samples, r.corner_sigma);
      if (r.region_dropped)
        std::printf("  WARNING: the target left filter.region (measurements outside it): the region was dropped; "
                    "check its center and size\n");
      return 0;
    }

    std::unique_ptr<scenarios::PanTiltDisplay> view;
    if (display) view = std::make_unique<scenarios::PanTiltDisplay>();
    io::LogDirectory log(log_dir);
    int last_pct = -1;
    const auto progress = [&](double f) {
      const int pct = static_cast<int>(std::lround(100.0 * f));
      if (pct / 10 != last_pct / 10) std::fprintf(stderr, "\r%3d %%", pct);
      last_pct = pct;
      if (pct >= 100) std::fprintf(stderr, "\n");
    };
    scenarios::PanTiltFrameSink sink;
    if (view) sink = [&](const scenarios::PanTiltFrameView& v) { view->show(v); };
    const scenarios::PanTiltComparison result =
        scenarios::runPanTiltComparison(cfg, seed, sink, log.enabled() ? &log : nullptr, progress);
    log.flush();
    nlohmann::json j = result.toJson(cfg);
    if (!sets.empty()) j["config_set"] = sets;
    if (!summary_path.empty()) io::writeJsonFile(summary_path, j);

    const auto& o = result.ours;
    std::printf("pan-tilt %s, seed %llu, %.0f s at %.0f fps (%ux%u, fx %.0f fy %.0f), filter %s, gain %.2f (ours %.2f)\n",
                result.path.c_str(), static_cast<unsigned long long>(seed), cfg.duration, cfg.fps, cfg.image_width,
                cfg.image_height, cfg.fx, cfg.fy, control::toString(cfg.control.filter.model), cfg.control.servo.gain,
                cfg.control.gain > 0.0 ? cfg.control.gain : cfg.control.servo.gain);
    if (!cfg.rig_folder.empty()) {
      std::printf("  rig %s: renders with truth.yaml, controls with rig.yaml + e_M_c.yaml\n", cfg.rig_folder.c_str());
    }
    std::printf("  [T] noise sigma (cm)        x %.3f  y %.3f\n", o.noise_sigma_cm.x(), o.noise_sigma_cm.y());
    std::printf("  rmse measured (cm)          x %.4f  y %.4f\n", o.rmse_measured_cm.x(), o.rmse_measured_cm.y());
    std::printf("  rmse filtered (cm)          x %.4f  y %.4f\n", o.rmse_filtered_cm.x(), o.rmse_filtered_cm.y());
    const auto t = scenarios::tTable1(cfg.path.shape);
    if (t.available) {
      std::printf("  [T] Table 1 measured / KF   x %.4f / %.4f  y %.4f / %.4f  (target: filtered <= %.4f, %.4f)\n",
                  t.measured.x(), t.kalman.x(), t.measured.y(), t.kalman.y(), 0.5 * t.kalman.x(), 0.5 * t.kalman.y());
    }
    std::printf("  image error rms (px)        ours %.2f", o.image_error_rms_px);
    if (result.has_baseline) {
      std::printf("  baseline %.2f  ratio %.3f", result.baseline.image_error_rms_px,
                  o.image_error_rms_px / result.baseline.image_error_rms_px);
    }
    std::printf("\n  limits: unsafe commands %zu, rate violations %zu, hard-stop hits %zu (ours)",
                o.unsafe_commands, o.rate_violations, o.limit_hits);
    if (result.has_baseline) {
      std::printf("; %zu, %zu, %zu (baseline)", result.baseline.unsafe_commands, result.baseline.rate_violations,
                  result.baseline.limit_hits);
    }
    std::printf("\n  pan %.1f..%.1f deg, tilt %.1f..%.1f deg\n", o.pan_range_deg.x(), o.pan_range_deg.y(),
                o.tilt_range_deg.x(), o.tilt_range_deg.y());
    if (o.occlusion) {
      std::printf("  occlusion %.1f s at %.1f s: %s", cfg.occlusion_duration, cfg.occlusion_start,
                  o.reacquired ? "reacquired" : "NOT reacquired");
      if (o.reacquired) std::printf(" %.3f s after it ended", o.reacquisition_delay_s);
      std::printf("\n");
    }
    std::printf("  filter: %zu velocity jumps (corners) detected", o.filter_jumps);
    if (o.filter_min_samples > 0)
      std::printf("; corner settings%s: %d measurements, %.4f m", cornerSettingsOrigin(cfg).c_str(),
                  o.filter_min_samples, o.filter_corner_sigma);
    std::printf("\n");
    if (o.filter_region_dropped)
      std::printf("  WARNING: the target left filter.region (measurements outside it): the region was dropped; "
                  "check its center and size\n");
    std::printf("  %.1f ms per frame (render + detect + control)\n", o.wall_ms_per_frame);
    return 0;
  } catch (const core::Error& e) {
    std::cerr << "error: " << e.what() << "\n";
    return 1;
  }
}
