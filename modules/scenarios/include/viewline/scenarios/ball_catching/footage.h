#pragma once
// Ball catching on footage: the rig's cameras give real frames (an image sequence, a video file or
// a live V4L2 camera per camera), and the catcher runs on them as it would on a real rig.
//
//   cameras:
//     - {name: right,  source: {kind: video, path: right.mkv, stamps: right_stamps.csv}}
//     - {name: behind, source: {kind: images, pattern: behind/image.%04d.png, stamps: behind/stamps.csv}}
//
// One `source:` per camera, in the rig's camera order (cameras[i].source, runtime/source_config.h:
// every kind but recording, each opened by runtime::makeFrameSource, so a live camera goes the
// same way as a file). The cameras' sources are merged into one source in stamp order: their
// stamps must share one clock (stamps files written by the capture, or V4L2's CLOCK_MONOTONIC);
// a video's container times start at 0 per file and suit one camera only.
//
// There is no simulated throw and no truth: the run is ONE session over the footage's frames,
// not throw by throw. Every frame is detected (vision::BallDetector, window around the tracker's
// predicted pixel) and fused by the viewline tracker; after processing_latency_s the fused state
// (the flight fit's, planner_input.h) reaches planning::CatchPlanner, which predicts the crossing
// of the box plane and streams set points to the simulated robot within its limits, every
// control period, as in a simulated throw (loop.h). A pause in the detections longer than the
// tracker's max_coast_s (or max_forward_gap) ends the ball: the tracker starts afresh, as it does
// for each simulated throw. Each track the tracker starts is one attempt:
// the planner is reset from the robot's current commanded state, so after a crossing (the planner
// goes home home_delay_s after it) the next ball starts a new plan. The session ends when the
// footage ends (the set points then in flight still reach the robot).
//
// What is reported is what can be known without truth: frames, lost frames and detections per
// camera, tracks started, each track's predicted crossing (point, time, std), the planner's
// decision on it (committed / gave up / moved without committing / no target) and where the hole
// was at the predicted crossing time, commands sent, the robot's limit violations and refused set
// points, and, on a live source (V4L2, or footage with pace: true), the processing times and
// deadline misses (runtime::LiveReport). There is no catch rate: "not scored: no truth".
// Registration (the marker on the box, seen by the cameras) needs the robot in the images: it is
// off on footage, and the rig's calibration is taken as registered to the robot.
//
// Live footage: each camera's PacedSource sets its wall-clock origin at its own first grab, so
// the cameras' pacing can be offset by up to one frame's processing; the stamps the estimators
// see are the footage's own, unaffected.

#include <cstdint>
#include <memory>
#include <nlohmann/json.hpp>
#include <optional>
#include <string>
#include <vector>

#include <Eigen/Core>

#include "viewline/planning/crossing.h"
#include "viewline/runtime/faults.h"
#include "viewline/runtime/live.h"
#include "viewline/runtime/merged_source.h"
#include "viewline/scenarios/ball_catching/config.h"
#include "viewline/scenarios/ball_catching/loop.h"

