// viewline_node: one node of the ball-catching rig over DDS (modules/nodes: roles.h says what each
// role does). Thin main: the role, the scenario YAML (--set edits), the node's options.
//   viewline_node world   --config config/ball_catching.yaml --expect 4 --duration 2
//   viewline_node camera  --config config/ball_catching.yaml --camera 0
//   viewline_node tracker --config config/ball_catching.yaml --summary tracker.json
//   viewline_node robot   --config config/ball_catching.yaml
// The DDS domain's configuration comes from CYCLONEDDS_URI (tutorials/spread_rig_over_machines).

#include <CLI/CLI.hpp>
#include <cstdio>

#include "app_options.h"
#include "viewline/io/config_edit.h"
#include "viewline/nodes/roles.h"
#include "viewline/scenarios/ball_catching/config.h"

using namespace viewline;

int main(int argc, char** argv) {
  CLI::App cli{"One node of the ball-catching rig over DDS (Cyclone DDS): world, camera, tracker or robot"};
  std::string role;
  std::string config_path = "config/ball_catching.yaml";
  std::vector<std::string> sets;
  nodes::NodeOptions opt;
  cli.add_option("role", role, "world | camera | tracker | robot")->required()->check(
      CLI::IsMember({"world", "camera", "tracker", "robot"}));
  cli.add_option("--config", config_path, "scenario YAML (the ball-catching scenario's keys)")
      ->capture_default_str()
      ->check(CLI::ExistingFile);
  cli.add_option("--set", sets, "KEY=VALUE edits of the config (repeatable)");
  cli.add_option("--camera", opt.camera, "camera role: index of the camera in the config")->capture_default_str();
  cli.add_option("--seed", opt.seed, "seed of the throw, camera phases and pixel noise")->capture_default_str();
  cli.add_option("--domain", opt.domain, "DDS domain id (default: CYCLONEDDS_URI's)");
  cli.add_option("--realtime", opt.realtime, "simulated seconds per wall second")->capture_default_str()->check(
      CLI::PositiveNumber);
  cli.add_option("--tick", opt.tick_s, "world: simulated clock period, s")->capture_default_str()->check(CLI::PositiveNumber);
  cli.add_option("--duration", opt.duration_s, "world: simulated time to run per throw, s")->capture_default_str()->check(
      CLI::PositiveNumber);
  cli.add_option("--throws", opt.throws, "world: throws in the session (the in-process session's, one per --duration)")
      ->capture_default_str()->check(CLI::PositiveNumber);
  cli.add_option("--release", opt.release_s, "world: throw release time, s")->capture_default_str();
  cli.add_option("--expect", opt.expect, "world: nodes that must follow the clock before it starts")
      ->capture_default_str();
  cli.add_option("--pixel-sigma", opt.pixel_sigma, "camera: pixel noise std, px")->capture_default_str();
  cli.add_option("--clock-offset", opt.clock_offset_s, "camera: error of its clock, s")->capture_default_str();
  cli.add_flag("--render", opt.render, "camera: render the images and run the ball detector (default: generator)");
  cli.add_option("--deadline", opt.setpoint_deadline_s, "set-point deadline, s (robot halts past it)")
      ->capture_default_str()->check(CLI::PositiveNumber);
  cli.add_option("--max-wall", opt.max_wall_s, "end after this much wall time, s")->capture_default_str();
  cli.add_option("--summary", opt.summary_path, "write the node's JSON summary here");
  cli.add_option("--track-log", opt.track_log_path,
                 "tracker: CSV of every fused detection (update time, camera, stamp, delay, position, sigma)");
  if (const auto code = apps::parseCommandLine(cli, argc, argv)) return *code;
  return apps::runGuarded("viewline_node " + role, [&] {
    const auto cfg = scenarios::loadBallCatchingConfig(io::loadConfigWithValues(config_path, sets));
    nlohmann::json j;
    if (role == "world") j = nodes::runWorldNode(cfg, opt);
    else if (role == "camera") j = nodes::runCameraNode(cfg, opt);
    else if (role == "tracker") j = nodes::runTrackerNode(cfg, opt);
    else j = nodes::runRobotNode(cfg, opt);
    std::printf("%s\n", j.dump().c_str());
    return 0;
  });
}
