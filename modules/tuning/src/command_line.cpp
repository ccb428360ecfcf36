#include "viewline/tuning/command_line.h"

#include <cmath>
#include <cstdio>
#include <cstdlib>

#include "viewline/core/error.h"
#include "viewline/io/config_edit.h"

namespace viewline::tuning {

namespace {

double get(const nlohmann::json& j, const char* k) {
  return j.contains(k) && j[k].is_number() ? j[k].get<double>() : std::nan("");
}

/// Element i of a JSON array of numbers (NaN for null: an empty band).
double element(const nlohmann::json& a, std::size_t i) {
  return a.is_array() && i < a.size() && a[i].is_number() ? a[i].get<double>() : std::nan("");
}

}  // namespace

AdapterOptions parseAdapterOptions(const std::vector<std::string>& items) {
  AdapterOptions o;
  for (const std::string& s : items) {
    const auto eq = s.find('=');
    if (eq == std::string::npos || eq == 0) throw core::InvalidInput("--option '" + s + "': expected name=value");
    o[s.substr(0, eq)] = s.substr(eq + 1);
  }
  return o;
}

TuneCommandLine::TuneCommandLine(CLI::App& app) {
  app.require_subcommand(1);

  sweep_ = app.add_subcommand("sweep", "run a sweep file (and its autotune section), write the report");
  SessionOptions& so = sweep_options_;
  sweep_->add_option("--sweep", sweep_file_, "sweep YAML (config/sweeps/*.yaml)")->required();
  sweep_->add_option("--config", so.config_override, "scenario config (instead of the sweep file's 'config')");
  sweep_->add_option("--set", so.set, io::kSetOptionHelp)->take_all();
  sweep_->add_option("--out", so.out_dir, "output folder (report.html, summary.json, results.jsonl, best_config.yaml)");
  sweep_->add_option("--workers", workers_, "threads (0: all cores)");
  sweep_->add_option("--seeds", so.seeds_override, "seeds per setting (instead of the file's)");
  sweep_->add_flag("--speedup", so.measure_speedup, "also run the sweep on one worker: parallel_speedup, same results");
  sweep_->add_flag("--no-autotune", so.skip_autotune, "skip the sweep file's autotune section");
  sweep_->add_flag("--quiet", quiet_, "no progress output");

  run_ = app.add_subcommand("run", "one seeded run: metrics, NEES/NIS verdict, plots");
  SingleRunOptions& ro = run_options_;
  ro.out_dir = "tune_run";
  run_->add_option("--scenario", ro.scenario, "scenario adapter (viewline_tune list)")->required();
  run_->add_option("--config", ro.config, "scenario YAML")->required();
  run_->add_option("--set", ro.set, io::kSetOptionHelp)->take_all();
  run_->add_option("--seed", ro.seed, "seed");
  run_->add_option("--out", ro.out_dir, "output folder");
  run_->add_option("--log", ro.log_dir, "CSV logs of the run (measurements, estimates, innovations and S)");
  run_->add_option("--option", run_adapter_options_, "adapter option name=value (viewline_tune list)");
  auto* display = run_->add_flag("--display", ro.display,
                                 "live curves (vpPlot) and the scenario's camera view, when an X display exists");
  run_->add_flag("--headless", "no display (the default)")->excludes(display);
  run_->add_flag("--quiet", quiet_, "no progress output");

  autotune_ = app.add_subcommand("autotune", "estimate process and measurement noise from a log or a live run");
  AutotuneSessionOptions& ao = autotune_options_;
  autotune_->add_option("--scenario", ao.scenario, "scenario adapter")->required();
  autotune_->add_option("--config", ao.config, "scenario YAML")->required();
  autotune_->add_option("--set", ao.set, io::kSetOptionHelp)->take_all();
  autotune_->add_option("--log", ao.log_dir, "the scenario app's --log folder (default: record a live run)");
  autotune_->add_option("--recording", ao.recording,
                        "a recording of the scenario's frames (its app's --record folder; pan_tilt, table_ball, "
                        "ball_catching, dart, mobile_capture) to fit on; no truth needed");
  autotune_->add_option("--record-seed", ao.record_seed, "seed of the live recording");
  autotune_->add_option("--record-runs", ao.record_runs, "live runs recorded");
  autotune_->add_option("--start-scale", ao.start_scale, "start from the config's noise values times this");
  autotune_->add_option("--start-value", start_values_,
                        "key=value: start this noise parameter (config key) here, e.g. one the config sets to 0");
  autotune_->add_option("--outlier-prior", ao.outlier_prior, "prior outlier probability in the likelihood");
  autotune_->add_option("--span-decades", ao.span_decades, "grid half-width in decades");
  autotune_->add_option("--grid-points", ao.grid_points, "grid points per parameter");
  autotune_->add_option("--verify-runs", ao.verify_runs,
                        "live runs with the start and the tuned noise from the verify seed (NEES/NIS)");
  autotune_->add_option("--verify-seed", ao.verify_seed,
                        "seed of the fresh-seed NIS check and the live runs (default: record seed + 1)");
  autotune_->add_option("--out", ao.out_dir, "output folder");
  autotune_->add_option("--option", autotune_adapter_options_, "adapter option name=value");
  autotune_->add_option("--workers", workers_, "threads (0: all cores)");
  autotune_->add_flag("--quiet", quiet_, "no progress output");

  check_ = app.add_subcommand("check", "NIS/NEES of a config's filter on seeded runs: means, 99 % bands, verdicts");
  CheckOptions& co = check_options_;
  check_->add_option("--scenario", co.scenario, "scenario adapter (viewline_tune list)")->required();
  check_->add_option("--config", co.config, "scenario YAML")->required();
  check_->add_option("--set", co.set, io::kSetOptionHelp)->take_all();
  check_->add_option("--seeds", co.seeds, "seeded runs pooled");
  check_->add_option("--seed", co.seed, "base seed (run i: deriveSeed(seed, i)); pick one the noise was not tuned on");
  check_->add_option("--recording", co.recording,
                     "a recording of the scenario's frames (--record folder): NIS of the config's filter on it, not seeded runs");
  check_->add_option("--out", co.out_dir, "folder for summary.json (default: none)");
  check_->add_option("--option", check_adapter_options_, "adapter option name=value");
  check_->add_option("--workers", workers_, "threads (0: all cores)");
  check_->add_flag("--quiet", quiet_, "no progress output");

  list_ = app.add_subcommand("list", "the scenarios of this build, their metrics and options");
}

int TuneCommandLine::run(const AdapterRegistry& registry, const std::atomic<bool>* stop,
                         const LiveViewFactory& live_view) {
  if (list_->parsed()) {
    list(registry);
    return 0;
  }
  if (sweep_->parsed()) return runSweep(registry, stop);
  if (run_->parsed()) return runSingle(registry, live_view);
  if (autotune_->parsed()) return runAutotune(registry);
  if (check_->parsed()) return runCheck(registry);
  return 0;
}

void TuneCommandLine::list(const AdapterRegistry& registry) {
  for (const std::string& n : registry.names()) {
    const auto& a = registry.get(n);
    std::printf("%s: %s\n  metrics:", n.c_str(), a.description().c_str());
    for (const auto& m : a.metricNames()) std::printf(" %s", m.c_str());
    std::printf("\n  options (sweep file 'adapter:' map or --option name=value):\n");
    for (const auto& o : a.options())
      std::printf("    %-24s default %-14s %s (%s)\n", o.name.c_str(), o.default_value.c_str(), o.doc.c_str(),
                  o.expected().c_str());
  }
}

int TuneCommandLine::runSweep(const AdapterRegistry& registry, const std::atomic<bool>* stop) {
  SessionOptions so = sweep_options_;
  so.workers = workers_;
  so.stop = stop;
  so.quiet = quiet_;
  const nlohmann::json j = runSweepSession(registry, sweep_file_, so);
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

int TuneCommandLine::runSingle(const AdapterRegistry& registry, const LiveViewFactory& live_view) {
  SingleRunOptions ro = run_options_;
  ro.adapter_options = parseAdapterOptions(run_adapter_options_);
  ro.quiet = quiet_;
  ro.live_view = live_view;
  const nlohmann::json j = runSingleSession(registry, ro);
  std::printf("viewline_tune run: %s seed %llu: verdict %s (NEES %s, NIS %s)\n", ro.scenario.c_str(),
              static_cast<unsigned long long>(ro.seed), j["verdict"].get<std::string>().c_str(),
              j["nees"]["verdict"].get<std::string>().c_str(), j["nis"]["verdict"].get<std::string>().c_str());
  for (const auto& [k, v] : j["metrics"].items()) std::printf("  %-28s %s\n", k.c_str(), v.dump().c_str());
  std::printf("  report: %s\n", j["report"].get<std::string>().c_str());
  return 0;
}

int TuneCommandLine::runAutotune(const AdapterRegistry& registry) {
  AutotuneSessionOptions ao = autotune_options_;
  ao.adapter_options = parseAdapterOptions(autotune_adapter_options_);
  for (const auto& [k, v] : parseAdapterOptions(start_values_)) {
    char* end = nullptr;
    const double x = std::strtod(v.c_str(), &end);
    if (end == v.c_str() || *end != '\0') throw core::InvalidInput("--start-value " + k + "=" + v + ": expected a number");
    ao.start_values[k] = x;
  }
  ao.workers = workers_;
  ao.quiet = quiet_;
  const nlohmann::json j = runAutotuneSession(registry, ao);
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
  if (j.contains("autotune_verify_seed"))
    std::printf("  fresh seed %llu (%s): NIS %.3f in [%.3f, %.3f] (%s)\n",
                static_cast<unsigned long long>(j["autotune_verify_seed"].get<std::uint64_t>()),
                j["autotune_verify_data"].get<std::string>().c_str(), get(j, "autotune_verify_nis_mean"),
                element(j["autotune_verify_nis_bounds"], 0), element(j["autotune_verify_nis_bounds"], 1),
                j["autotune_verify_nis_verdict"].get<std::string>().c_str());
  else
    std::printf("  fitted on a recording: check the tuned config on another one (viewline_tune check --recording)\n");
  std::printf("  tuned config: %s\n  report: %s\n", j["autotuned_config"].get<std::string>().c_str(),
              j["report"].get<std::string>().c_str());
  return 0;
}

int TuneCommandLine::runCheck(const AdapterRegistry& registry) {
  CheckOptions co = check_options_;
  co.adapter_options = parseAdapterOptions(check_adapter_options_);
  co.workers = workers_;
  co.quiet = quiet_;
  const nlohmann::json j = runCheckSession(registry, co);
  if (!co.recording.empty())
    std::printf("viewline_tune check: %s %s on recording %s (confidence %.2f)\n  %s\n", co.scenario.c_str(),
                co.config.c_str(), co.recording.c_str(), get(j, "confidence"), j["data"].get<std::string>().c_str());
  else
    std::printf("viewline_tune check: %s %s, %d seed(s) from %llu (confidence %.2f)\n", co.scenario.c_str(),
                co.config.c_str(), co.seeds, static_cast<unsigned long long>(co.seed), get(j, "confidence"));
  for (const char* k : {"check_nis", "check_nees"}) {
    const nlohmann::json& c = j[k];
    std::printf("  %-4s mean %-9.4g band [%.4g, %.4g]  %zu samples, %g dof  %s\n", k + 6, get(c, "mean"),
                element(c["bounds"], 0), element(c["bounds"], 1), c["samples"].get<std::size_t>(), get(c, "dof"),
                c["verdict"].get<std::string>().c_str());
  }
  std::printf("  verdict: %s\n", j["check_verdict"].get<std::string>().c_str());
  return 0;
}

}  // namespace viewline::tuning
