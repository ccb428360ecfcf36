// table_ball_balancing: [M]'s table-ball observer in the closed loop it was built for.
// Thin main: the common flags (apps/common), the YAML scenario, scenarios::runTableBall, the
// summary. --duration S is the common "simulated seconds" flag (as --set duration=S, which also
// works; the flag keeps the config file's relative paths as written in the summary). With footage
// (source: images, video or v4l2) one session over it instead (scenarios::runTableBallFootage).

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <memory>

#include "app_options.h"
#include "viewline/core/error.h"
#include "viewline/io/config_edit.h"
#include "viewline/io/files.h"
#include "viewline/io/log.h"
#include "viewline/runtime/progress.h"
#include "viewline/runtime/telemetry.h"
#include "viewline/scenarios/table_ball.h"
#include "viewline/viz/table_ball_display.h"

using namespace viewline;

int main(int argc, char** argv) {
  CLI::App cli{"Table-ball balancing: [M]'s observer (table PnP, ball on table, rolling-ball Kalman filter) "
               "and an LQR that tilts the table, on a rendered head-camera view"};
  apps::CommonOptions opt;
  opt.config_path = "config/table_ball.yaml";
  apps::addCommonOptions(cli, opt);
  apps::addRecordOption(cli, opt);
  apps::addReplayOption(cli, opt);
  double duration = 0.0;
  cli.add_option("--duration", duration, "simulated seconds (default: the config's duration)")->check(CLI::PositiveNumber);
  if (const auto code = apps::parseCommandLine(cli, argc, argv)) return *code;
  return apps::runGuarded("table_ball_balancing", [&] {
    const io::ConfigNode root = io::loadConfigWithValues(opt.config_path, opt.sets);
    scenarios::TableBallConfig cfg = scenarios::tableBallConfigFromYaml(root);
    if (duration > 0.0) cfg.duration = duration;  // > 0 checked by CLI11: the config stays valid
    io::LogDirectory log(opt.log_dir);
    runtime::CsvSink csv(log);
    scenarios::TableBallHooks hooks;
    if (log.enabled()) hooks.telemetry = &csv;
    if (cfg.onFootage()) {
      // One session over the head camera's footage (table_ball/footage.h): it ends with the
      // footage, is paced by its source, and is recorded already.
      if (cli.count("--duration") > 0) throw core::InvalidInput("--duration: footage runs until it ends (source.count limits it)");
      if (cli.count("--realtime") > 0) throw core::InvalidInput("--realtime: footage is paced by its source (source.pace: true)");
      if (!opt.record_dir.empty()) throw core::InvalidInput("--record: footage is recorded already");
      if (!opt.replay_dir.empty()) throw core::InvalidInput("--replay: the footage is the input (source:)");
      std::unique_ptr<viz::TableBallDisplay> view;
      if (opt.wantDisplay("table_ball_balancing")) {
        view = std::make_unique<viz::TableBallDisplay>(cfg.table_side, cfg.ball_radius);
        hooks.on_frame = [&](const scenarios::TableBallFrameView& v) { return view->show(v); };
      }
      const scenarios::TableBallFootageSummary s = scenarios::runTableBallFootage(cfg, opt.seed, hooks);
      nlohmann::json j = scenarios::toJson(s);
      j["rig"] = cfg.rig ? nlohmann::json(cfg.rig->folder) : nlohmann::json(nullptr);
      if (!opt.sets.empty()) j["config_set"] = opt.sets;
      if (!opt.summary_path.empty()) io::writeSummaryFile(opt.summary_path, j);
      scenarios::printTableBallFootageSummary(stdout, s, cfg);
      if (view) view->waitForClose();
      return 0;
    }
    hooks.pacing = opt.pacing();
    hooks.record_dir = opt.record_dir;
    hooks.replay_dir = opt.replay_dir;
    if (!opt.record_dir.empty()) {
      YAML::Emitter yaml;
      yaml << root.yaml();
      hooks.config_text = std::string(yaml.c_str()) + "\n";
    }
    std::unique_ptr<viz::TableBallDisplay> view;
    if (opt.wantDisplay("table_ball_balancing")) {
      view = std::make_unique<viz::TableBallDisplay>(cfg.table_side, cfg.ball_radius);
      hooks.on_frame = [&](const scenarios::TableBallFrameView& v) { return view->show(v); };
    }
    const long total = std::max(1L, std::lround(std::ceil(cfg.duration)));
    runtime::Progress progress = opt.quiet ? runtime::Progress::quiet() : runtime::Progress("simulated s", total);
    hooks.on_progress = [&](double t, double) { progress.update(static_cast<long>(t)); };
    const scenarios::TableBallResult r = scenarios::runTableBall(cfg, opt.seed, hooks);
    if (!r.stopped_early) progress.update(total);
    progress.finish();
    nlohmann::json j = scenarios::toJson(r);
    j["rig"] = cfg.rig ? nlohmann::json(cfg.rig->folder) : nlohmann::json(nullptr);
    if (!opt.sets.empty()) j["config_set"] = opt.sets;
    if (!opt.summary_path.empty()) io::writeSummaryFile(opt.summary_path, j);
    scenarios::printTableBallSummary(stdout, r, cfg);
    if (view) view->waitForClose();
    return 0;
  });
}
