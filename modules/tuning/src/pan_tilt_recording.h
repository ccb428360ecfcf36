#pragma once
// Tuning the pan-tilt filter on a recording of its frames (internal to modules/tuning): the config
// that replays a viewline recording folder through the scenario's own loop.
//
// Why the loop and not the frames alone: the camera rides on the unit, so a detected pixel becomes
// a screen-plane measurement through the unit's pose at that frame, and a recording holds the
// frames, not the encoder readings. The loop re-drives the unit with the recorded run's controller
// (same config, same filter noise, same seed: scenarios::PanTiltRunIo::replay_dir reproduces the
// recorded run bit for bit), and its measurements are then replayed open loop through the filter
// for each candidate noise, as the adapter does with a live run. So the replayed loop must use the
// filter the recording was made with: its filter.q is taken from the recording's config.yaml (the
// config as run) when it has one, whatever noise is being checked, and a different filter.model is
// refused.

#include <cstddef>
#include <string>

#include "viewline/scenarios/pan_tilt/config.h"

namespace viewline::tuning::detail {

/// A pan-tilt recording ready to replay through the scenario loop.
struct PanTiltRecordingRun {
  scenarios::PanTiltScenarioConfig config;  ///< `base` on the recording: source, length, the recorded filter.q
  std::string dir;                          ///< the folder holding recording.csv
  std::size_t grabs = 0;                    ///< grabs in the recording (lost ones included)
  std::string note;                         ///< one line: what came from the recording's config.yaml
};

/// The run that replays the recording in `dir` (a folder with recording.csv, or the folder given to
/// pan_tilt_tracking --record, whose predictive/ subfolder holds it) with `base`: kind recording,
/// ours only, run.duration covering every grab. Throws core::InvalidInput naming the folder (no
/// recording, too short for run.metrics_start) or the recording's config.yaml (another filter.model).
PanTiltRecordingRun panTiltRecordingRun(scenarios::PanTiltScenarioConfig base, const std::string& dir);

}  // namespace viewline::tuning::detail
