// catch_table: the catch-rate comparison tables (catch rate against camera count, frame rate,
// pixel noise, robot limits and planner model), each cell a seeded session of the shipped
// scenario run through the same library loop as apps/ball_catching (scenarios::runBallCatching).
// Every variant changes ONE thing of the config (the app reaches each through --set: camera_count,
// rate_override_hz, noise_sigma_override, detector.pixel_noise_px, robot.v_max / a_max, planner.model); the reachability oracle is the scenario's (a robot
// knowing the true flight from the first frame showing the ball, with that variant's limits), so
// reachable_throws changes with the robot limits and the cameras (what they see first), never by
// a change of definition. Throw i of every cell uses the same seed: cells differ only in the variant.
//
//   build/bench/catch_table --config config/ball_catching.yaml --throws 150 --seed 1 --jobs 2
// Prints one markdown table per factor (the baseline row appears in each), progress on stderr;
// --only SUBSTRING runs the variants whose label contains it; --json FILE writes every cell's summary.
#include <CLI/CLI.hpp>
#include <cstdio>
#include <functional>
#include <iostream>
#include <map>
#include <optional>
#include <string>
#include <utility>
#include <vector>

#include "viewline/core/version.h"
#include "viewline/core/error.h"
#include "viewline/io/config.h"
#include "viewline/io/files.h"
#include "viewline/scenarios/ball_catching.h"

using namespace viewline;

namespace {

struct Variant {
  std::string table, label;
  std::function<void(scenarios::BallCatchingConfig&)> apply;
};

std::string row(const std::string& label, const scenarios::CatchSummary& s) {
  char buf[512];
  std::snprintf(buf, sizeof buf, "| %s | %d | %d | %d | **%.3f** | %.3f | %d / %d / %d / %d | %.1f / %.1f | %.3f |",
                label.c_str(), s.throws, s.reachable_throws, s.caught_reachable, s.catch_rate_reachable,
                s.catch_rate_all, s.miss_reasons.at("late"), s.miss_reasons.at("off_target"),
                s.miss_reasons.at("lost_track"), s.miss_reasons.at("not_reachable"), s.prediction_error_mm_median,
                s.prediction_error_mm_p95, s.decision_time_s_median);
  return buf;
}

}  // namespace

