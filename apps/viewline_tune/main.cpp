// viewline_tune: tuning sessions for the scenarios (sweeps, NEES/NIS consistency, noise
// auto-tuning, HTML reports). Thin main: the command line and the sessions are in modules/tuning
// (command_line.h, session.h); the app adds the live curves (viz::LivePlot), Ctrl-C and exit codes.
// See tutorials/tune_tracking_loop/README.md.
#include <CLI/CLI.hpp>
#include <atomic>
#include <csignal>
#include <cstdio>
#include <exception>
#include <memory>

#include "app_options.h"
#include "viewline/core/version.h"
#include "viewline/core/error.h"
#include "viewline/tuning/command_line.h"
#include "viewline/viz/live_plot.h"

using namespace viewline;

namespace {

std::atomic<bool> g_stop{false};  // set by SIGINT/SIGTERM: no new runs are started (handlers need a global)
std::atomic<int> g_signal{0};     // the signal that set it

// First SIGINT (Ctrl-C) or SIGTERM: stop launching runs and write what is done; a second one ends
// the program (the default action).
extern "C" void onTuneStopSignal(int sig) {
  g_signal.store(sig);
  g_stop.store(true);
  std::signal(sig, SIG_DFL);
}

// The live curves of `run --display`: the error and the NIS (2 rows per image) in a vpPlot window.
std::function<void(const tuning::LiveSample&)> livePlot(const std::string& title, double confidence) {
  if (!viz::LivePlot::available()) return {};
  auto plot = std::make_shared<viz::LivePlot>(title, "error", 2.0, confidence);
  return [plot](const tuning::LiveSample& s) { plot->add(s.t, s.error, s.nis); };
}

}  // namespace

int main(int argc, char** argv) {
  CLI::App app{"viewline_tune: parameter sweeps, NEES/NIS consistency, noise auto-tuning and HTML reports for the\n"
               "viewline scenarios (run in-process, in parallel). See tutorials/tune_tracking_loop/README.md."};
  app.set_version_flag("--version", std::string("viewline ") + viewline::core::kVersion);
  tuning::TuneCommandLine command_line(app);
  if (const auto code = apps::parseCommandLine(app, argc, argv)) return *code;
  std::signal(SIGINT, onTuneStopSignal);
  std::signal(SIGTERM, onTuneStopSignal);
  // Bad input (a sweep file's key, a scenario refusing a value) is a usage error here: exit 2, as
  // tutorials/tune_tracking_loop documents; anything else (a full disk, a numerical failure) is a
  // runtime error (1). A session stopped by a signal exits 128 + its number (130, 143).
  try {
    const int status = command_line.run(tuning::makeBuiltinAdapters(), &g_stop, livePlot);
    if (const int sig = g_signal.load(); sig != 0 && status == 130) return 128 + sig;
    return status;
  } catch (const core::InvalidInput& e) {
    std::fprintf(stderr, "viewline_tune: error: %s\n", e.what());
    return 2;
  } catch (const std::exception& e) {
    std::fprintf(stderr, "viewline_tune: error: %s\n", e.what());
    return 1;
  }
}
