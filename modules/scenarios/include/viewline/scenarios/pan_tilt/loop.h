#pragma once
// The pan-tilt closed loop ([T]) on the scenario runtime: one scheduler orders every event, the
// camera frames come from a runtime::FrameSource (the renderer over the simulated world), and
// the loop only wires the detector, the controller and the unit.
//
// One frame k (capture time t_k = k / fps), two events:
//   capture (at the end of the frame's exposure):
//     1. grab the frame; detect with [T]'s pipeline (vision::ScreenTargetDetector: crop,
//        resize 50 %, binarise, median, centroid);
//     2. back-project the centroid through the capture-time camera onto the screen plane -> m_k
//        (screen coordinates, m): the camera the controllers believe in (calibrated intrinsics and
//        mount) at the encoder reading of the capture stamp;
//     3. add [T]'s measurement noise: m̃_k = m_k + n_k (pan_tilt::World); the noisy feature s̃_k
//        is m̃_k projected into the capture-time camera;
//     4. the observation (s̃_k, m̃_k, diag(σx², σy²)) stamped t_k enters a runtime::DelayLine that
//        delivers it after the processing delay;
//   control (at t_k + processing_delay): the controller takes the delivered observation and issues
//     a joint velocity command to the unit, which applies it after the unit's own latency
//     (robots::SimulatedPanTiltUnit); the commands still in flight go to the law (its prediction of
//     the joints at the effect time).
// processing_delay < 1/fps (validated), so every frame's command precedes the next capture: the
// order of all stateful calls is that of one frame after the other.
//
// Frames: the renderer over the simulated world by default; config.source (or PanTiltRunIo::
// replay_dir) selects another runtime::FrameSource. The simulated unit, the [T] noise draws and the
// controllers are the same whatever the source. Truth comes from the renderer or from a
// recording's truth.csv; without it the truth figures are NaN and the metrics say "not scored".
// A live source (a V4L2 camera, footage with source.pace; runtime/live.h) runs at its own pace:
// the frames it delivered while the loop was busy are dropped and counted, and each frame's
// processing (grab to command, without the wait for the control event) is timed against a
// deadline of one frame period (1 / fps); the metrics' `live` report holds both.
//
// Reports: generic telemetry records (measurement and truth per frame, the innovation with the
// filter's NIS and gate decision, the estimate, the command) to a runtime::TelemetrySink, and one
// pan_tilt::FrameRecord per frame (display, frames CSV) to a pan_tilt::FrameSink.

#include <cstdint>
#include <functional>
#include <optional>
#include <string>
#include <vector>

#include <Eigen/Geometry>

#include "viewline/core/camera.h"
#include "viewline/runtime/scheduler.h"
#include "viewline/runtime/telemetry.h"
#include "viewline/scenarios/pan_tilt/config.h"
#include "viewline/scenarios/pan_tilt/metrics.h"
#include "viewline/scenarios/pan_tilt/telemetry.h"

namespace viewline::scenarios {

/// Which law closes the loop: ours ([T]'s predictive controller) or ViSP's visual servo.
enum class PanTiltControllerKind {
  Predictive,  ///< the predictive controller (filter, delay compensation, reacquisition)
  Baseline     ///< ViSP's image-based visual servo (control.servo), the comparison
};

/// Where a run reports, and how it relates to the wall clock.
struct PanTiltRunIo {
  runtime::TelemetrySink* telemetry = nullptr;  ///< generic records; null: none (nothing is computed for them)
  pan_tilt::FrameSink* frames = nullptr;        ///< per-frame records; null: none
  runtime::Pacing pacing;                       ///< as fast as possible by default
  std::function<void(double)> progress;         ///< fraction of the run done
  /// Record each run's frames, truth, camera and unit readings (ptu.csv, ptuTableColumns()) to
  /// record_dir/CONTROLLER, CONTROLLER the law's name (runtime::RecordingWriter; "" : none).
  std::string record_dir;
  /// Run on the frames recorded in replay_dir/CONTROLLER instead of the config's source: with the
  /// same config and seed the run, and its summary, are those of the recorded run ("" : none).
  std::string replay_dir;
  std::string config_text;  ///< the config as run (YAML), written into a recording
  /// The wall clock of a live source (paced footage) and of its processing times (null: the
  /// steady clock; a test passes a clock it advances itself).
  runtime::WallClock* clock = nullptr;
};

/// Telemetry channels of a run of `controller`: the target's measurements, innovations, estimates
/// and the commands on `controller`; the truth on `controller`_truth; the image error (px) as a
/// scalar on `controller`_image_error_px. Measurement and innovation ids are the frame index + 1.
std::string truthChannel(const std::string& controller);
/// The scalar channel of the image error (px) of `controller`'s run.
std::string imageErrorChannel(const std::string& controller);

/// Name of a pan-tilt recording's per-frame table of what the measurement used besides the frame.
inline const char* const kPtuTable = "ptu";
/// Its columns (after camera,sequence): the unit's joint reading that back-projected the frame's
/// detection (its time s, pan and tilt rad), [T]'s noise draw added to the measurement (m), and the
/// measurement covariance R given to the filter (m², xx, xy, yy).
const std::vector<std::string>& ptuTableColumns();

/// A detection measured on the screen plane, [T]'s capture step.
struct ScreenMeasurement {
  Eigen::Vector2d plane = Eigen::Vector2d::Zero();     ///< on the screen plane with [T]'s noise added (m)
  Eigen::Vector3d in_camera = Eigen::Vector3d::Zero();  ///< that point in the camera frame (m)
};
/// The ray through pixel `px` of `cam` (its c_M_w the camera at the joint reading, frame f) cut with
/// the screen plane z_screen = 0 (`f_M_screen`), plus `noise` (m, screen plane). Empty when the ray
/// does not meet the plane in front of it. The loop and the tuning replay of a recording share it.
std::optional<ScreenMeasurement> measureOnScreen(const core::Camera& cam, const Eigen::Vector2d& px,
                                                 const Eigen::Isometry3d& f_M_screen, const Eigen::Vector2d& noise);

/// Runs one controller on the scenario; deterministic for (config, seed) whatever the pacing and
/// the sinks: both controllers see the same path, sensor noise stream and [T] noise draws for the
/// same frame index.
PanTiltRunMetrics runPanTilt(const PanTiltScenarioConfig& config, std::uint64_t seed, PanTiltControllerKind kind,
                             const PanTiltRunIo& io = {});

/// Ours, then (when config.run_baseline) ViSP's law on the same seed (not after a quit).
PanTiltComparison runPanTiltComparison(const PanTiltScenarioConfig& config, std::uint64_t seed,
                                       const PanTiltRunIo& io = {});

}  // namespace viewline::scenarios
