// pan_tilt_seeds: the seed tables of docs/results.md ("Pan-tilt tracking") in one
// command. For every seed, the closed loop of apps/pan_tilt_tracking (ours, then ViSP's law on the same
// seed: scenarios::runPanTiltComparison), then filter-only replays of its logged measurements
// (scenarios::replayPanTiltFilter): the config's filter, for its prediction error at the law's horizon
// and at the one the frames see,
// and (rectangle, random) the oracle bound told the path's true corner times and speed, and (random, with
// filter.region) the causal reference: the waypoint particle filter of the path's generator.
//
//   build/bench/pan_tilt_seeds --config config/pan_tilt_random.yaml --seeds 10 --jobs 2
//
// --set KEY=VALUE (repeatable) changes one config key for the study without a copy of the file, e.g.
// --set camera.fps=60 or --set measurement_noise_fraction=0.05 (the scenario loader still checks it).
//
// Prints two markdown tables (filtered RMSE; image error and predictions) and a summary against the
// scenario's targets; progress on stderr. --log-dir DIR keeps each seed's logs (DIR/log_<path>_s<seed>,
// replayable with pan_tilt_tracking --replay); --json FILE writes every seed's figures.
// A 60 s seed renders 2 x 1800 frames: about 1-2 CPU-minutes.
#include <CLI/CLI.hpp>
#include <unistd.h>

#include <algorithm>
#include <atomic>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <iostream>
#include <iomanip>
#include <mutex>
#include <sstream>
#include <string>
#include <vector>

#include "viewline/core/version.h"
#include "viewline/core/error.h"
#include "viewline/io/config.h"
#include "viewline/io/log.h"
#include "viewline/scenarios/pan_tilt_scenario.h"
#include "viewline/tuning/sweep_runner.h"
#include "viewline/io/config_edit.h"

using namespace viewline;
namespace fs = std::filesystem;

namespace {

struct SeedResult {
  std::uint64_t seed = 0;
  scenarios::PanTiltComparison run;
  scenarios::PanTiltReplayMetrics filter, oracle, reference;
  bool has_oracle = false, has_reference = false;
  std::string error;  ///< what stopped this seed (the worker threads must not throw)
};

/// x with `digits` decimals.
std::string num(double x, int digits) {
  std::ostringstream os;
  os << std::fixed << std::setprecision(digits) << x;
  return os.str();
}
/// "x / y" with 3 decimals.
std::string pair(double x, double y) { return num(x, 3) + " / " + num(y, 3); }

}  // namespace

