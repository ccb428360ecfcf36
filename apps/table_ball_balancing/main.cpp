// table_ball_balancing: [M]'s table-ball observer in the closed loop it was built for (issue 7).
// Thin main: parse the CLI, load the YAML scenario, run scenarios::runTableBall, print and write
// the summary. See modules/scenarios/include/viewline/scenarios/table_ball.h for the loop.

#include <CLI/CLI.hpp>
#include <cstdio>
#include <cstdlib>
#include <iostream>
#include <memory>

#include "viewline/core/error.h"
#include "viewline/io/config_edit.h"
#include "viewline/io/files.h"
#include "viewline/io/log.h"
#include "viewline/scenarios/table_ball.h"
#include "viewline/scenarios/table_ball_display.h"

using namespace viewline;

int main(int argc, char** argv) {
  CLI::App app{"Table-ball balancing: [M]'s observer (table PnP, ball on table, rolling-ball Kalman filter) "
               "and an LQR that tilts the table, on a rendered head-camera view"};
  std::string config_path = "config/table_ball.yaml", summary_path, log_dir;
  std::uint64_t seed = 1;
  double duration = -1.0;
  bool headless = false, display = false;
  std::vector<std::string> sets;
  app.add_option("--config", config_path, "scenario YAML")->check(CLI::ExistingFile);
  app.add_option("--set", sets, io::kSetOptionHelp)->take_all();
  app.add_option("--seed", seed, "random seed");
  app.add_option("--duration", duration, "simulated seconds (default: the config's duration)");
  app.add_flag("--headless", headless, "no display (never needs X)");
  app.add_flag("--display", display, "show the camera view and a top view (vpDisplayX)");
  app.add_option("--log", log_dir, "write CSV logs (truth, measurements, estimates, commands) to this directory");
  app.add_option("--summary", summary_path, "write the metrics as JSON");
  CLI11_PARSE(app, argc, argv);
  if (headless && display) {
    std::cerr << "table_ball_balancing: --headless and --display exclude each other\n";
    return 2;
  }
  try {
    scenarios::TableBallConfig cfg = scenarios::tableBallConfigFromYaml(io::loadConfigWithValues(config_path, sets));
    if (duration > 0.0) cfg.duration = duration;
    io::LogDirectory log(log_dir);
    scenarios::TableBallHooks hooks;
    if (!log_dir.empty()) hooks.log = &log;
    std::unique_ptr<scenarios::TableBallDisplay> viewer;
    if (display) {
      if (std::getenv("DISPLAY") == nullptr) {
        std::cerr << "table_ball_balancing: --display needs an X display (DISPLAY is not set); running headless\n";
      } else {
        viewer = std::make_unique<scenarios::TableBallDisplay>(cfg.table_side, cfg.ball_radius);
        hooks.on_frame = [&](const scenarios::TableBallFrameView& v) { viewer->show(v); };
      }
    }
    hooks.on_progress = [](double t, double total) {
      std::fprintf(stderr, "\r  simulated %5.1f / %.1f s", t, total);
      std::fflush(stderr);
    };
    const scenarios::TableBallResult r = scenarios::runTableBall(cfg, seed, hooks);
    std::fprintf(stderr, "\n");
    nlohmann::json j = scenarios::toJson(r);
    j["rig"] = cfg.rig ? nlohmann::json(cfg.rig->folder) : nlohmann::json(nullptr);
    if (!sets.empty()) j["config_set"] = sets;
    if (!summary_path.empty()) io::writeJsonFile(summary_path, j);
    std::printf("table_ball_balancing: %.1f s, seed %llu, %d frames (%d dropped), table found %d, ball found %d\n",
                r.duration, static_cast<unsigned long long>(r.seed), r.frames, r.frames_dropped, r.table_detections,
                r.ball_detections);
    if (cfg.rig) {
      std::printf("  camera: rig %s (renders with truth.yaml; the observer uses rig.yaml + ground.yaml)\n",
                  cfg.rig->folder.c_str());
    } else {
      std::printf("  camera: inline config keys (one perfect camera)\n");
    }
    std::printf("  observer RMSE %.2f mm (measurements %.2f mm); [M] tunings: sw=1,sv=0.005 %.2f mm, sw=sv=1 %.2f mm; "
                "stationary gain %.2f mm\n",
                r.observer_rmse_mm, r.measurement_rmse_mm, r.observer_rmse_mm_M_sw1_sv0005, r.observer_rmse_mm_M_sw1_sv1,
                r.observer_rmse_mm_stationary);
    std::printf("  10-step prediction RMSE %.2f mm, tilt RMSE %.3f deg, NIS mean %.2f\n", r.prediction_rmse_mm_10,
                r.tilt_rmse_deg, r.nis_mean);
    std::printf("  steps (worst): overshoot %.1f %%, settling %.2f s, steady-state error %.2f mm; push recovery %.2f s\n",
                r.overshoot_pct, r.settling_time_s, r.steady_state_error_mm, r.push_recovery_s);
    std::printf("  frame cost: observer %.3f ms, plain OpenCV reference %.3f ms, ratio %.3f\n", r.observer_frame_ms,
                r.reference_frame_ms, r.frame_time_ratio_to_reference);
    std::printf("  fast path (edge tracking) on %d of %d frames\n", r.tracked_frames, r.frames);
    std::printf("  frame CPU time (this thread): observer %.3f ms, reference %.3f ms, ratio %.3f\n",
                r.observer_frame_cpu_ms, r.reference_frame_cpu_ms, r.frame_cpu_ratio_to_reference);
    std::printf("  commands: max |tilt| %.2f deg, max rate %.1f deg/s, limits %s; wall %.1f s\n",
                r.max_commanded_angle_deg, r.max_commanded_rate_deg_s, r.limits_respected ? "respected" : "VIOLATED",
                r.wall_seconds);
    return 0;
  } catch (const core::Error& e) {
    std::cerr << "\ntable_ball_balancing: " << e.what() << "\n";
    return 1;
  }
}
