#pragma once
// What pan_tilt_tracking does, as library code (the app only parses its command line): load the
// scenario file with its --set edits, then either the closed loop (ours, then ViSP's law on the
// same seed) or a filter-only replay of a logged run; write the summary JSON and the logs; print
// a short human summary with "met" / "not met" on each line that states a target.
//
//   pan_tilt_tracking --config config/pan_tilt_circle.yaml --seed 1 --summary out.json
//   pan_tilt_tracking --config config/pan_tilt_circle.yaml --seed 1 --record rec   (frames to rec/<controller>)
//   pan_tilt_tracking --config config/pan_tilt_circle.yaml --seed 1 --replay rec   (the loop on those frames)
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

/// The pan_tilt_tracking command line, parsed: scenario file and edits, seed, outputs, mode.
struct CommandOptions {
  std::string config_path;              ///< the scenario YAML (--config)
  std::vector<std::string> sets;        ///< --set KEY=VALUE, recorded in the summary (config_set)
  std::vector<std::string> shorthands;  ///< further KEY=VALUE edits from shorthand flags (not recorded)
  std::uint64_t seed = 1;               ///< run seed (--seed): path, noise, [T] draws
  std::string log_dir,                  ///< --log folder for the CSV logs ("" : none)
              summary_path;             ///< --summary JSON file ("" : none)
  bool quiet = false;                   ///< no progress lines
  runtime::Pacing pacing;               ///< wall-clock pacing of the loop (default: as fast as possible)
  /// A recording folder (written by --record): the loop on the recorded frames (scored with the
  /// recorded truth); or a frames CSV of a logged run: filter-only replay instead of the loop.
  std::string replay;
  std::string record;                   ///< record each run's frames, truth, camera and config to this folder ("" : none)
  PanTiltReplayEstimator estimator = PanTiltReplayEstimator::Filter;  ///< the replay's estimator
  std::size_t particles = 20000;        ///< of PanTiltReplayEstimator::WaypointParticles
};

/// Runs what the options ask for. `view`: a live view of the loop's frames (null: none; not used
/// by a replay). Returns the exit status (0). Throws core::InvalidInput for bad input.
int runCommand(const CommandOptions& options, FrameSink* view = nullptr, std::FILE* out = stdout);

}  // namespace viewline::scenarios::pan_tilt
