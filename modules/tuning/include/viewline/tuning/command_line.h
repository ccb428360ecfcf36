#pragma once
// The viewline_tune command line (its subcommands, their options and the short summaries they
// print), so that the app is a thin main:
//
//   CLI::App app{"viewline_tune: ..."};
//   tuning::TuneCommandLine cl(app);
//   CLI11_PARSE(app, argc, argv);
//   return cl.run(tuning::makeBuiltinAdapters(), &stop_flag, live_view);
//
//   viewline_tune sweep    --sweep config/sweeps/dart_noise.yaml --out out/tune [--workers N] [--speedup]
//   viewline_tune run      --scenario dart --config config/dart_tracking.yaml --seed 1 --out out/run [--display]
//   viewline_tune autotune --scenario dart --config config/dart_tracking.yaml [--log DIR] --out out/autotune
//   viewline_tune check    --scenario mobile_capture --config config/mobile_capture.yaml --seeds 3 [--seed 2]
//   viewline_tune list

#include <CLI/CLI.hpp>
#include <atomic>
#include <string>
#include <vector>

#include "viewline/tuning/scenario.h"
#include "viewline/tuning/session.h"

namespace viewline::tuning {

/// The viewline_tune subcommands on a CLI11 app, and running the parsed one.
class TuneCommandLine {
public:
  /// Adds the subcommands sweep, run, autotune, check and list to `app` (exactly one is required).
  explicit TuneCommandLine(CLI::App& app);
  /// Runs the parsed subcommand and prints its summary on stdout; returns the exit status (130 for
  /// a sweep stopped by `stop`). Throws core::InvalidInput for bad input (name, file, key).
  int run(const AdapterRegistry& registry, const std::atomic<bool>* stop, const LiveViewFactory& live_view);

private:
  int runSweep(const AdapterRegistry& registry, const std::atomic<bool>* stop);
  int runSingle(const AdapterRegistry& registry, const LiveViewFactory& live_view);
  int runAutotune(const AdapterRegistry& registry);
  int runCheck(const AdapterRegistry& registry);
  static void list(const AdapterRegistry& registry);

  CLI::App* sweep_ = nullptr;
  CLI::App* run_ = nullptr;
  CLI::App* autotune_ = nullptr;
  CLI::App* check_ = nullptr;
  CLI::App* list_ = nullptr;
  int workers_ = 0;
  bool quiet_ = false;
  std::string sweep_file_;
  SessionOptions sweep_options_;
  SingleRunOptions run_options_;
  AutotuneSessionOptions autotune_options_;
  CheckOptions check_options_;
  std::vector<std::string> run_adapter_options_, autotune_adapter_options_, check_adapter_options_;
  std::vector<std::string> start_values_;  // --start-value key=value items
};

/// "name=value" items of --option as adapter options; throws core::InvalidInput on a bad item.
AdapterOptions parseAdapterOptions(const std::vector<std::string>& items);

}  // namespace viewline::tuning
