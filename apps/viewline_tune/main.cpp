// viewline_tune: tuning sessions for the scenarios (issue 10). Thin main: parse the command line,
// call the tuning library (modules/tuning), print a short summary. See
// tutorials/tune_tracking_loop/README.md.
//
//   viewline_tune sweep    --sweep config/sweeps/dart_noise.yaml --out out/tune [--workers N] [--speedup]
//   viewline_tune run      --scenario dart --config config/dart_tracking.yaml --seed 1 --out out/run [--display]
//   viewline_tune autotune --scenario dart --config config/dart_tracking.yaml [--log DIR] --out out/autotune
//   viewline_tune list
#include <CLI/CLI.hpp>
#include <atomic>
#include <csignal>
#include <cstdio>
#include <iostream>

#include "viewline/core/error.h"
#include "viewline/io/config_edit.h"
#include "viewline/tuning/session.h"

using namespace viewline;

namespace {

std::atomic<bool> g_stop{false};  // set by SIGINT: no new runs are started (signal handlers need a global)

// First Ctrl-C: stop launching runs and write what is done; a second one ends the program.
extern "C" void onSigint(int) {
  g_stop.store(true);
  std::signal(SIGINT, SIG_DFL);
}

tuning::AdapterOptions parseOptions(const std::vector<std::string>& kv) {
  tuning::AdapterOptions o;
  for (const std::string& s : kv) {
    const auto eq = s.find('=');
    if (eq == std::string::npos || eq == 0) throw core::InvalidInput("--option '" + s + "': expected name=value");
    o[s.substr(0, eq)] = s.substr(eq + 1);
  }
  return o;
}

double get(const nlohmann::json& j, const char* k) {
  return j.contains(k) && j[k].is_number() ? j[k].get<double>() : std::nan("");
}

}  // namespace

