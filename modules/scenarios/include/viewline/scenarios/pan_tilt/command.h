#pragma once
// What pan_tilt_tracking does, as library code (the app only parses its command line): load the
// scenario file with its --set edits, then either the closed loop (ours, then ViSP's law on the
// same seed) or a filter-only replay of a logged run; write the summary JSON and the logs; print
// a short human summary with "met" / "not met" on each line that states a target.
//
//   pan_tilt_tracking --config config/pan_tilt_circle.yaml --seed 1 --summary out.json
//   pan_tilt_tracking --config <variant>.yaml --seed 1 --replay <log>/predictive_frames.csv   (filter only)
//   ... --replay <log>/predictive_frames.csv --oracle-corners   (a bound: the true corner times and speed)
//   ... --replay <log>/predictive_frames.csv --particles        (the random path's Bayes reference)

#include <cstdint>
#include <cstdio>
#include <string>
#include <vector>

#include "viewline/runtime/scheduler.h"
#include "viewline/scenarios/pan_tilt/replay.h"
#include "viewline/scenarios/pan_tilt/telemetry.h"

namespace viewline::scenarios::pan_tilt {

/// The pan_tilt_tracking command line, as parsed: config, edits, seed, outputs, pacing, replay.
struct CommandOptions {
  std::string config_path;  ///< --config FILE
  std::vector<std::string> sets;        ///< --set KEY=VALUE, recorded in the summary (config_set)
  std::vector<std::string> shorthands;  ///< further KEY=VALUE edits from shorthand flags (not recorded)
  std::uint64_t seed = 1;  ///< --seed
  std::string log_dir,        ///< --log DIR ("": no log)
              summary_path;   ///< --summary FILE ("": none)
  bool quiet = false;                   ///< no progress lines
  runtime::Pacing pacing;               ///< --realtime: paced to the wall clock, else as fast as possible
  std::string replay;                   ///< frames CSV of a logged run: filter-only replay instead of the loop
  PanTiltReplayEstimator estimator = PanTiltReplayEstimator::Filter;  ///< what the replay runs
  std::size_t particles = 20000;        ///< of PanTiltReplayEstimator::WaypointParticles
};

/// Runs what the options ask for. `view`: a live view of the loop's frames (null: none; not used
/// by a replay). Returns the exit status (0). Throws core::InvalidInput for bad input.
int runCommand(const CommandOptions& options, FrameSink* view = nullptr, std::FILE* out = stdout);

}  // namespace viewline::scenarios::pan_tilt
