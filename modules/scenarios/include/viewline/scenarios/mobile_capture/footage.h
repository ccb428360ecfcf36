#pragma once
// Mobile capture on footage: the head camera's frames come from a file or a live camera
// (`source: {kind: images | video | v4l2, ...}`, runtime::makeFrameSource) while the robot stays
// simulated.
//
// The model: a fixed camera. Footage cannot follow the robot (the frames show what the real camera
// saw, wherever the simulated base would have driven), so the base and the pan/tilt head are held
// at their start pose (world.robot_start, world.robot_heading_deg, the head pointed 2 m ahead as at
// the start of a simulated run, RobotSim) and the camera's pose is known from it: every detection
// is localised on the floor through that pose (the estimators' camera, the rig's calibration) and
// tracked by the scenario's unicycle EKF, exactly as in the simulated loop. The planner still plans
// the capture from the held pose every frame, and every control period the base's (v, ω) and the
// head's set point are computed by the same laws (goToPoint towards the capture point, the head
// towards the prediction, the search when the target is lost), checked against the robot's limits
// and counted, but not executed: a base that moved would make the known camera pose false.
//
// There is no truth: no grasp, no oracle, no capture time. The run is ONE session to the footage's
// end (or a stop request), and its summary gives what is known without truth: frames, detections,
// the object's tracked ground position and speed (the last one; per frame in --log footage.csv),
// the planner's intercept estimate, the commands and their limit violations, and on a live source
// (V4L2, or footage with pace: true) the processing times and deadline misses. The capture time and
// rate are "not scored: no truth" (text) and null (JSON).
//
// Frames must be colour (8-bit BGR: the detector segments red) and of the estimators' camera
// size; their stamps are the footage's own (a stamps file, the container's times or the driver's).

#include <Eigen/Core>
#include <cstdint>
#include <limits>
#include <nlohmann/json.hpp>
#include <optional>
#include <string>
#include <vector>

#include "viewline/io/log.h"
#include "viewline/robots/differential_drive.h"
#include "viewline/robots/mobile_pan_tilt.h"
#include "viewline/runtime/faults.h"
#include "viewline/runtime/live.h"
#include "viewline/scenarios/mobile_capture/config.h"
#include "viewline/scenarios/mobile_capture/loop.h"
#include "viewline/tracking/track_gate.h"

namespace viewline::scenarios {

/// One frame of a footage session (a row of --log footage.csv). NaN where there is nothing.
struct MobileFootageSample {
  double t = 0.0;              ///< s, the frame's stamp
  std::uint64_t sequence = 0;  ///< the source's frame counter
  bool detected = false;       ///< the detector found the object and its floor point exists
  bool fused = false;          ///< the floor point went into the track (Start or Accept)
  /// m, the detection back-projected onto the plane z = object_height / 2 (world floor frame).
  Eigen::Vector2d measured = Eigen::Vector2d::Constant(std::numeric_limits<double>::quiet_NaN());
  bool track_valid = false;  ///< a track exists after this frame
  /// m, the tracked ground position at t (world floor frame).
  Eigen::Vector2d position = Eigen::Vector2d::Constant(std::numeric_limits<double>::quiet_NaN());
  double speed = std::numeric_limits<double>::quiet_NaN(),      ///< m/s, tracked speed v
         heading = std::numeric_limits<double>::quiet_NaN(),    ///< rad, tracked heading θ
         turn_rate = std::numeric_limits<double>::quiet_NaN();  ///< rad/s, tracked turn rate ω
  bool reachable = false;  ///< the planner's capture point is reachable in time from the held pose
  /// m, the planner's capture (intercept) point (world floor frame).
  Eigen::Vector2d intercept = Eigen::Vector2d::Constant(std::numeric_limits<double>::quiet_NaN());
  double intercept_time = std::numeric_limits<double>::quiet_NaN();  ///< s, footage stamp of the intercept (t + m* T)
};

/// The summary of a footage session (footage.h): what is known without truth.
struct MobileFootageSummary {
  std::uint64_t seed = 0;   ///< the seed (injected faults only: footage has no random draw)
  std::string source;       ///< the source as named in messages, e.g. "images seq/image.%04d.png"
  double t_first = 0.0,     ///< s, first frame's stamp
         t_last = 0.0;      ///< s, last frame's stamp
  std::uint64_t frames = 0,      ///< frames handed out by the source
                lost = 0,        ///< grabs that lost their frame
                detections = 0;  ///< frames with a detection on the floor
  tracking::GateCounts gate;     ///< the track's gate decisions
  std::vector<MobileFootageSample> samples;  ///< every processed frame, in order
  robots::BasePose robot;        ///< the held base pose (x, y m; θ rad; world floor frame)
  robots::PanTiltJoints head;    ///< the held head joints (tilt, pan), rad
  std::uint64_t base_commands = 0,  ///< base (v, ω) commands computed (one per control period), not executed
                head_commands = 0;  ///< head set points computed (one per control period), not executed
  std::uint64_t limit_violations = 0;  ///< commands outside the base's speed / turn-rate or the head's joint limits
  double max_speed = 0.0,      ///< m/s, largest |v| commanded
         max_turn_rate = 0.0;  ///< rad/s, largest |ω| commanded
  std::optional<runtime::LiveReport> live;  ///< processing times and misses on a live source
  runtime::FaultReport faults;  ///< injected faults (empty without)
  bool interrupted = false;     ///< a stop request (signal, the view's quit) ended the session before the footage's end
  double wall_s = 0.0;          ///< wall-clock time of the session, s
};

/// Runs the session over cfg.source's footage (images, video or v4l2; the header comment).
/// `clock`: the wall clock of paced footage and of the processing timer (null: the steady clock).
/// `hooks`: on_frame (a live view: MobileCaptureFrame with the held robot and joints; there is no
/// truth, so object_true is the tracked position, or the last measured one before a track) and
/// quit_requested (polled after each frame: true ends the session, `interrupted`) are used;
/// telemetry, pacing, record_dir and replay_dir are refused (core::InvalidInput).
/// Throws core::InvalidInput naming the file or device a source cannot open or read, or a frame
/// that is not a colour image of the camera's size.
MobileFootageSummary runMobileCaptureFootage(const MobileCaptureConfig& cfg, std::uint64_t seed,
                                             runtime::WallClock* clock = nullptr,
                                             const MobileCaptureHooks* hooks = nullptr);

/// True when cfg.source is footage (images, video or v4l2), which runMobileCaptureFootage() runs.
bool mobileCaptureOnFootage(const MobileCaptureConfig& cfg);

/// The per-frame rows as footage.csv in `log` (t, detection, tracked state, intercept).
void logFootage(const MobileFootageSummary& s, io::LogDirectory& log);

/// The summary as JSON (capture figures null: not scored, no truth).
nlohmann::json footageSummaryJson(const MobileFootageSummary& s, const MobileCaptureConfig& cfg);

/// The console summary (says "not scored: no truth" where a simulated batch gives its capture figures).
std::string footageSummaryText(const MobileFootageSummary& s, const MobileCaptureConfig& cfg);

}  // namespace viewline::scenarios