int main(int argc, char** argv) {
  CLI::App app{"viewline_tune: parameter sweeps, NEES/NIS consistency, noise auto-tuning and HTML reports for the\n"
               "viewline scenarios (run in-process, in parallel). See tutorials/tune_tracking_loop/README.md."};
  app.require_subcommand(1);
  int workers = 0;
  bool quiet = false;

  auto* sweep = app.add_subcommand("sweep", "run a sweep file (and its autotune section), write the report");
  std::string sweep_file, out = "tune_out", config;
  int seeds = 0;
  bool speedup = false, no_autotune = false;
  sweep->add_option("--sweep", sweep_file, "sweep YAML (config/sweeps/*.yaml)")->required();
  sweep->add_option("--config", config, "scenario config (instead of the sweep file's 'config')");
  std::vector<std::string> sweep_set;
  sweep->add_option("--set", sweep_set, io::kSetOptionHelp)->take_all();
  sweep->add_option("--out", out, "output folder (report.html, summary.json, results.jsonl, best_config.yaml)");
  sweep->add_option("--workers", workers, "threads (0: all cores)");
  sweep->add_option("--seeds", seeds, "seeds per setting (instead of the file's)");
  sweep->add_flag("--speedup", speedup, "also run the sweep on one worker: parallel_speedup, same results");
  sweep->add_flag("--no-autotune", no_autotune, "skip the sweep file's autotune section");
  sweep->add_flag("--quiet", quiet, "no progress output");

  auto* run = app.add_subcommand("run", "one seeded run: metrics, NEES/NIS verdict, plots");
  tuning::SingleRunOptions ro;
  std::vector<std::string> run_opts;
  run->add_option("--scenario", ro.scenario, "scenario adapter (viewline_tune list)")->required();
  run->add_option("--config", ro.config, "scenario YAML")->required();
  run->add_option("--set", ro.set, io::kSetOptionHelp)->take_all();
  run->add_option("--seed", ro.seed, "seed");
  run->add_option("--out", ro.out_dir, "output folder");
  run->add_option("--log", ro.log_dir, "CSV logs of the run (measurements, estimates, innovations and S)");
  run->add_option("--option", run_opts, "adapter option name=value (viewline_tune list)");
  run->add_flag("--display", ro.display, "live curves (vpPlot) and the scenario's camera view, when an X display exists");
  run->add_flag("--headless", "no display (the default)");
  run->add_flag("--quiet", quiet, "no progress output");

  auto* at = app.add_subcommand("autotune", "estimate process and measurement noise from a log or a live run");
  tuning::AutotuneSessionOptions ao;
  std::vector<std::string> at_opts;
  at->add_option("--scenario", ao.scenario, "scenario adapter")->required();
  at->add_option("--config", ao.config, "scenario YAML")->required();
  at->add_option("--set", ao.set, io::kSetOptionHelp)->take_all();
  at->add_option("--log", ao.log_dir, "the scenario app's --log folder (default: record a live run)");
  at->add_option("--record-seed", ao.record_seed, "seed of the live recording");
  at->add_option("--record-runs", ao.record_runs, "live runs recorded");
  at->add_option("--start-scale", ao.start_scale, "start from the config's noise values times this");
  at->add_option("--outlier-prior", ao.outlier_prior, "prior outlier probability in the likelihood");
  at->add_option("--span-decades", ao.span_decades, "grid half-width in decades");
  at->add_option("--grid-points", ao.grid_points, "grid points per parameter");
  at->add_option("--verify-runs", ao.verify_runs, "live runs with the start and the tuned noise (NEES/NIS)");
  at->add_option("--out", ao.out_dir, "output folder");
  at->add_option("--option", at_opts, "adapter option name=value");
  at->add_option("--workers", workers, "threads (0: all cores)");
  at->add_flag("--quiet", quiet, "no progress output");

  auto* list = app.add_subcommand("list", "the scenarios of this build, their metrics and options");

  CLI11_PARSE(app, argc, argv);
  std::signal(SIGINT, onSigint);
  try {
    const tuning::AdapterRegistry registry = tuning::makeBuiltinAdapters();
    if (list->parsed()) {
      for (const std::string& n : registry.names()) {
        const auto& a = registry.get(n);
        std::printf("%s: %s\n  metrics:", n.c_str(), a.description().c_str());
        for (const auto& m : a.metricNames()) std::printf(" %s", m.c_str());
        std::printf("\n  options (sweep file 'adapter:' map or --option name=value):\n");
        for (const auto& o : a.options())
          std::printf("    %-24s default %-14s %s\n", o.name.c_str(), o.default_value.c_str(), o.doc.c_str());
      }
      return 0;
    }
    if (sweep->parsed()) {
      tuning::SessionOptions so;
      so.out_dir = out;
      so.config_override = config;
      so.set = sweep_set;
      so.workers = workers;
      so.seeds_override = seeds;
      so.measure_speedup = speedup;
      so.skip_autotune = no_autotune;
      so.stop = &g_stop;
      so.quiet = quiet;
      const nlohmann::json j = tuning::runSweepSession(registry, sweep_file, so);
      std::printf("viewline_tune sweep: %s, %zu/%zu runs%s, %.1f s on %d workers (load %s)\n",
                  j["scenario"].get<std::string>().c_str(), j["jobs_done"].get<std::size_t>(),
                  j["jobs_total"].get<std::size_t>(), j["interrupted"].get<bool>() ? " (INTERRUPTED)" : "",
                  get(j, "sweep_wall_s"), j["workers"].get<int>(), j["load_average_before"].get<std::string>().c_str());
      if (j.contains("best_label"))
        std::printf("  best: %s  %s = %.6g  (%s)\n  config: %s\n", j["best_label"].get<std::string>().c_str(),
                    j["metric"].get<std::string>().c_str(), get(j, "best_metric"),
                    j["best"]["verdict"].get<std::string>().c_str(), j["best_config"].get<std::string>().c_str());
      if (j.contains("parallel_speedup"))
        std::printf("  parallel_speedup %.3f (%d workers vs 1), same results: %s\n", get(j, "parallel_speedup"),
                    j["parallel_workers"].get<int>(), j["parallel_same_results"].get<bool>() ? "yes" : "NO");
      if (j.contains("autotune_nis_mean")) {
        std::printf("  autotune: NIS %.3f in [%.3f, %.3f] (before %.3f)", get(j, "autotune_nis_mean"),
                    j["autotune_nis_bounds"][0].get<double>(), j["autotune_nis_bounds"][1].get<double>(),
                    get(j, "autotune_nis_mean_before"));
        if (j.contains("autotune_metric_ratio_to_best_grid"))
          std::printf(", metric ratio to best grid %.3f", get(j, "autotune_metric_ratio_to_best_grid"));
        std::printf("\n  autotuned config: %s\n", j["autotuned_config"].get<std::string>().c_str());
      }
      std::printf("  report: %s (%zu plots)\n", j["report"].get<std::string>().c_str(), j["report_plots"].get<std::size_t>());
      return j["interrupted"].get<bool>() ? 130 : 0;
    }
    if (run->parsed()) {
      ro.adapter_options = parseOptions(run_opts);
      ro.quiet = quiet;
      const nlohmann::json j = tuning::runSingleSession(registry, ro);
      std::printf("viewline_tune run: %s seed %llu: verdict %s (NEES %s, NIS %s)\n", ro.scenario.c_str(),
                  static_cast<unsigned long long>(ro.seed), j["verdict"].get<std::string>().c_str(),
                  j["nees"]["verdict"].get<std::string>().c_str(), j["nis"]["verdict"].get<std::string>().c_str());
      for (const auto& [k, v] : j["metrics"].items())
        std::printf("  %-28s %s\n", k.c_str(), v.dump().c_str());
      std::printf("  report: %s\n", j["report"].get<std::string>().c_str());
      return 0;
    }
    if (at->parsed()) {
      ao.adapter_options = parseOptions(at_opts);
      ao.workers = workers;
      ao.quiet = quiet;
      const nlohmann::json j = tuning::runAutotuneSession(registry, ao);
      std::printf("viewline_tune autotune: %s\n", j["data"].get<std::string>().c_str());
      for (const auto& [k, v] : j["parameters"].items())
        std::printf("  %-12s %-10s start %-12.5g tuned %.5g %s\n", k.c_str(), v["symbol"].get<std::string>().c_str(),
                    v["start"].get<double>(), v["tuned"].get<double>(), v["unit"].get<std::string>().c_str());
      std::printf("  NIS before %.3f (%s), after %.3f in [%.3f, %.3f] (%s)\n", get(j, "autotune_nis_mean_before"),
                  j["autotune_nis_verdict_before"].get<std::string>().c_str(), get(j, "autotune_nis_mean"),
                  j["autotune_nis_bounds"][0].get<double>(), j["autotune_nis_bounds"][1].get<double>(),
                  j["autotune_nis_verdict"].get<std::string>().c_str());
      if (j.contains("autotune_nees_mean"))
        std::printf("  live NEES with the tuned noise %.3f in [%.3f, %.3f]: %s\n", get(j, "autotune_nees_mean"),
                    j["autotune_nees_bounds"][0].get<double>(), j["autotune_nees_bounds"][1].get<double>(),
                    j["autotune_nees_inside"].get<bool>() ? "inside" : "OUTSIDE");
      std::printf("  tuned config: %s\n  report: %s\n", j["autotuned_config"].get<std::string>().c_str(),
                  j["report"].get<std::string>().c_str());
      return 0;
    }
  } catch (const core::Error& e) {
    std::fprintf(stderr, "viewline_tune: error: %s\n", e.what());
    return 2;
  }
  return 0;
}
