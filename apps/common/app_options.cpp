#include "app_options.h"

#include <csignal>
#include <cstdlib>
#include <cstring>
#include <exception>
#include <iostream>

#include "viewline/core/error.h"
#include "viewline/core/interrupt.h"
#include "viewline/core/version.h"
#include "viewline/io/config_edit.h"

namespace viewline::apps {

runtime::Pacing CommonOptions::pacing() const {
  if (realtime > 0.0) return {realtime};
  if (realtime == 0.0) return {1.0};  // --realtime without a factor
  if (display) return {1.0};
  return {};
}

bool CommonOptions::wantDisplay(const std::string& app_name) const {
  if (!display) return false;
  const char* d = std::getenv("DISPLAY");
  if (d == nullptr || *d == '\0') {
    std::cerr << app_name << ": --display needs an X display (DISPLAY is not set); running headless\n";
    return false;
  }
  return true;
}

void addCommonOptions(CLI::App& cli, CommonOptions& opt) {
  auto* config = cli.add_option("--config", opt.config_path, "scenario YAML (unknown keys are refused)");
  if (opt.config_path.empty()) config->required();
  config->check(CLI::ExistingFile);
  cli.add_option("--set", opt.sets, io::kSetOptionHelp)->take_all();
  cli.add_option("--seed", opt.seed, "random seed (every run is reproducible from it)");
  auto* headless = cli.add_flag("--headless", opt.headless, "no window (the default; never needs X)");
  auto* display = cli.add_flag("--display", opt.display,
                               "live window, paced to real time; keys: space pause, n step, q quit; "
                               "stays open at the end until a click or key");
  headless->excludes(display);
  cli.add_option("--realtime", opt.realtime,
                 "pace the run to the wall clock: FACTOR simulated seconds per second (default 1 when "
                 "given without a value or with --display; otherwise as fast as possible)")
      ->expected(0, 1)
      ->default_str("1")
      ->check(CLI::Range(0.0, 1000.0));
  cli.add_option("--log", opt.log_dir, "CSV logs of the run in this directory");
  cli.add_option("--summary", opt.summary_path, "the metrics as JSON in this file (written atomically)");
  cli.add_flag("--quiet", opt.quiet, "no progress output");
  cli.set_version_flag("--version", std::string("viewline ") + core::kVersion);
}

void addRecordOption(CLI::App& cli, CommonOptions& opt) {
  cli.add_option("--record", opt.record_dir,
                 "record the frames (PNG), their stamps, the truth, the camera (ViSP XML) and the config as run "
                 "into this new folder, to run again with --replay");
}

void addReplayOption(CLI::App& cli, CommonOptions& opt) {
  cli.add_option("--replay", opt.replay_dir,
                 "run on the frames of a folder written by --record (same config and --seed: the same run)")
      ->check(CLI::ExistingDirectory);
}

std::optional<int> parseCommandLine(CLI::App& cli, int argc, char** argv) {
  try {
    cli.parse(argc, argv);
  } catch (const CLI::ParseError& e) {
    const int code = cli.exit(e);  // prints help, or the error and "Run with --help"
    return code == 0 ? 0 : 2;
  }
  return std::nullopt;
}

namespace {
extern "C" void onStopSignal(int sig) { core::noteInterrupt(sig); }  // async-signal-safe: one atomic store
}  // namespace

void installStopHandlers() {
  struct sigaction sa;
  std::memset(&sa, 0, sizeof sa);
  sa.sa_handler = onStopSignal;
  sigemptyset(&sa.sa_mask);
  // SA_RESTART: blocking reads and writes go on after the handler; SA_RESETHAND: a second Ctrl-C
  // takes the default action and ends a run that does not stop by itself.
  sa.sa_flags = SA_RESTART | SA_RESETHAND;
  sigaction(SIGINT, &sa, nullptr);
  sigaction(SIGTERM, &sa, nullptr);
}

int runGuarded(const std::string& app_name, const std::function<int()>& body, OnSignal on_signal) {
  if (on_signal == OnSignal::EndTheRun) installStopHandlers();
  try {
    const int status = body();
    if (const int sig = core::interruptSignal()) {
      std::cerr << app_name << ": interrupted by " << (sig == SIGINT ? "SIGINT" : sig == SIGTERM ? "SIGTERM" : "a signal")
                << "; the outputs hold the part of the run that was done\n";
      return 128 + sig;  // the shell's convention for "ended by signal sig"
    }
    return status;
  } catch (const core::Error& e) {
    std::cerr << app_name << ": " << e.what() << "\n";
    return 1;
  } catch (const std::exception& e) {
    std::cerr << app_name << ": error: " << e.what() << "\n";
    return 1;
  }
}

}  // namespace viewline::apps
