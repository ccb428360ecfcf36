#include "pan_tilt_recording.h"

#include <yaml-cpp/yaml.h>

#include <filesystem>

#include "viewline/core/error.h"
#include "viewline/runtime/recording.h"
#include "viewline/tracking/planar_target/config.h"

namespace viewline::tuning::detail {

namespace fs = std::filesystem;

namespace {

/// The folder holding recording.csv: `dir` itself or its predictive/ subfolder (--record DIR).
std::string recordingFolder(const std::string& dir) {
  if (fs::exists(fs::path(dir) / "recording.csv")) return dir;
  const fs::path ours = fs::path(dir) / "predictive";
  if (fs::exists(ours / "recording.csv")) return ours.string();
  throw core::InvalidInput(dir + ": not a recording (no recording.csv, nor predictive/recording.csv as "
                           "pan_tilt_tracking --record DIR writes)");
}

}  // namespace

PanTiltRecordingRun panTiltRecordingRun(scenarios::PanTiltScenarioConfig base, const std::string& dir) {
  PanTiltRecordingRun run;
  run.dir = recordingFolder(dir);
  const runtime::RecordingSource source(run.dir);
  run.grabs = source.entries().size();
  scenarios::PanTiltScenarioConfig& c = base;
  c.source = runtime::SourceConfig{};
  c.source.kind = runtime::SourceKind::Recording;
  c.source.recording = run.dir;
  c.run_baseline = false;
  // Every grab (the loop stops at floor(duration x fps) grabs or at the recording's end).
  c.duration = (static_cast<double>(run.grabs) + 0.5) / c.fps;
  if (!(c.metrics_start < c.duration))
    throw core::InvalidInput(run.dir + ": " + std::to_string(run.grabs) + " grabs at " + std::to_string(c.fps) +
                             " fps end before run.metrics_start (" + std::to_string(c.metrics_start) + " s)");
  run.note = "no config.yaml: the given config's filter replays the loop";
  const std::string text = source.configText();
  if (!text.empty()) {
    const std::string file = run.dir + "/config.yaml";
    YAML::Node recorded;
    try {
      recorded = YAML::Load(text);
    } catch (const YAML::Exception& e) {
      throw core::InvalidInput(file + ": " + e.what());
    }
    const YAML::Node f = recorded["filter"];
    if (f && f.IsMap() && f["model"]) {
      const auto model = tracking::targetModelFromString(f["model"].as<std::string>());
      if (model != c.control.filter.model)
        throw core::InvalidInput(file + ": recorded with filter.model " + tracking::toString(model) + ", the config has " +
                                 tracking::toString(c.control.filter.model) +
                                 ": the loop replays the recorded run only with the filter it ran");
    }
    if (f && f.IsMap() && f["q"]) {
      c.control.filter.q = f["q"].as<double>();
      run.note = "the loop replayed with the recorded filter.q " + f["q"].as<std::string>() + " (" + file + ")";
    } else {
      run.note = "the loop replayed with the config's filter (" + file + " sets no filter.q)";
    }
  }
  run.config = std::move(c);
  return run;
}

}  // namespace viewline::tuning::detail
