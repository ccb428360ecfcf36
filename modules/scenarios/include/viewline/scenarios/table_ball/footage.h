#pragma once
// Table-ball balancing on footage: the head camera's frames come from an image sequence, a video
// file or a live V4L2 camera (`source: {kind: images|video|v4l2, ...}`, runtime/source_config.h,
// opened by runtime::makeFrameSource), and the loop runs on them as it would on a real rig.
//
// There is no simulated table behind the frames, so nothing is scored against a truth: the run
// is ONE session over the footage, ending when the footage ends. Every frame goes through the
// same observer as a simulated run (table pose from the image, ball on the table, the
// rolling-ball filter; observer.h), and the controller computes its tilt ramp from the estimate
// as in the closed loop (loop.h): the ramp goes down the same delay line to the SIMULATED wrist
// (robots::SimulatedTableTilt behind WristLink: its angle and rate limits, its delay), commanded
// at 1 kHz on the footage's clock. The footage does not move with that wrist.
//
// What the observer needs besides the image, and where it comes from on footage:
//  - the arm's tilt prior (the nominal table pose that resolves the square's quarter turns):
//    the simulated wrist's actual tilt at the frame, through the arm's kinematics
//    (TableBallWorld::tablePose);
//  - the head's pose (camera-to-ground rotation, the rest pose of the nominal table pose): the
//    calibrated rest pose (the rig's rig.yaml + ground.yaml, or the inline camera); footage
//    carries no measurement of the head's sway;
//  - the table pose filter (observer.h step 2b) fuses the PnP pose with the kinematic pose of
//    the table the wrist holds. The simulated wrist does not hold the footage's table, so that
//    kinematic pose is not the footage's: on footage the observer uses each frame's own PnP
//    pose (table_pose_time_constant 0, as [M]) whatever the config says. The filter's noise
//    (sigma_v, coloured_sigma) is tuned for the filtered pose, so the NIS on footage is larger.
//
// Reported (what can be known without truth): frames, lost frames, frames with the table and
// the ball found, the filter's mean NIS, the controller's ramps and the wrist's position
// commands, their limit violations (none: the ramps are planned within the limits), the largest
// commanded angle and rate, and on a live source (V4L2, or footage with pace: true) the
// processing times and deadline misses (runtime::LiveReport; each frame timed from its grab to
// the ramp it led to, against one frame period of camera.rate_hz). Observer RMSE, settling,
// overshoot and push recovery: "not scored: no truth" in the text, null in the JSON. Set points
// (events.setpoints) are taken on the footage's clock from its first frame; pushes are physics
// of the simulated table and do nothing here.

#include <cstdint>
#include <cstdio>
#include <nlohmann/json.hpp>
#include <optional>
#include <string>

#include "viewline/runtime/faults.h"
#include "viewline/runtime/live.h"
#include "viewline/scenarios/table_ball/config.h"
#include "viewline/scenarios/table_ball/loop.h"

namespace viewline::scenarios {

/// The summary of a footage session (footage.h): what is known without truth.
struct TableBallFootageSummary {
  std::uint64_t seed = 0;  ///< the seed (injected faults)
  std::string source;      ///< the source: "images <pattern>", "video <path>" or "v4l2 <device>"
  double t_first = 0.0,    ///< s, stamp of the first frame
         t_last = 0.0;     ///< s, stamp of the last frame
  std::uint64_t frames = 0,        ///< frames the source handed out
                lost = 0,          ///< grabs that lost their frame (nothing to stamp it: no step)
                skipped = 0,       ///< frames not processed (late, frozen, or a stamp not after the last)
                table_found = 0,   ///< frames in which the table pose was measured
                ball_found = 0,    ///< frames in which the ball's position on the table was measured
                tracked = 0;       ///< frames measured by the fast path (edge tracking)
  double nis_mean = 0.0;           ///< mean NIS of the ball updates after metrics.warmup (2 dof); NaN: none
  std::uint64_t nis_count = 0;     ///< updates in that mean
  std::uint64_t ramps = 0,         ///< tilt ramps the controller sent to the wrist
                wrist_commands = 0,    ///< position commands sent to the simulated wrist (1 kHz)
                limit_violations = 0;  ///< commands outside the wrist's angle or rate limits
  double max_commanded_angle_deg = 0.0,   ///< largest |tilt| commanded on either axis, degrees
         max_commanded_rate_deg_s = 0.0;  ///< largest commanded tilt rate, degrees/s
  std::optional<runtime::LiveReport> live;  ///< processing times and misses on a live source
  runtime::FaultReport faults;  ///< injected faults (empty without)
  bool stopped_early = false;   ///< stopped before the footage ended (a display's quit key, a signal)
  double wall_s = 0.0;          ///< wall-clock time of the session, s
};

/// "images <pattern>", "video <path>", "v4l2 <device>": the footage named for messages.
std::string tableBallFootageName(const runtime::SourceConfig& source);

/// Runs the session over cfg.source's footage (cfg.onFootage(); the header comment). `hooks`:
/// on_frame (TableBallFrameView: truth NaN, tilt the simulated wrist's), on_progress (seconds
/// of footage from its first stamp; the total is NaN) and telemetry (footage stamps) are used;
/// record_dir, replay_dir and pacing are refused (core::InvalidInput: footage is recorded
/// already and is paced by its source, source.pace). `clock`: the wall clock of paced footage
/// and of the processing timer (null: the steady clock). Throws core::InvalidInput naming the
/// file or device that cannot be opened or read, or a frame that is not a colour image of the
/// camera's calibrated size.
TableBallFootageSummary runTableBallFootage(const TableBallConfig& config, std::uint64_t seed,
                                            const TableBallHooks& hooks = {}, runtime::WallClock* clock = nullptr);

/// The same session over the head camera's frames of a viewline recording folder (DIR of
/// table_ball_balancing --record DIR, or a rig's own; runtime/recording.h), whatever cfg.source
/// says: the frames, their stamps and lost grabs as recorded, no truth read (a simulated run's
/// table and ball are not in the folder). What the tuning tool's `--recording` runs (each frame
/// through the observer as on footage). Throws core::InvalidInput naming the folder when it is
/// not a recording, holds more than one camera or no frame, and for the hooks refused above.
TableBallFootageSummary runTableBallOnRecording(const TableBallConfig& config, std::uint64_t seed,
                                                const std::string& dir, const TableBallHooks& hooks = {});

/// The summary as JSON ("mode": "footage"; the truth-scored figures null, "truth": not scored).
nlohmann::json toJson(const TableBallFootageSummary& s);

/// The summary a person reads (says "not scored: no truth" where a simulated run gives its errors).
void printTableBallFootageSummary(std::FILE* out, const TableBallFootageSummary& s, const TableBallConfig& config);

}  // namespace viewline::scenarios
