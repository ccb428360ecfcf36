// mobile_capture: [K]'s mobile robot with a pan/tilt camera chasing and grasping a red object that
// moves on the floor. Thin main: the common flags, the YAML scenario, one displayed/logged run when
// asked, then scenarios::runMobileCaptureBatch and its summary; --record DIR / --replay DIR
// (mobile_capture/recording.h); with footage as `source:` (images, video, v4l2) one session over it
// instead (scenarios::runMobileCaptureFootage, mobile_capture/footage.h). The scenario is documented in
// modules/scenarios/include/viewline/scenarios/mobile_capture.h.

#include <cstdio>
#include <memory>
#include <nlohmann/json.hpp>

#include "app_options.h"
#include "viewline/core/error.h"
#include "viewline/core/random.h"
#include "viewline/io/config_edit.h"
#include "viewline/io/files.h"
#include "viewline/io/log.h"
#include "viewline/runtime/progress.h"
#include "viewline/runtime/telemetry.h"
#include "viewline/scenarios/mobile_capture.h"
#include "viewline/scenarios/mobile_capture/footage.h"
#include "viewline/viz/mobile_capture_display.h"

using namespace viewline;

int main(int argc, char** argv) {
  CLI::App cli{"Mobile capture: differential-drive robot with a pan/tilt camera, curvilinear-target EKF, "
               "least-squares path prediction and [K]'s shortest-time capture planner, on rendered images (or footage: "
               "source: images, video, v4l2)"};
  apps::CommonOptions opt;
  opt.config_path = "config/mobile_capture.yaml";
  int runs = 1, jobs = 0;
  apps::addCommonOptions(cli, opt);
  apps::addRecordOption(cli, opt);
  apps::addReplayOption(cli, opt);
  cli.add_option("--runs", runs, "number of capture runs (run i uses deriveSeed(seed, i)); with --replay: default the recording's")
      ->check(CLI::PositiveNumber);
  cli.add_option("--jobs", jobs, "worker threads (default: the config's threads)");
  if (const auto code = apps::parseCommandLine(cli, argc, argv)) return *code;
  return apps::runGuarded("mobile_capture", [&] {
    const io::ConfigNode root = io::loadConfigWithValues(opt.config_path, opt.sets);
    auto cfg = scenarios::loadMobileCaptureConfig(root);
    if (jobs > 0) cfg.threads = jobs;
    cfg.validate();
    if (scenarios::mobileCaptureOnFootage(cfg)) {
      // One session over the head camera's footage, the robot held at its start pose
      // (mobile_capture/footage.h): no runs to count, nothing to record or replay.
      if (cli.count("--runs") > 0) throw core::InvalidInput("--runs: footage runs as one session");
      if (cli.count("--realtime") > 0)
        throw core::InvalidInput("--realtime: footage is paced by its source (source.pace: true)");
      scenarios::MobileCaptureHooks hooks;
      hooks.record_dir = opt.record_dir;  // refused by the session, naming the flag
      hooks.replay_dir = opt.replay_dir;
      std::unique_ptr<viz::MobileCaptureDisplay> view;
      if (opt.wantDisplay("mobile_capture")) {
        view = std::make_unique<viz::MobileCaptureDisplay>(cfg);
        hooks.on_frame = [&](const scenarios::MobileCaptureFrame& f) { view->show(f); };
        hooks.quit_requested = [&] { return view->quitRequested(); };
      }
      const auto s = scenarios::runMobileCaptureFootage(cfg, opt.seed, nullptr, &hooks);
      io::LogDirectory log(opt.log_dir);
      scenarios::logFootage(s, log);
      nlohmann::json j = scenarios::footageSummaryJson(s, cfg);
      if (!opt.sets.empty()) j["config_set"] = opt.sets;
      if (!opt.summary_path.empty()) io::writeSummaryFile(opt.summary_path, j);
      std::fputs(scenarios::footageSummaryText(s, cfg).c_str(), stdout);
      if (view) view->waitForClose();
      return 0;
    }
    // --record / --replay: the batch's runs in a session recording (mobile_capture/recording.h).
    scenarios::MobileCaptureSessionIo files;
    files.record_dir = opt.record_dir;
    files.replay_dir = opt.replay_dir;
    if (!opt.record_dir.empty()) {
      YAML::Emitter yaml;
      yaml << root.yaml();
      files.config_text = std::string(yaml.c_str()) + "\n";
    }
    const std::string replay = scenarios::mobileCaptureReplayRoot(cfg, files);
    if (!replay.empty()) {  // read first: a folder that is no recording is refused before any run
      const int recorded = scenarios::recordedMobileCaptureRuns(replay);
      if (cli.count("--runs") == 0) runs = recorded;
    }
    // One watched and/or logged run first: the batch's run 0 (same seed).
    const bool display = opt.wantDisplay("mobile_capture");
    if (!opt.log_dir.empty() || display) {
      io::LogDirectory log(opt.log_dir);
      runtime::CsvSink csv(log);
      scenarios::MobileCaptureHooks hooks;
      if (!opt.log_dir.empty()) hooks.telemetry = &csv;
      hooks.pacing = opt.pacing();
      if (!replay.empty()) hooks.replay_dir = scenarios::mobileCaptureRunDir(replay, 0);  // the batch records run 0
      std::unique_ptr<viz::MobileCaptureDisplay> view;
      if (display) {
        view = std::make_unique<viz::MobileCaptureDisplay>(cfg);
        hooks.on_frame = [&](const scenarios::MobileCaptureFrame& f) { view->show(f); };
        hooks.quit_requested = [&] { return view->quitRequested(); };
      }
      const auto r = scenarios::runMobileCapture(cfg, core::deriveSeed(opt.seed, 0), &hooks);
      if (r.interrupted)
        std::printf("run 0: stopped early (%s), %d grasp attempts, %d/%d frames with a detection; not scored\n",
                    r.captured ? "captured" : "not captured", r.grasp_attempts, r.detections, r.frames);
      else
        std::printf("run 0: %s at %.1f s (oracle %.1f s), %d grasp attempts, %d/%d frames with a detection\n",
                    r.captured ? "captured" : "NOT captured", r.capture_time, r.oracle_time, r.grasp_attempts,
                    r.detections, r.frames);
      if (view) view->waitForClose();
      scenarios::logFilterTest(scenarios::runFilterTest(cfg, core::deriveSeed(opt.seed, 100000)), log);
    }
    runtime::Progress progress = opt.quiet ? runtime::Progress::quiet() : runtime::Progress("runs", runs);
    const auto s =
        scenarios::runMobileCaptureBatch(cfg, runs, opt.seed, [&](int done, int) { progress.update(done); }, files);
    progress.finish();
    nlohmann::json j = nlohmann::json::parse(scenarios::summaryJson(s, cfg));
    if (!opt.summary_path.empty()) {
      nlohmann::json out = j;
      if (!opt.sets.empty()) out["config_set"] = opt.sets;
      io::writeSummaryFile(opt.summary_path, out);
    }
    std::printf("%s", scenarios::summaryText(s, cfg, runs, opt.seed).c_str());
    return 0;
  });
}
