#pragma once
// Dart tracking on footage: the dart rig's cameras give real frames (an image sequence, a video
// file or a live V4L2 camera per camera) and the viewline tracker runs on the dart's marker as
// it would on a real rig.
//
//   cameras:
//     - {name: side, eye: [...], target: [...], hfov_deg: 62, source: {kind: video, path: side.mkv, stamps: side.csv}}
//     - {name: rear, eye: [...], target: [...], hfov_deg: 62, source: {kind: images, pattern: rear/%04d.png, stamps: rear.csv}}
//   detector: {hsv: [35, 85, 80, 255, 30, 255], min_area_px: 6}
//
// One `source:` per camera (every camera or none), merged in stamp order
// (runtime::MergedFrameSource: the stamps must share one clock). Each frame's marker is detected
// by vision::BallDetector (the `detector:` block; a dart seen by a camera is a small blob, so its
// defaults have smaller area floors than the ball's, defaultDartDetector()), in a window around
// the tracker's predicted pixel, and fed to the viewline tracker with the scenario's tracker
// config (tracker.gate: the shipped Mahalanobis gate; the experiments' gate comparison needs
// truth). Tracks start and restart as the tracker does; a pause in the detections longer than
// max_coast_s (or max_forward_gap_s) ends the dart: the tracker starts afresh, as for a new throw.
//
// There is no truth: the run is ONE session to the end of the footage. What is reported is what
// can be known without it: frames, lost frames and detections per camera, tracks started, each
// track's predicted board hit (the crossing of the plane x = board_center.x, with the time and
// std, from its last confirmed estimate before the predicted hit time: later images show the
// dart at rest in the board) and the mean NIS of the fused images tested against their track
// before that time. The experiments' RMSE, NEES and gate figures are "not scored: no truth".
//
// Live: on footage with pace: true (or a V4L2 camera) the cameras run at their own pace
// (runtime::PacedSource per camera, merged): a frame the session is too busy to take is dropped
// and counted, and each frame is timed from its grab to the end of its processing (the tracker's
// update and the board-hit prediction; wall and thread CPU, runtime::ProcessingTimer) against one
// frame period of the fastest camera (cameras[].rate_hz): the summary's `live` object and lines,
// as ball catching's footage session gives them (runtime::LiveReport). Each camera's PacedSource
// sets its wall-clock origin at its own first grab, so the frames of a camera whose first stamp
// is later (alternating cameras: the second, 10 ms) arrive that much earlier, relative to the
// other camera's, than their stamps say; the stamps the tracker sees are the footage's own.
//
// Faults: the `faults:` list (runtime/faults.h, windows on the footage's stamps) is injected into
// the footage and the detector as in ball catching's footage session, and the same defences run
// with or without it: a frame delivered past frame_deadline_s is dropped, a frozen camera's repeated
// image is dropped (runtime::StaleFrameFilter), a detector exception is caught and a non-finite or
// outside pixel screened (runtime::guardedDetect, runtime::usablePixel), each counted in the
// summary's `faults` (present when anything was counted). v4l2 is untested on hardware.

#include <cstdint>
#include <nlohmann/json.hpp>
#include <optional>
#include <string>
#include <vector>

#include "viewline/planning/crossing.h"
#include "viewline/runtime/faults.h"
#include "viewline/runtime/live.h"
#include "viewline/runtime/telemetry.h"
#include "viewline/scenarios/ball_catching/footage.h"
#include "viewline/scenarios/dart/config.h"

namespace viewline::scenarios {

/// What one camera of a dart footage session gave (ball catching's footage camera counts).
using DartFootageCamera = FootageCamera;

/// One track of a dart footage session and its predicted board hit.
struct DartFootageTrack {
  int track = 0;         ///< the session's track number, from 1 (a restart after rejections keeps it)
  double t_first = 0.0,  ///< s, footage stamp of the track's first fused image
         t_last = 0.0;   ///< s, stamp of its last fused image
  int fused = 0;         ///< images fused into the track
  /// The crossing of the board plane x = board_center.x predicted from the track's last confirmed
  /// estimate before the predicted hit time: point (m, world), time (s, footage clock),
  /// covariance; empty when none was predicted.
  std::optional<planning::Crossing> board_hit;
};

/// The summary of a dart footage session (footage.h): what is known without truth.
struct DartFootageSummary : FootageSessionCounts {
  std::vector<DartFootageTrack> tracks;  ///< the tracks with a fused image, in order
  double nis_mean = 0.0;        ///< mean NIS of the fused images tested against their track before its hit (2 dof)
  std::uint64_t nis_samples = 0;  ///< images in nis_mean
  std::optional<runtime::LiveReport> live;  ///< processing times and misses on a live source
  runtime::FaultReport faults;  ///< injected faults and the defences' counts (empty: nothing counted)
  double wall_s = 0.0;  ///< wall-clock time of the session, s
};

/// The board plane of the scenario: x = board_center.x, normal towards the thrower (-x).
planning::CrossingPlane dartBoardPlane(const DartScenarioConfig& cfg);

/// Runs the session over the footage of cfg's cameras (cfg.onFootage(); the header comment).
/// `telemetry` (optional): the detections, the tracker's updates (channel "dart") and estimates.
/// `clock`: the wall clock of paced footage and of the processing timer (null: the steady clock).
/// `seed`: the injected faults' (corrupt images). Throws core::InvalidInput naming the file or
/// device a source cannot open or read.
DartFootageSummary runDartFootage(const DartScenarioConfig& cfg, runtime::TelemetrySink* telemetry = nullptr,
                                  runtime::WallClock* clock = nullptr, std::uint64_t seed = 1);

/// The summary as JSON (RMSE and experiments null: "truth": not scored).
nlohmann::json dartFootageSummaryJson(const DartFootageSummary& s, const DartScenarioConfig& cfg);

/// The console summary (says "not scored: no truth" where the experiments give their figures).
std::string dartFootageSummaryText(const DartFootageSummary& s, const DartScenarioConfig& cfg);

}  // namespace viewline::scenarios
