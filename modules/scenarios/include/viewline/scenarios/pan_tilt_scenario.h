#pragma once
// Pan-tilt tracking scenario ([T], SPEC §5): a camera on a simulated FLIR PTU-D46 keeps a dark disc
// moving on a screen at the image centre; our predictive law against ViSP's point servo. Library
// code, so that the app, the tuning tool and the benches run the same thing (a config + a seed ->
// metrics). One header per part, under pan_tilt/:
//
//   config.h     the config struct, its reader (read once, validated once) and the cameras
//   world.h      the simulated world: screen, target path, [T] noise, unit, renderer as a FrameSource
//   loop.h       the closed loop on the scheduler (runPanTilt, runPanTiltComparison)
//   metrics.h    run metrics and the summary JSON
//   telemetry.h  per-frame records and their sinks (frames CSV, fan-out; displays live in viz)
//   replay.h     filter-only replays of a logged run
//   command.h    what pan_tilt_tracking does (the app only parses its command line)

#include "viewline/scenarios/pan_tilt/command.h"
#include "viewline/scenarios/pan_tilt/config.h"
#include "viewline/scenarios/pan_tilt/loop.h"
#include "viewline/scenarios/pan_tilt/metrics.h"
#include "viewline/scenarios/pan_tilt/replay.h"
#include "viewline/scenarios/pan_tilt/telemetry.h"
#include "viewline/scenarios/pan_tilt/world.h"
