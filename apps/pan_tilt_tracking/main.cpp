// Pan-tilt tracking ([T]): a camera on a simulated FLIR PTU-D46 keeps a dark disc moving on a screen
// at the image centre; our predictive law and ViSP's baseline law on the same seed, [T]'s Table 1
// beside ours. Parses the command line and calls the scenario library
// (viewline/scenarios/pan_tilt/command.h), which runs, logs and prints.
//
//   pan_tilt_tracking --config config/pan_tilt_circle.yaml --set run.duration=60 --seed 1 --summary out.json
//   pan_tilt_tracking --config config/pan_tilt_circle.yaml --seed 1 --record rec; ... --replay rec
//   pan_tilt_tracking --config <variant>.yaml --seed 1 --replay <log>/predictive_frames.csv [--oracle-corners | --particles]
#include <CLI/CLI.hpp>
#include <filesystem>
#include <iostream>
#include <memory>
#include <string>

#include "app_options.h"
#include "viewline/scenarios/pan_tilt/command.h"
#include "viewline/viz/pan_tilt_display.h"

using namespace viewline;

int main(int argc, char** argv) {
  CLI::App cli{"viewline pan-tilt tracking ([T]): predictive servo vs ViSP's point servo on a simulated FLIR PTU-D46"};
  apps::CommonOptions opt;
  apps::addCommonOptions(cli, opt);
  scenarios::pan_tilt::CommandOptions run;
  std::string duration;
  bool no_baseline = false, oracle_corners = false, particles = false;
  cli.add_option("--duration", duration, "simulated seconds: shorthand for --set run.duration=S");
  cli.add_flag("--no-baseline", no_baseline, "ours only: shorthand for --set run.baseline=false");
  apps::addRecordOption(cli, opt);
  cli.add_option("--replay", run.replay,
                 "a folder written by --record: the loop on its frames (same config and --seed: the same run); "
                 "or filter only: re-run this config's target filter on the measurements of a --log run "
                 "(<log>/predictive_frames.csv, same --seed and run.duration) instead of simulating");
  cli.add_flag("--oracle-corners", oracle_corners,
               "with --replay (rectangle, random): a bound instead of the config's filter, constant-speed legs "
               "told the path's true corner times and speed");
  cli.add_flag("--particles", particles,
               "with --replay (random path): the reference instead of the config's filter, a particle filter of "
               "the path's generator (waypoints uniform in filter.region, one constant speed)");
  cli.add_option("--particle-count", run.particles, "particles of --particles")->check(CLI::Range(10, 10000000));
  if (const auto code = apps::parseCommandLine(cli, argc, argv)) return *code;
  if ((oracle_corners || particles) && run.replay.empty()) {
    std::cerr << (oracle_corners ? "--oracle-corners" : "--particles") << " needs --replay\n";
    return 2;
  }
  if (oracle_corners && particles) {
    std::cerr << "--oracle-corners and --particles are exclusive\n";
    return 2;
  }
  return apps::runGuarded("pan_tilt_tracking", [&] {
    run.config_path = opt.config_path;
    run.sets = opt.sets;
    if (!duration.empty()) run.shorthands.push_back("run.duration=" + duration);
    if (no_baseline) run.shorthands.push_back("run.baseline=false");
    run.seed = opt.seed;
    run.log_dir = opt.log_dir;
    run.summary_path = opt.summary_path;
    run.quiet = opt.quiet;
    run.record = opt.record_dir;
    run.estimator = oracle_corners ? scenarios::PanTiltReplayEstimator::OracleCorners
                    : particles    ? scenarios::PanTiltReplayEstimator::WaypointParticles
                                   : scenarios::PanTiltReplayEstimator::Filter;
    std::unique_ptr<viz::PanTiltDisplay> view;
    const bool filter_replay = !run.replay.empty() && !std::filesystem::is_directory(run.replay);
    if (!filter_replay && opt.wantDisplay("pan_tilt_tracking")) view = std::make_unique<viz::PanTiltDisplay>();
    run.pacing = view || opt.realtime >= 0.0 ? opt.pacing() : runtime::Pacing{};  // no window: no reason to wait
    const int status = scenarios::pan_tilt::runCommand(run, view.get());
    if (view) view->close();
    return status;
  });
}
