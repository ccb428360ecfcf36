// catch_envelope: the ball catcher's catch rate over its operating envelope, each condition over
// several seeds (mean and spread of catch_rate_reachable across seeds). Conditions: extra detection
// noise per pixel axis (told to the tracker), the robot's positioning error during the camera
// registration (std per axis), and the camera count; every combination of the listed values.
// Seed s of every condition draws the same throws (deriveSeed(s, i)) and the same registration
// images; conditions differ only in what they change. Long: run it in the background.
//
//   build/bench/catch_envelope --config config/ball_catching.yaml --throws 500 --seeds 5 --jobs 2
//       --noise 0,0.25,0.5 --registration-error 0,0.0005 --cameras 2,4   (one command line)
// Prints one markdown row per condition as soon as it is done; --json FILE writes every run's summary.
#include <CLI/CLI.hpp>
#include <cmath>
#include <cstdio>
#include <iostream>
#include <string>
#include <vector>

#include "viewline/core/error.h"
#include "viewline/core/statistics.h"
#include "viewline/core/version.h"
#include "viewline/io/config.h"
#include "viewline/io/files.h"
#include "viewline/scenarios/ball_catching.h"

using namespace viewline;

int main(int argc, char** argv) {
  CLI::App app{"Catch rate over the envelope: detection noise x registration error x camera count, several seeds"};
  app.set_version_flag("--version", std::string("viewline ") + viewline::core::kVersion);
  std::string config_path = "config/ball_catching.yaml", json_path;
  int throws = 100, seeds = 5, jobs = 2;
  std::uint64_t first_seed = 1;
  std::vector<double> noise{0.0, 0.5}, reg_error{0.0, 0.0005};
  std::vector<unsigned> cameras{2, 4};
  app.add_option("--config", config_path, "scenario YAML")->check(CLI::ExistingFile);
  app.add_option("--throws", throws, "throws per seed and condition")->check(CLI::PositiveNumber);
  app.add_option("--seeds", seeds, "seeds per condition (first-seed, first-seed + 1, ...)")->check(CLI::PositiveNumber);
  app.add_option("--first-seed", first_seed, "first seed");
  app.add_option("--jobs", jobs, "worker threads")->check(CLI::PositiveNumber);
  app.add_option("--noise", noise, "extra detection noise per pixel axis, px (comma list)")->delimiter(',');
  app.add_option("--registration-error", reg_error, "robot positioning error during registration, m std per axis")
      ->delimiter(',');
  app.add_option("--cameras", cameras, "camera counts (comma list)")->delimiter(',');
  app.add_option("--json", json_path, "write every run's summary JSON here");
  CLI11_PARSE(app, argc, argv);
  try {
    scenarios::BallCatchingConfig base = scenarios::loadBallCatchingConfig(io::ConfigNode::loadFile(config_path));
    base.threads = jobs;
    nlohmann::json all = nlohmann::json::array();
    std::printf("%d throws per seed, seeds %llu-%llu, config %s, robot limits %s\n\n", throws,
                static_cast<unsigned long long>(first_seed), static_cast<unsigned long long>(first_seed + seeds - 1),
                config_path.c_str(), robots::toString(base.robot.limits.norm));
    std::printf("| detection noise px | registration error mm | cameras | reachable (all seeds) | catch_rate_reachable"
                " mean ± std over seeds | min - max | limit violations |\n|---|---|---|---|---|---|---|\n");
    std::fflush(stdout);
    for (unsigned nc : cameras)
      for (double re : reg_error)
        for (double px : noise) {
          scenarios::BallCatchingConfig cfg = base;
          cfg.camera_count = nc;
          cfg.pixel_noise_px = px;
          cfg.registration.robot_position_error_m = re;
          std::vector<double> rates;
          int reachable = 0;
          std::size_t violations = 0;
          for (int k = 0; k < seeds; ++k) {
            const std::uint64_t seed = first_seed + static_cast<std::uint64_t>(k);
            const auto s = scenarios::runBallCatching(cfg, throws, seed);
            std::fprintf(stderr, "noise %.2f px, registration %.1f mm, %u cameras, seed %llu: %.3f (%d of %d), %.0f s\n",
                         px, 1e3 * re, nc, static_cast<unsigned long long>(seed), s.catch_rate_reachable,
                         s.caught_reachable, s.reachable_throws, s.wall_s);
            if (std::isfinite(s.catch_rate_reachable)) rates.push_back(s.catch_rate_reachable);
            reachable += s.reachable_throws;
            violations += s.limit_violations;
            auto j = scenarios::summaryJson(s, cfg);
            j["registration_error_m"] = re;
            all.push_back(j);
          }
          double mean = 0.0, var = 0.0, lo = 1.0, hi = 0.0;
          for (double r : rates) mean += r / static_cast<double>(rates.size());
          for (double r : rates) {
            var += (r - mean) * (r - mean) / std::max<double>(1.0, static_cast<double>(rates.size()) - 1.0);
            lo = std::min(lo, r);
            hi = std::max(hi, r);
          }
          std::printf("| %.2f | %.1f | %u | %d | **%.3f** ± %.3f | %.3f - %.3f | %zu |\n", px, 1e3 * re, nc, reachable,
                      mean, std::sqrt(var), lo, hi, violations);
          std::fflush(stdout);
        }
    if (!json_path.empty()) io::writeJsonFile(json_path, all);
    return 0;
  } catch (const core::Error& e) {
    std::cerr << "catch_envelope: " << e.what() << "\n";
    return 1;
  }
}
