// ball_catching: [L]'s ball catcher. Thin main: the common flags, the YAML scenario (every
// setting is a config key: --set camera_count=1, --set rate_override_hz=100,
// --set noise_sigma_override=8, --set robot.v_max=1, --set robot.a_max=26, --set planner.model=ballistic,
// --set robot.kind=arm, --set threads=4), --record DIR / --replay DIR (ball_catching/recording.h),
// scenarios::runBallCatching, the summary; with footage per camera (cameras[].source) one session
// over it instead (scenarios::runCatchFootage, ball_catching/footage.h). The loop is documented in
// modules/scenarios/include/viewline/scenarios/ball_catching/loop.h.

#include <CLI/CLI.hpp>
#include <cstdio>
#include <memory>

#include "app_options.h"
#include "viewline/core/error.h"
#include "viewline/io/config_edit.h"
#include "viewline/io/files.h"
#include "viewline/io/log.h"
#include "viewline/runtime/progress.h"
#include "viewline/scenarios/ball_catching.h"
#include "viewline/scenarios/ball_catching/recording.h"
#include "viewline/viz/ball_catching_display.h"

using namespace viewline;

int main(int argc, char** argv) {
  CLI::App cli{"Ball catching: rendered unsynchronised cameras, colour-blob detector, multi-view viewline "
               "tracker, drag-aware interception planner and a robot with [L]'s limits"};
  apps::CommonOptions opt;
  opt.config_path = "config/ball_catching.yaml";
  int throws = 20;
  apps::addCommonOptions(cli, opt);
  apps::addRecordOption(cli, opt);
  apps::addReplayOption(cli, opt);
  cli.add_option("--throws", throws,
                 "number of throws (throw i uses deriveSeed(seed, i)); with --replay: default the recording's")
      ->check(CLI::PositiveNumber);
  if (const auto code = apps::parseCommandLine(cli, argc, argv)) return *code;
  return apps::runGuarded("ball_catching", [&] {
    const io::ConfigNode root = io::loadConfigWithValues(opt.config_path, opt.sets);
    const auto cfg = scenarios::loadBallCatchingConfig(root);
    scenarios::CatchHooks hooks;
    hooks.pacing = opt.pacing();
    hooks.record_dir = opt.record_dir;
    hooks.replay_dir = opt.replay_dir;
    if (!opt.record_dir.empty()) {
      YAML::Emitter yaml;
      yaml << root.yaml();
      hooks.config_text = std::string(yaml.c_str()) + "\n";
    }
    if (cfg.onFootage()) {
      // One session over the cameras' footage: no throws to count, nothing to record or replay.
      if (cli.count("--throws") > 0) throw core::InvalidInput("--throws: footage runs as one session");
      if (cli.count("--realtime") > 0)
        throw core::InvalidInput("--realtime: footage is paced by its source (cameras[].source.pace: true)");
    } else {
      // A replay runs the recording's throws unless --throws asks for fewer.
      const std::string replay = scenarios::catchReplayRoot(cfg, &hooks);
      if (!replay.empty() && cli.count("--throws") == 0) throws = scenarios::recordedCatchThrows(replay);
    }
    // --log DIR: the runtime's CSV files (with throws, one folder per throw, throw_007/, and throws.csv on top).
    io::LogDirectory log(opt.log_dir);
    if (log.enabled()) hooks.telemetry = scenarios::csvTelemetry(opt.log_dir);
    std::unique_ptr<viz::BallCatchingDisplay> view;
    if (opt.wantDisplay("ball_catching")) {
      view = std::make_unique<viz::BallCatchingDisplay>(cfg);
      hooks.on_frame = [&](const scenarios::CatchFrame& f) { return view->show(f); };
    }
    nlohmann::json j;
    std::string text;
    if (cfg.onFootage()) {
      const auto s = scenarios::runCatchFootage(cfg, opt.seed, hooks);
      log.flush();
      j = scenarios::footageSummaryJson(s, cfg);
      text = scenarios::footageSummaryText(s, cfg);
    } else {
      runtime::Progress progress = opt.quiet ? runtime::Progress::quiet() : runtime::Progress("throws", throws);
      hooks.progress = [&](int done, int) { progress.update(done); };
      const auto s = scenarios::runBallCatching(cfg, throws, opt.seed, hooks);
      progress.finish();
      scenarios::writeThrowsCsv(log, s.results);
      log.flush();
      j = scenarios::summaryJson(s, cfg);
      text = scenarios::summaryText(s, cfg);
    }
    if (!opt.sets.empty()) j["config_set"] = opt.sets;
    if (!opt.summary_path.empty()) io::writeSummaryFile(opt.summary_path, j);
    std::fputs(text.c_str(), stdout);
    if (view) view->waitForClose();
    return 0;
  });
}