int main(int argc, char** argv) {
  CLI::App app{"Pan-tilt seed tables: closed loop (ours and ViSP's law), the filter's prediction and the oracle bound."};
  app.set_version_flag("--version", std::string("viewline ") + viewline::core::kVersion);
  std::string config_file, log_dir, json_file;
  std::vector<std::string> sets;
  int seeds = 5, jobs = 2;
  std::uint64_t first_seed = 1;
  double duration = 0.0;
  std::size_t particles = 100000;
  app.add_option("--config", config_file, "pan-tilt scenario (config/pan_tilt_*.yaml)")->required();
  app.add_option("--seeds", seeds, "number of seeds")->check(CLI::PositiveNumber);
  app.add_option("--first-seed", first_seed, "first seed (then +1 each)");
  app.add_option("--jobs", jobs, "seeds run at once")->check(CLI::PositiveNumber);
  app.add_option("--duration", duration, "s per run (0: the config's run.duration)")->check(CLI::NonNegativeNumber);
  app.add_option("--log-dir", log_dir, "keep each seed's logs here (default: a temporary folder, removed)");
  app.add_option("--json", json_file, "write every seed's figures (JSON)");
  app.add_option("--particles", particles,
                 "random path with filter.region: particles of the reference replay (waypoint particle filter; 0: none)");
  app.add_option("--set", sets, io::kSetOptionHelp)
      ->take_all();
  CLI11_PARSE(app, argc, argv);

  try {
    scenarios::PanTiltScenarioConfig cfg =
        scenarios::loadPanTiltScenarioConfig(io::loadConfigWithValues(config_file, sets));
    if (duration > 0.0) cfg.duration = duration;
    cfg.run_baseline = true;
    cfg.validate();
    const std::string path = scenarios::pathShapeName(cfg.path.shape);
    const bool corners = cfg.path.shape != sim::PathShape::Circle;
    const bool reference = particles > 0 && cfg.path.shape == sim::PathShape::Random && cfg.path.corner_radius == 0.0 &&
                           cfg.control.filter.region_size.x() > 0.0;
    const bool keep = !log_dir.empty();
    const fs::path logs = keep ? fs::path(log_dir)
                               : fs::temp_directory_path() / ("viewline_pan_tilt_seeds_" + std::to_string(::getpid()));
    fs::create_directories(logs);

    std::vector<SeedResult> results(static_cast<std::size_t>(seeds));
    std::mutex out;
    std::size_t done = 0;
    std::atomic<bool> stop{false};
    tuning::parallelFor(results.size(), jobs, [&](std::size_t i) {
      SeedResult& r = results[i];
      r.seed = first_seed + i;
      try {
        const fs::path dir = logs / ("log_" + path + "_s" + std::to_string(r.seed));
        {
          io::LogDirectory log(dir.string());
          scenarios::pan_tilt::FrameCsvSink frames(log);  // what the replays read
          scenarios::PanTiltRunIo io;
          io.frames = &frames;
          r.run = scenarios::runPanTiltComparison(cfg, r.seed, io);
          log.flush();
        }
        const std::string frames = (dir / "predictive_frames.csv").string();
        r.filter = scenarios::replayPanTiltFilter(cfg, r.seed, frames, scenarios::PanTiltReplayEstimator::Filter);
        if (corners) {
          r.oracle = scenarios::replayPanTiltFilter(cfg, r.seed, frames, scenarios::PanTiltReplayEstimator::OracleCorners);
          r.has_oracle = true;
        }
        if (reference) {
          r.reference = scenarios::replayPanTiltFilter(cfg, r.seed, frames,
                                                       scenarios::PanTiltReplayEstimator::WaypointParticles, nullptr,
                                                       particles);
          r.has_reference = true;
        }
      } catch (const std::exception& e) {
        r.error = e.what();
        stop = true;
      }
      std::lock_guard<std::mutex> lock(out);
      std::cerr << "pan_tilt_seeds: seed " << r.seed << (r.error.empty() ? " done (" : " FAILED (") << ++done << "/"
                << results.size() << ")\n";
    }, &stop);
    if (!keep) fs::remove_all(logs);
    for (const SeedResult& r : results)
      if (!r.error.empty()) throw core::Error("seed " + std::to_string(r.seed) + ": " + r.error);
    if (stop) throw core::Error("stopped before every seed ran");

    const scenarios::TTable1Row t = scenarios::tTable1(cfg.path.shape);
    const bool ratio_target = cfg.path.shape != sim::PathShape::Rectangle;  // the ratio target: circle and random
    std::cout << "Pan-tilt " << path << ", " << cfg.duration << " s, seeds " << first_seed << "-"
              << first_seed + results.size() - 1 << " (" << config_file;
    for (const std::string& kv : sets) std::cout << ", --set " << kv;
    std::cout << ")\n\n";
    std::cout << "Filtered RMSE (cm, x / y)" << (t.available ? "; target <= 1/2 [T]: " + pair(0.5 * t.kalman.x(), 0.5 * t.kalman.y()) : std::string())
              << "\n\n| seed | measured | filtered (ours) | oracle (true corners) | met |\n|---|---|---|---|---|\n";
    std::size_t rmse_met = 0, ratio_met = 0, oracle_over = 0, reference_over = 0;
    double ratio_lo = 1e9, ratio_hi = 0.0, ratio_sum = 0.0, max_rate = 0.0, reacq = 0.0;
    std::size_t unsafe = 0;
    std::size_t occluded = 0, lost = 0;  // runs long enough to contain the occlusion; not reacquired
    for (const SeedResult& r : results) {
      const auto& o = r.run.ours;
      const bool met = t.available && o.rmse_filtered_cm.x() <= 0.5 * t.kalman.x() && o.rmse_filtered_cm.y() <= 0.5 * t.kalman.y();
      rmse_met += met ? 1 : 0;
      std::cout << "| " << r.seed << " | " << pair(o.rmse_measured_cm.x(), o.rmse_measured_cm.y()) << " | **"
                << pair(o.rmse_filtered_cm.x(), o.rmse_filtered_cm.y()) << "** | "
                << (r.has_oracle ? pair(r.oracle.rmse_filtered_cm.x(), r.oracle.rmse_filtered_cm.y()) : "–")
                << " | " << (t.available ? (met ? "yes" : "no") : "–") << " |\n";
    }
    std::cout << "\nImage error (px) and the prediction error at the law's " << num(1e3 * results.front().filter.horizon_s, 1)
              << " ms horizon and at the " << num(1e3 * results.front().filter.frame_horizon_s, 1)
              << " ms that the frames see (the first frame a command moves)"
              << (ratio_target ? "; target: ours <= 1/3 of ViSP's law" : "")
              << "\n\n| seed | ours | ViSP law | ratio | 1/3 baseline | ours, worst | baseline, worst | filter's prediction | oracle's prediction "
                 "| filter, frames' horizon | oracle, frames' horizon | reference, frames' horizon |\n"
                 "|---|---|---|---|---|---|---|---|---|---|---|---|\n";
    for (const SeedResult& r : results) {
      const auto& o = r.run.ours;
      const auto& b = r.run.baseline;
      const double ratio = o.image_error_rms_px / b.image_error_rms_px, third = b.image_error_rms_px / 3.0;
      ratio_lo = std::min(ratio_lo, ratio);
      ratio_hi = std::max(ratio_hi, ratio);
      ratio_sum += ratio;
      ratio_met += ratio <= 1.0 / 3.0 ? 1 : 0;
      if (r.has_oracle && r.oracle.frame_predicted_error_px > third) ++oracle_over;
      if (r.has_reference && r.reference.frame_predicted_error_px > third) ++reference_over;
      for (const auto* m : {&o, &b}) {
        unsafe += m->unsafe_commands + m->rate_violations + m->limit_hits;
        max_rate = std::max(max_rate, m->max_rate_fraction);
      }
      if (o.occlusion) {
        ++occluded;
        if (o.reacquired) reacq = std::max(reacq, o.reacquisition_delay_s);
        else ++lost;
      }
      char buf[512];
      std::snprintf(buf, sizeof buf, "| %llu | %.2f | %.2f | **%.3f** | %.2f | %.1f | %.1f | %.2f | %s | %.2f | %s | %s |\n",
                    static_cast<unsigned long long>(r.seed), o.image_error_rms_px, b.image_error_rms_px, ratio, third,
                    o.image_error_max_px, b.image_error_max_px, r.filter.predicted_error_px,
                    r.has_oracle ? num(r.oracle.predicted_error_px, 2).c_str() : "–", r.filter.frame_predicted_error_px,
                    r.has_oracle ? num(r.oracle.frame_predicted_error_px, 2).c_str() : "–",
                    r.has_reference ? num(r.reference.frame_predicted_error_px, 2).c_str() : "–");
      std::cout << buf;
    }
    const double n = static_cast<double>(results.size());
    std::cout << "\nSummary: image-error ratio " << num(ratio_lo, 3) << "-" << num(ratio_hi, 3) << " (mean " << num(ratio_sum / n, 3) << ")";
    if (ratio_target) std::cout << ", <= 1/3 on " << ratio_met << " of " << results.size() << " seeds";
    if (t.available) std::cout << "; filtered RMSE <= 1/2 [T] on " << rmse_met << " of " << results.size() << " seeds";
    if (corners) std::cout << "; the oracle's prediction at the frames' horizon alone is above 1/3 of the baseline on " << oracle_over << " seeds";
    if (reference)
      std::cout << "; the reference's (" << particles << " particles) on " << reference_over << " seeds";
    std::cout << ".\nLimits (both controllers): " << unsafe << " unsafe commands, rate violations and hard-stop hits; largest commanded rate "
              << num(100.0 * max_rate, 0) << " % of the maximum";
    if (occluded > 0) {
      std::cout << "; reacquired <= " << num(reacq, 3) << " s after the occlusion";
      if (lost > 0) std::cout << " (NOT reacquired on " << lost << " of " << occluded << " seeds)";
    }
    std::cout << ".\n";

    if (!json_file.empty()) {
      nlohmann::json j = nlohmann::json::array();
      for (const SeedResult& r : results) {
        nlohmann::json s = r.run.toJson(cfg);
        s["seed"] = r.seed;
        s["filter_replay"] = r.filter.toJson();
        if (r.has_oracle) s["oracle_replay"] = r.oracle.toJson();
        if (r.has_reference) s["reference_replay"] = r.reference.toJson();
        j.push_back(s);
      }
      std::ofstream f(json_file);
      if (!f) throw core::InvalidInput("--json: cannot write " + json_file);
      f << j.dump(2) << "\n";
    }
    return unsafe == 0 && lost == 0 ? 0 : 2;  // the limits and the reacquisition are asserted, not just printed
  } catch (const std::exception& e) {
    std::cerr << "pan_tilt_seeds: error: " << e.what() << "\n";
    return 1;
  }
}