namespace viewline::scenarios {

/// "images <pattern>", "video <path>", "v4l2 <device>" or "recording <folder>": a source named for messages.
std::string describeSource(const runtime::SourceConfig& source);

/// The footage of the rig's active cameras (cameras[i].source), merged into one multi-camera
/// source in stamp order (runtime::MergedFrameSource), `camera` set to the camera's index in the rig.
class CatchFootageFrames : public runtime::MergedFrameSource {
public:
  /// Opens every active camera's source (runtime::makeFrameSource; throws core::InvalidInput
  /// naming the file or device) with `clock` for paced footage (null: the steady clock).
  explicit CatchFootageFrames(const BallCatchingConfig& cfg, runtime::WallClock* clock = nullptr);
};

/// One track of a footage session (one attempt of the planner) and what the planner made of it.
struct CatchFootageTrack {
  int track = 0;             ///< the tracker's track number, from 1 (its restarts keep it)
  double t_first = 0.0,      ///< s, footage stamp of the first image of the track that reached the planner
         t_last = 0.0;       ///< s, stamp of its last one
  int planner_updates = 0;   ///< fused states the planner received from the track
  /// The commanded hole position the planner started the track's plan from, m (world).
  Eigen::Vector3d start = Eigen::Vector3d::Zero();
  /// The crossing the planner aimed at when the track ended (its committed target, or the last
  /// prediction certain enough to move for): point (m, world), time (s), covariance.
  std::optional<planning::Crossing> target;
  /// The last crossing predicted from the track, whether or not the planner acted on it.
  std::optional<planning::Crossing> last_prediction;
  /// "committed", "gave_up", "moved" (moved towards a prediction, never committed) or "no_target".
  std::string decision = "no_target";
  double t_first_move = -1.0,  ///< s, the planner's first move towards a prediction (-1: none)
         t_commit = -1.0,      ///< s, the commitment (-1: none)
         t_give_up = -1.0;     ///< s, the give-up decision (-1: none)
  /// The hole centre at the target's crossing time (robot's actual position, m, world); empty when
  /// the footage ended before it.
  std::optional<Eigen::Vector3d> hole_at_crossing;
};

/// What one camera of a multi-camera footage session gave (ball catching's, dart's).
struct FootageCamera {
  std::string name;         ///< the rig's camera name
  std::string source;       ///< describeSource()
  std::uint64_t frames = 0,      ///< frames handed out
                lost = 0,        ///< grabs that lost their frame
                detections = 0;  ///< frames the ball (or the dart's marker) was detected in
};

/// What one camera of a ball-catching footage session gave.
using CatchFootageCamera = FootageCamera;

/// What a multi-camera footage session (ball catching, dart) knows without truth: its cameras and
/// the tracker's counts; each scenario's summary adds its own.
struct FootageSessionCounts {
  std::uint64_t seed = 0;  ///< the seed (added pixel noise, injected faults)
  std::vector<FootageCamera> cameras;  ///< per active camera, in the rig's order
  double t_first = 0.0,  ///< s, first frame's stamp
         t_last = 0.0;   ///< s, last frame's stamp
  std::uint64_t frames = 0,      ///< frames over the cameras
                detections = 0,  ///< detections over the cameras
                fused = 0,       ///< detections the tracker fused
                gated = 0,       ///< detections its gate rejected
                refused = 0;     ///< detections the tracker refused (tracking::Refusal: stamp, pixel, duplicate)
  int tracks_started = 0;  ///< tracks the tracker started (a restart after rejections is the same track)
};

/// The opening lines of a multi-camera footage session's console summary (ball catching, dart):
/// the session (stamps, frames, detections), one line per camera, the tracker's counts.
std::string footageSessionText(const std::string& scenario, const FootageSessionCounts& session);

/// A footage summary's common keys: scenario, mode, seed, cameras (name, source, frames, lost and
/// detections per camera), the stamps' span and the tracker's counts.
nlohmann::json footageSessionJson(const std::string& scenario, const FootageSessionCounts& session);

/// A footage summary's live lines (runtime::summaryLine, runtime::processingLine; indented, one
/// per line); empty when the session ran on no live source.
std::string footageLiveText(const std::optional<runtime::LiveReport>& live);

/// The summary of a footage session (footage.h): what is known without truth.
struct CatchFootageSummary : FootageSessionCounts {
  std::vector<CatchFootageTrack> tracks;  ///< the tracks that reached the planner, in order
  std::size_t commands = 0,           ///< set points streamed to the robot
              limit_violations = 0,   ///< set points over the velocity or acceleration limits
              refused_setpoints = 0;  ///< set points refused (outside the workspace, no IK)
  double max_speed = 0.0,         ///< largest set-point speed, m/s
         max_acceleration = 0.0;  ///< largest set-point acceleration, m/s²
  std::optional<runtime::LiveReport> live;  ///< processing times and misses on a live source
  runtime::FaultReport faults;  ///< injected faults (empty without)
  double wall_s = 0.0;  ///< wall-clock time of the session, s
};

/// Runs the session over the footage of cfg's active cameras (cfg.onFootage(); the header
/// comment). `hooks`: on_frame (live view; CatchFrame::throw_index 0), telemetry (sink 0) and
/// progress are used; record_dir and replay_dir are refused (core::InvalidInput). `clock`: the
/// wall clock of paced footage and of the processing timer (null: the steady clock). Throws
/// core::InvalidInput naming the file or device a source cannot open or read.
CatchFootageSummary runCatchFootage(const BallCatchingConfig& cfg, std::uint64_t seed, const CatchHooks& hooks = {},
                                    runtime::WallClock* clock = nullptr);

/// The same session over the frames of one throw of a viewline recording (`dir` = DIR/throw_iii of
/// ball_catching --record DIR, or a rig's own recording of its cameras in one index, camera k being
/// the rig's active camera k; runtime/recording.h): the frames, stamps and lost grabs as recorded,
/// no truth read (throw.json and truth.csv are not opened). The estimators' cameras are the rig's
/// calibration as on footage. What the tuning tool's `--recording` runs. Throws core::InvalidInput
/// naming the folder when it is not a recording, holds no frame or more cameras than the config's
/// active ones, and for record_dir or replay_dir in `hooks`.
CatchFootageSummary runCatchFootageOnRecording(const BallCatchingConfig& cfg, std::uint64_t seed, const std::string& dir,
                                               const CatchHooks& hooks = {});

/// The summary as JSON ("truth": not scored; "registration": off on footage).
nlohmann::json footageSummaryJson(const CatchFootageSummary& s, const BallCatchingConfig& cfg);

/// The console summary (says "not scored: no truth" where a simulated run gives its catch rate).
std::string footageSummaryText(const CatchFootageSummary& s, const BallCatchingConfig& cfg);

}  // namespace viewline::scenarios
