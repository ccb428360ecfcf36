// ball_catching: [L]'s ball catcher (issue 5). Thin main: parse the CLI, load the YAML scenario,
// run scenarios::runBallCatching, print and write the summary. The loop is documented in
// modules/scenarios/include/viewline/scenarios/ball_catching.h.

#include <CLI/CLI.hpp>
#include <cstdio>
#include <cstdlib>
#include <iostream>
#include <memory>

#include "viewline/core/error.h"
#include "viewline/io/config_edit.h"
#include "viewline/io/files.h"
#include "viewline/io/log.h"
#include "viewline/scenarios/ball_catching.h"
#include "viewline/scenarios/ball_catching_display.h"

using namespace viewline;

int main(int argc, char** argv) {
  CLI::App app{"Ball catching: rendered unsynchronised cameras, colour-blob detector, multi-view viewline "
               "tracker, drag-aware interception planner and a robot with [L]'s limits"};
  std::string config_path = "config/ball_catching.yaml", summary_path, log_dir, model;
  std::uint64_t seed = 1;
  int throws = 20, jobs = 0;
  unsigned cameras = 0;
  double rate = 0.0, noise = -1.0, vmax = 0.0, amax = 0.0;
  bool headless = false, display = false;
  std::string robot_kind;
  std::vector<std::string> sets;
  app.add_option("--config", config_path, "scenario YAML")->check(CLI::ExistingFile);
  app.add_option("--set", sets, io::kSetOptionHelp)->take_all();
  app.add_option("--seed", seed, "random seed (throw i uses deriveSeed(seed, i))");
  app.add_option("--throws", throws, "number of throws")->check(CLI::PositiveNumber);
  app.add_option("--jobs", jobs, "worker threads (default: the config's threads)");
  app.add_flag("--headless", headless, "no display (never needs X)");
  app.add_flag("--display", display, "show the camera images with detections and the predicted crossing (vpDisplayX)");
  app.add_option("--log", log_dir, "CSV logs (throws, truth, measurements, estimates, plan) in this directory");
  app.add_option("--summary", summary_path, "write the metrics as JSON");
  // Overrides for the comparison tables (the config stays the reference).
  app.add_option("--cameras", cameras, "use the first N cameras of the config");
  app.add_option("--rate", rate, "every camera at this frame rate, Hz");
  app.add_option("--pixel-noise", noise, "sensor noise of every camera, grey levels");
  app.add_option("--v-max", vmax, "robot speed limit per axis, m/s");
  app.add_option("--a-max", amax, "robot acceleration limit per axis, m/s²");
  app.add_option("--planner-model", model, "drag | ballistic");
  app.add_option("--robot", robot_kind, "stage | arm");
  CLI11_PARSE(app, argc, argv);
  if (headless && display) {
    std::cerr << "ball_catching: --headless and --display exclude each other\n";
    return 2;
  }
  try {
    scenarios::BallCatchingConfig cfg = scenarios::loadBallCatchingConfig(io::loadConfigWithValues(config_path, sets));
    if (jobs > 0) cfg.threads = jobs;
    if (cameras > 0) cfg.camera_count = cameras;
    if (rate > 0.0) cfg.rate_override_hz = rate;
    if (noise >= 0.0)
      for (auto& c : cfg.cameras) c.noise_sigma = noise;
    if (vmax > 0.0) cfg.robot.limits.v_max.setConstant(vmax);
    if (amax > 0.0) cfg.robot.limits.a_max.setConstant(amax);
    if (!model.empty()) {
      if (model != "drag" && model != "ballistic") throw core::InvalidInput("--planner-model: expected drag or ballistic");
      cfg.planner.model.kind = model == "drag" ? planning::FlightModel::Drag : planning::FlightModel::Ballistic;
    }
    if (!robot_kind.empty()) {
      if (robot_kind != "stage" && robot_kind != "arm") throw core::InvalidInput("--robot: expected stage or arm");
      cfg.robot.kind = robot_kind == "arm" ? robots::CartesianBackEnd::Arm : robots::CartesianBackEnd::Stage;
    }
    cfg.finalize();
    cfg.validate();

    io::LogDirectory log(log_dir);
    scenarios::CatchHooks hooks;
    if (!log_dir.empty()) hooks.log = &log;
    std::unique_ptr<scenarios::BallCatchingDisplay> viewer;
    if (display) {
      if (std::getenv("DISPLAY") == nullptr) {
        std::cerr << "ball_catching: --display needs an X display (DISPLAY is not set); running headless\n";
      } else {
        viewer = std::make_unique<scenarios::BallCatchingDisplay>(cfg);
        hooks.on_frame = [&](const scenarios::CatchFrame& f) { viewer->show(f); };
      }
    }
    hooks.progress = [](int done, int total) {
      std::fprintf(stderr, "\r  throws %d / %d", done, total);
      std::fflush(stderr);
    };
    const auto s = scenarios::runBallCatching(cfg, throws, seed, hooks);
    std::fprintf(stderr, "\n");
    nlohmann::json j = scenarios::summaryJson(s, cfg);
    if (!sets.empty()) j["config_set"] = sets;
    if (!summary_path.empty()) io::writeJsonFile(summary_path, j);
    std::printf("ball_catching: %d throws, seed %llu, %zu cameras, %s robot (%.2f m/s, %.1f m/s²), planner %s, %.1f s wall\n",
                s.throws, static_cast<unsigned long long>(seed), cfg.camera_count > 0 ? cfg.camera_count : cfg.cameras.size(),
                robots::toString(cfg.robot.kind), cfg.robot.limits.v_max.x(), cfg.robot.limits.a_max.x(),
                planning::toString(cfg.planner.model.kind), s.wall_s);
    std::printf("  caught %d: catch rate %.3f of all, %.3f of the %d reachable throws\n", s.caught, s.catch_rate_all,
                s.catch_rate_reachable, s.reachable_throws);
    std::printf("  misses: late %d, off target %d, lost track %d, not reachable %d\n", s.miss_reasons.at("late"),
                s.miss_reasons.at("off_target"), s.miss_reasons.at("lost_track"), s.miss_reasons.at("not_reachable"));
    std::printf("  prediction error at the crossing: median %.1f mm, p95 %.1f mm; decision time median %.3f s, p95 %.3f s\n",
                s.prediction_error_mm_median, s.prediction_error_mm_p95, s.decision_time_s_median, s.decision_time_s_p95);
    std::printf("  %d frames, detection rate %.3f, %.2f ms per frame (render + detect + track + plan); "
                "robot limit violations %zu\n",
                s.frames, s.detection_rate, s.ms_per_frame, s.limit_violations);
    return 0;
  } catch (const core::Error& e) {
    std::cerr << "\nball_catching: " << e.what() << "\n";
    return 1;
  }
}
