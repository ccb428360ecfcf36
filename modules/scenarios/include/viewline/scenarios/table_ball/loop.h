#pragma once
// The table-ball closed loop on one runtime::Scheduler (timing in table_ball.h):
//
//   physics tick     every 1 ms at k · kTick: the wrist takes the interpolated ramp command
//                    (through WristLink: a robot fault makes it hold its tilt, the loop then
//                    holds its command and drops the ramps planned before), the table and ball
//                    advance one tick
//   frame ready      capture_time + exposure / 2 (RenderedHeadCamera): detection, observer,
//                    side filters, metrics, controller; the new tilt ramp goes down a
//                    DelayLine to the arm, available at capture_time + latency. After a failed
//                    wrist command the controller's model takes the held tilt
//                    (TableBalancer::hold); while the wrist does not answer it is not stepped
//
// At equal times a frame runs before a physics tick: the frame shows the world up to its ready
// time, and a tick starting there simulates what comes after.

#include <cstdint>
#include <functional>
#include <string>

#include "viewline/core/camera.h"
#include "viewline/runtime/scheduler.h"
#include "viewline/runtime/telemetry.h"
#include "viewline/scenarios/table_ball/config.h"
#include "viewline/scenarios/table_ball/metrics.h"
#include "viewline/scenarios/table_ball/observer.h"

namespace viewline::scenarios {

/// Everything a viewer needs about one processed frame.
struct TableBallFrameView {
  const cv::Mat* image = nullptr;        ///< the camera image (null for a dropped frame)
  const core::Camera* camera = nullptr;  ///< the observer's camera at capture (calibrated with a rig)
  const ObserverFrame* observer = nullptr;  ///< what the observer made of the frame (detections, estimate)
  Eigen::Vector2d truth = Eigen::Vector2d::Zero();     ///< true ball position, m (table frame)
  Eigen::Vector2d setpoint = Eigen::Vector2d::Zero();  ///< set point in force, m (table frame)
  Eigen::Vector2d tilt = Eigen::Vector2d::Zero();  ///< true table tilt
};

/// Optional observers of a run: live frames, progress, telemetry and pacing.
struct TableBallHooks {
  /// Called after every frame (e.g. a display); returning false stops the run (quit key).
  std::function<bool(const TableBallFrameView&)> on_frame;
  /// Simulated time and duration, about once per simulated second.
  std::function<void(double t, double duration)> on_progress;
  /// Receives the run's records when non-null (channels: measurements "ball" (table frame, m),
  /// "table_tilt" (rad), "ball_acceleration" (the filter's input a_xy, m/s², every frame);
  /// innovations "ball"; estimates "ball" (x, P), "ball_prediction" (the N-th predicted
  /// position), "truth" (p, v, tilt at the capture instant) and one per side filter; commands
  /// "setpoint", "tilt_ramp" (start θ, rate θ̇, from the controller) and "wrist" (the
  /// interpolated position command, every 5th tick)).
  runtime::TelemetrySink* telemetry = nullptr;
  /// Wall-clock pacing (0: as fast as possible); results do not depend on it.
  runtime::Pacing pacing;
  /// Record the head camera's frames (lost ones with their times) and the config to this folder
  /// (runtime::RecordingWriter; "" : none).
  std::string record_dir;
  /// Run on the frames recorded in this folder instead of config.source (same config and seed:
  /// the same run; the truth is the simulated table's, which the replay reproduces).
  std::string replay_dir;
  std::string config_text;  ///< the config as run (YAML), written into a recording
};

/// Runs the closed loop for `config.duration` seconds with all randomness from `seed`. The
/// config must be valid (tableBallConfigFromYaml validates it; code editing a config calls
/// validate()).
TableBallResult runTableBall(const TableBallConfig& config, std::uint64_t seed, const TableBallHooks& hooks = {});

}  // namespace viewline::scenarios
