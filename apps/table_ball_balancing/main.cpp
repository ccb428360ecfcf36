// table_ball_balancing: [M]'s table-ball observer in the closed loop it was built for.
// Thin main: the common flags (apps/common), the YAML scenario, scenarios::runTableBall, the
// summary. --duration D is the common "simulated seconds" flag: the same as --set duration=D.

#include <cmath>
#include <cstdio>
#include <memory>

#include "app_options.h"
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
  apps::CommonOptions opt{"config/table_ball.yaml"};
  apps::addCommonOptions(cli, opt);
  std::string duration;
  cli.add_option("--duration", duration, "simulated seconds (the same as --set duration=S)")
      ->check(CLI::PositiveNumber);
  CLI11_PARSE(cli, argc, argv);
  return apps::runGuarded("table_ball_balancing", [&] {
    std::vector<std::string> sets = opt.sets;
    if (!duration.empty()) sets.push_back("duration=" + duration);
    const scenarios::TableBallConfig cfg = scenarios::tableBallConfigFromYaml(io::loadConfigWithValues(opt.config_path, sets));
    io::LogDirectory log(opt.log_dir);
    runtime::CsvSink csv(log);
    scenarios::TableBallHooks hooks;
    if (log.enabled()) hooks.telemetry = &csv;
    hooks.pacing = opt.pacing();
    std::unique_ptr<viz::TableBallDisplay> view;
    if (opt.wantDisplay("table_ball_balancing")) {
      view = std::make_unique<viz::TableBallDisplay>(cfg.table_side, cfg.ball_radius);
      hooks.on_frame = [&](const scenarios::TableBallFrameView& v) { return view->show(v); };
    }
    runtime::Progress progress =
        opt.quiet ? runtime::Progress::quiet() : runtime::Progress("simulated s", std::lround(cfg.duration));
    hooks.on_progress = [&](double t, double) { progress.update(static_cast<long>(t)); };
    const scenarios::TableBallResult r = scenarios::runTableBall(cfg, opt.seed, hooks);
    if (!r.stopped_early) progress.update(std::lround(cfg.duration));
    progress.finish();
    nlohmann::json j = scenarios::toJson(r);
    j["rig"] = cfg.rig ? nlohmann::json(cfg.rig->folder) : nlohmann::json(nullptr);
    if (!opt.sets.empty()) j["config_set"] = opt.sets;
    if (!opt.summary_path.empty()) io::writeJsonFile(opt.summary_path, j);
    scenarios::printTableBallSummary(stdout, r, cfg);
    if (view) view->waitForClose();
    return 0;
  });
}
