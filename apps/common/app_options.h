#pragma once
// The command line every scenario app shares, so that the same flag means the same thing in
// each of them (DESIGN "Running"): --config, --set KEY=VALUE, --seed, --headless / --display,
// --realtime [FACTOR], --log DIR, --summary FILE, --quiet, --version; and, for apps whose loop
// runs on a runtime::FrameSource, --record DIR / --replay DIR (addRecordOption, addReplayOption).
//
//   int main(int argc, char** argv) {
//     CLI::App cli{"..."};
//     apps::CommonOptions opt{"config/ball_catching.yaml"};
//     apps::addCommonOptions(cli, opt);
//     if (const auto code = apps::parseCommandLine(cli, argc, argv)) return *code;
//     return apps::runGuarded("ball_catching", [&] { ...; return 0; });
//   }
//
// Exit status: 0 done, 1 runtime error (message names the file/key), 2 usage error,
// 130 / 143 ended by SIGINT (Ctrl-C) / SIGTERM with its partial summary written.

#include <CLI/CLI.hpp>
#include <cstdint>
#include <functional>
#include <optional>
#include <string>
#include <vector>

#include "viewline/runtime/scheduler.h"

namespace viewline::apps {

struct CommonOptions {
  std::string config_path;        ///< --config
  std::vector<std::string> sets;  ///< --set KEY=VALUE (repeatable)
  std::uint64_t seed = 1;         ///< --seed
  bool headless = false;          ///< --headless (the default)
  bool display = false;           ///< --display: a live window, paced to real time
  double realtime = -1.0;         ///< --realtime [FACTOR]: < 0 not given, 0 given without a value (1)
  std::string log_dir;            ///< --log DIR
  std::string summary_path;       ///< --summary FILE
  bool quiet = false;             ///< --quiet: no progress lines
  std::string record_dir;         ///< --record DIR: the run's frames, truth, camera and config (runtime/recording.h)
  std::string replay_dir;         ///< --replay DIR: run on a recording written by --record instead of the config's source

  /// The pacing the flags ask for: --realtime F paces at F; --display alone paces at 1;
  /// otherwise as fast as possible. Call after parsing.
  runtime::Pacing pacing() const;
  /// Whether a display is wanted and possible (an X display exists); prints why not.
  bool wantDisplay(const std::string& app_name) const;
};

/// Adds the common flags to `cli` (with --headless/--display excluding each other).
void addCommonOptions(CLI::App& cli, CommonOptions& opt);

/// Adds --record DIR (every app that runs a scenario loop can record its frames).
void addRecordOption(CLI::App& cli, CommonOptions& opt);
/// Adds --replay DIR: the loop on a recording written by --record (apps whose --replay already
/// means something else add only --record and accept a recording folder there).
void addReplayOption(CLI::App& cli, CommonOptions& opt);

/// Parses the command line. nullopt: go on; otherwise the exit status to return at once: 0 after
/// --help, 2 for a usage error (unknown flag, bad value, excluded pair), with CLI11's message.
/// (CLI11_PARSE would return CLI11's own codes, e.g. 105/108, instead of 2.)
std::optional<int> parseCommandLine(CLI::App& cli, int argc, char** argv);

/// What SIGINT (Ctrl-C) and SIGTERM do while runGuarded() runs its body.
enum class OnSignal {
  /// The first signal is recorded (core::noteInterrupt): schedulers stop, the run ends with what it
  /// has, its summary says "interrupted": true, and the exit status is 128 + signal (130 / 143).
  /// A second signal ends the process at once (the default action).
  EndTheRun,
  /// The default action: the process ends at once (outputs are written atomically, so no file is
  /// left half-written). For tools whose loops do not poll core::interruptRequested().
  Terminate,
};

/// Runs `body` and maps exceptions to exit codes: viewline::core::InvalidInput and other
/// core::Error → 1 with "<app>: <message>" on stderr; anything else → 1 with its what().
/// A run ended by a signal (OnSignal::EndTheRun) returns 128 + the signal number.
int runGuarded(const std::string& app_name, const std::function<int()>& body, OnSignal on_signal = OnSignal::EndTheRun);

/// Installs the OnSignal::EndTheRun handlers for SIGINT and SIGTERM (runGuarded() does it).
void installStopHandlers();

}  // namespace viewline::apps
