// dart_tracking: the dart experiment of [L] §VI for the viewline tracker (modules/scenarios/dart).
// Measurement-level scenario: pixels are generated from the true flights + noise + outliers (no
// rendered images, so no live view: --headless is the only mode). See config/dart_tracking.yaml.
// --record DIR / --replay DIR: the detections as generated, and the trackers on them (dart/recording.h).
// With footage per camera (cameras[].source: images, video or v4l2) the tracker runs on the marker
// detected in the frames instead: one session, no truth (dart/footage.h).
#include <CLI/CLI.hpp>
#include <cstdio>

#include "app_options.h"
#include "viewline/core/error.h"
#include "viewline/io/config_edit.h"
#include "viewline/io/files.h"
#include "viewline/io/log.h"
#include "viewline/runtime/progress.h"
#include "viewline/runtime/recording.h"
#include "viewline/scenarios/dart/footage.h"
#include "viewline/scenarios/dart/loop.h"

using namespace viewline;

int main(int argc, char** argv) {
  CLI::App cli{
      "dart_tracking: Monte Carlo of the multi-view viewline tracker on thrown darts ([L] section VI).\n"
      "MEASUREMENT-LEVEL scenario: detected pixels are generated from the true ballistic flights plus\n"
      "pixel noise and gross outliers (no images are rendered or detected). With footage per camera\n"
      "(cameras[].source) the tracker runs on the dart's marker detected in the frames (no truth)."};
  apps::CommonOptions opt;
  opt.config_path = "config/dart_tracking.yaml";  // the shipped scenario (--config optional)
  apps::addCommonOptions(cli, opt);
  apps::addRecordOption(cli, opt);
  apps::addReplayOption(cli, opt);
  int runs = 500;
  cli.add_option("--runs", runs,
                 "number of Monte-Carlo runs (run r uses deriveSeed(seed, r)); with --replay: default the recording's")
      ->check(CLI::PositiveNumber);
  if (const auto code = apps::parseCommandLine(cli, argc, argv)) return *code;
  return apps::runGuarded("dart_tracking", [&] {
    if (opt.display) std::fprintf(stderr, "dart_tracking: no live view (generated detections, no images)\n");
    const scenarios::DartScenarioConfig cfg = scenarios::loadDartScenario(opt.config_path, opt.sets);
    io::LogDirectory log(opt.log_dir);
    runtime::CsvSink telemetry(log);
    if (cfg.onFootage()) {
      // Footage: one session over the cameras' frames, no truth (dart/footage.h).
      if (!opt.record_dir.empty()) throw core::InvalidInput("--record: footage is recorded already (a recording holds generated detections)");
      if (!opt.replay_dir.empty()) throw core::InvalidInput("--replay: the cameras' footage is the input (cameras[].source)");
      const scenarios::DartFootageSummary s = scenarios::runDartFootage(cfg, log.enabled() ? &telemetry : nullptr, nullptr, opt.seed);
      log.flush();
      nlohmann::json j = scenarios::dartFootageSummaryJson(s, cfg);
      if (!opt.sets.empty()) j["config_set"] = opt.sets;
      if (!opt.summary_path.empty()) io::writeSummaryFile(opt.summary_path, j);
      std::fputs(scenarios::dartFootageSummaryText(s, cfg).c_str(), stdout);
      return 0;
    }
    scenarios::DartRunCallbacks cb;
    cb.pacing = opt.pacing();  // --realtime F: the late deliveries at F simulated seconds per second
    // --record / --replay: the generated detections, their truth and the other draws (dart/recording.h).
    cb.record_dir = opt.record_dir;
    cb.replay_dir = opt.replay_dir;
    if (!opt.record_dir.empty()) {
      YAML::Emitter yaml;
      yaml << io::loadConfigWithValues(opt.config_path, opt.sets).yaml();
      cb.config_text = std::string(yaml.c_str()) + "\n";
    }
    const std::string replay = !opt.replay_dir.empty() ? opt.replay_dir
                               : cfg.source.kind == runtime::SourceKind::Recording ? cfg.source.recording
                                                                                   : std::string();
    if (!replay.empty() && cli.count("--runs") == 0) runs = runtime::readSessionRecording(replay, "dart_tracking").units;
    if (log.enabled()) {
      io::CsvWriter& csv = log.stream("detections", scenarios::dartLogColumns());
      cb.log = [&csv](const scenarios::DartLogRow& r) { csv.rowText(scenarios::dartLogRow(r)); };
      cb.telemetry = &telemetry;
    }
    runtime::Progress progress = opt.quiet ? runtime::Progress::quiet() : runtime::Progress("dart_tracking runs", runs);
    cb.progress = [&](int done, int) { progress.update(done); };
    const scenarios::DartSummary s = scenarios::runDartExperiments(cfg, opt.seed, runs, cb);
    progress.finish();
    log.flush();
    nlohmann::json j = scenarios::summaryToJson(s, cfg);
    if (!opt.sets.empty()) j["config_set"] = opt.sets;
    if (!opt.summary_path.empty()) io::writeSummaryFile(opt.summary_path, j);
    std::fputs(scenarios::dartSummaryText(s).c_str(), stdout);
    return 0;
  });
}
