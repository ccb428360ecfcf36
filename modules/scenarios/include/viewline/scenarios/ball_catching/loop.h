#pragma once
// Ball catching: the loop of one throw and of a session, on the scenario runtime.
//
// One throw (independent: its own seed deriveSeed(seed, i), its own cameras, clocks, scheduler):
//  1. draw the throw (world.h) and find its true crossing of the box plane;
//  2. free-running cameras render the ball and the box where the robot holds it: a
//     runtime::FrameSource (RigFrameSource over sim::CameraRig) whose next frame is ready at the
//     end of its exposure;
//  3. each image: the colour-blob detector (vision::BallDetector, window around the tracker's
//     predicted pixel) -> ImageMeasurement{stamp, pixel, σ_px} -> tracking::ViewlineTracker;
//     the estimate reaches the planner `processing_latency` after the capture (runtime::DelayLine);
//  4. every control period (a periodic event): the estimates that have arrived go to
//     planning::CatchPlanner::update (crossing prediction, replanning from the current set point,
//     commit / give up), then the planner's set point is streamed to the robot
//     (robots::SimulatedCartesianRobot: stage or vpViper850 arm, command latency, limits counted);
//  5. the outcome (metrics.h).
// One runtime::Scheduler orders the events: at equal times the control tick runs before the
// capture (priority Control < Capture), so the box is commanded up to the end of an exposure
// before that image is rendered. Batch runs go as fast as possible; hooks.pacing paces each
// throw to the wall clock (a live view), which changes when events run, never their order.
//
// Telemetry (hooks.telemetry, one sink per throw): measurements ("camera<i>": the detected pixel
// and its σ), innovations ("ball": the tracker's NIS and gate decision for each submitted image:
// Start for the seed of a track, Accept when fused, Reject when gated, Restart when the image
// restarted the track and was fused), estimates ("ball": x, P after each fused image; "crossing":
// the planner's predicted crossing (t, p) with blockdiag(var_t, cov_p) at each update; "truth":
// the true ball position at each capture showing it), commands ("setpoint": p, v at each tick).

#include <cstdint>
#include <functional>
#include <memory>
#include <optional>
#include <string>
#include <opencv2/core/mat.hpp>

#include "viewline/core/camera.h"
#include "viewline/planning/crossing.h"
#include "viewline/runtime/scheduler.h"
#include "viewline/runtime/telemetry.h"
#include "viewline/scenarios/ball_catching/config.h"
#include "viewline/scenarios/ball_catching/metrics.h"
#include "viewline/sim/scene.h"

namespace viewline::scenarios {

/// What a live view gets for every image.
struct CatchFrame {
  int throw_index = 0;     ///< index of the throw in runBallCatching()
  std::size_t camera = 0;  ///< index of the camera that took the image (config order)
  const core::Camera* camera_model = nullptr;   ///< what the estimator believes (calibrated with rig:)
  double t = 0.0;                               ///< s, capture stamp on the throw's clock (from 0)
  const cv::Mat* image = nullptr;               ///< the rendered BGR image; valid during the call only
  std::optional<Eigen::Vector2d> detection;     ///< detected ball pixel (u, v), px; empty: not found
  std::optional<planning::Crossing> crossing;   ///< planner's current target
  Eigen::Vector3d hole = Eigen::Vector3d::Zero();  ///< m, hole centre in the world frame (the robot's)
  std::optional<Eigen::Vector3d> estimate;      ///< tracker position
};

/// Optional observers of runBallCatching(): telemetry per throw, live view, progress, pacing.
struct CatchHooks {
  /// The telemetry sink of throw i, or null. Called once per throw, from the thread running it:
  /// with threads > 1 return a distinct sink per throw. The throw flushes it and drops its
  /// reference at its end (a CSV sink then closes its files).
  std::function<std::shared_ptr<runtime::TelemetrySink>(int throw_index)> telemetry;
  /// Live view of every image (the session then runs on one thread). Returning false stops the
  /// session: the throw under way is dropped, the throws done are summarised.
  std::function<bool(const CatchFrame&)> on_frame;
  /// Called after each finished throw with the throws done and the total (any thread).
  std::function<void(int done, int total)> progress;
  runtime::Pacing pacing;  ///< wall-clock pacing of every throw (0: as fast as possible)
  std::string record_dir;   ///< --record DIR: every throw's frames and truth (recording.h); "" : none
  std::string replay_dir;   ///< --replay DIR: the throws of a recording instead of the renderer (overrides `source:`)
  std::string config_text;  ///< the config as run, written into a recording (config.yaml)
};

/// The recording a session replays: hooks->replay_dir, else the config's `source:` folder, else "" (render).
std::string catchReplayRoot(const BallCatchingConfig& cfg, const CatchHooks* hooks);

/// A CatchHooks::telemetry that writes throw i's records as CSV (runtime::CsvSink: one file per
/// record kind and channel) into `dir/throw_iii/` (iii: the throw index, 3 digits; each throw has
/// its own clock, from 0).
std::function<std::shared_ptr<runtime::TelemetrySink>(int throw_index)> csvTelemetry(const std::string& dir);

/// One throw with its own seed. `interrupted` (optional) is set when hooks->on_frame stopped it.
ThrowResult runThrow(const BallCatchingConfig& cfg, const sim::Scene& room, int index, std::uint64_t seed,
                     const CatchHooks* hooks = nullptr, bool* interrupted = nullptr);

/// `throws` throws (throw i uses deriveSeed(seed, i)), in parallel over cfg.threads unless a live
/// view needs one thread; the results do not depend on the thread count nor on the pacing. With
/// registration.enabled the session first registers the cameras to the robot (seed
/// deriveSeed(seed, 0x4E6)). Validates cfg first (code may have edited a loaded config).
CatchSummary runBallCatching(const BallCatchingConfig& cfg, int throws, std::uint64_t seed,
                             const CatchHooks& hooks = {});

}  // namespace viewline::scenarios