int main(int argc, char** argv) {
  CLI::App app{"Catch-rate tables: cameras, frame rate, pixel noise, robot limits, planner model"};
  app.set_version_flag("--version", std::string("viewline ") + viewline::core::kVersion);
  std::string config_path = "config/ball_catching.yaml", only, json_path;
  int throws = 150, jobs = 2;
  std::uint64_t seed = 1;
  app.add_option("--config", config_path, "scenario YAML (the baseline)")->check(CLI::ExistingFile);
  app.add_option("--throws", throws, "throws per cell")->check(CLI::PositiveNumber);
  app.add_option("--seed", seed, "seed of every cell (throw i: deriveSeed(seed, i))");
  app.add_option("--jobs", jobs, "worker threads")->check(CLI::PositiveNumber);
  app.add_option("--only", only, "run only the variants whose label contains this");
  app.add_option("--json", json_path, "write every cell's summary JSON here");
  CLI11_PARSE(app, argc, argv);
  try {
    scenarios::BallCatchingConfig base = scenarios::loadBallCatchingConfig(io::ConfigNode::loadFile(config_path));
    base.threads = jobs;
    const double v0 = base.robot.limits.v_max.x(), a0 = base.robot.limits.a_max.x();
    using Cfg = scenarios::BallCatchingConfig;
    std::vector<Variant> variants = {
        {"cameras", "1 camera (right)", [](Cfg& c) { c.camera_count = 1; }},
        {"cameras", "1 camera (behind)", [](Cfg& c) {
           std::swap(c.cameras[0], c.cameras[1]);
           c.camera_count = 1;
         }},
        {"cameras", "4 cameras (right, behind, left, high)", [](Cfg& c) { c.camera_count = 4; }},
        {"rate", "25 Hz", [](Cfg& c) { c.rate_override_hz = 25.0; }},
        {"rate", "100 Hz", [](Cfg& c) { c.rate_override_hz = 100.0; }},
        {"noise", "sensor noise 8 grey levels", [](Cfg& c) { for (auto& k : c.cameras) k.noise_sigma = 8.0; }},
        {"noise", "sensor noise 16 grey levels", [](Cfg& c) { for (auto& k : c.cameras) k.noise_sigma = 16.0; }},
        {"noise", "+0.5 px detection noise", [](Cfg& c) { c.pixel_noise_px = 0.5; }},
        {"noise", "+1 px detection noise", [](Cfg& c) { c.pixel_noise_px = 1.0; }},
        {"noise", "+2 px detection noise", [](Cfg& c) { c.pixel_noise_px = 2.0; }},
        {"limits", "0.5x: 0.25 m/s, 6.5 m/s²", [v0, a0](Cfg& c) {
           c.robot.limits.v_max.setConstant(0.5 * v0);
           c.robot.limits.a_max.setConstant(0.5 * a0);
         }},
        {"limits", "2x: 1 m/s, 26 m/s²", [v0, a0](Cfg& c) {
           c.robot.limits.v_max.setConstant(2.0 * v0);
           c.robot.limits.a_max.setConstant(2.0 * a0);
         }},
        {"model", "planner ballistic (no drag)", [](Cfg& c) { c.planner.model.kind = planning::FlightModel::Ballistic; }},
    };
    const std::map<std::string, std::string> titles = {
        {"cameras", "Camera count (first N of right, behind, left, high, or behind alone; 50 Hz)"},
        {"rate", "Frame rate (every camera)"},
        {"noise", "Pixel noise (sensor noise in grey levels; extra Gaussian noise on each detection, told to the tracker)"},
        {"limits", "Robot limits (as robot.limit_norm measures them; the oracle uses the same limits)"},
        {"model", "Planner crossing model (the ball has drag, k = 0.0103 /m)"}};
    char base_label[160];
    std::snprintf(base_label, sizeof base_label, "baseline: %zu cameras, 50 Hz, 2 grey levels, %.2g m/s & %.3g m/s², drag",
                  base.camera_count > 0 ? base.camera_count : base.cameras.size(), v0, a0);
    nlohmann::json all = nlohmann::json::array();
    auto run = [&](const std::string& label, const scenarios::BallCatchingConfig& cfg) {
      std::fprintf(stderr, "%s: ", label.c_str());
      scenarios::CatchHooks hooks;
      hooks.progress = [](int done, int total) {
        if (done == total || done % 25 == 0) std::fprintf(stderr, "%d/%d ", done, total);
      };
      const auto s = scenarios::runBallCatching(cfg, throws, seed, hooks);
      std::fprintf(stderr, "(%.0f s)\n%s\n", s.wall_s, row(label, s).c_str());  // each row as soon as it is done
      auto j = scenarios::summaryJson(s, cfg);
      j["variant"] = label;
      all.push_back(j);
      return s;
    };
    const bool want_base = only.empty() || std::string(base_label).find(only) != std::string::npos ||
                           std::string("baseline").find(only) != std::string::npos;
    std::vector<std::pair<const Variant*, scenarios::CatchSummary>> done;
    std::optional<scenarios::CatchSummary> base_summary;
    if (want_base) base_summary = run(base_label, base);
    for (const auto& v : variants) {
      if (!only.empty() && v.label.find(only) == std::string::npos && v.table.find(only) == std::string::npos) continue;
      scenarios::BallCatchingConfig cfg = base;
      v.apply(cfg);
      done.emplace_back(&v, run(v.label, cfg));
    }
    std::printf("%d throws per cell, seed %llu, config %s\n", throws, static_cast<unsigned long long>(seed),
                config_path.c_str());
    for (const auto& [key, title] : titles) {
      bool any = false;
      for (const auto& d : done) any = any || d.first->table == key;
      if (!any) continue;
      std::printf("\n%s\n\n| variant | throws | reachable | caught (reachable) | catch_rate_reachable | catch_rate_all |"
                  " misses late / off-target / lost / not reachable | prediction error at catch median / p95 mm |"
                  " decision time median s |\n|---|---|---|---|---|---|---|---|---|\n",
                  title.c_str());
      if (base_summary) std::printf("%s\n", row(base_label, *base_summary).c_str());
      for (const auto& d : done)
        if (d.first->table == key) std::printf("%s\n", row(d.first->label, d.second).c_str());
    }
    if (done.empty() && base_summary) std::printf("%s\n", row(base_label, *base_summary).c_str());
    if (!json_path.empty()) io::writeJsonFile(json_path, all);
    return 0;
  } catch (const core::Error& e) {
    std::cerr << "catch_table: " << e.what() << "\n";
    return 1;
  }
}
