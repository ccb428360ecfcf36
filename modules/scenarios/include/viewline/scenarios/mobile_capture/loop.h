#pragma once
// Mobile capture: one chase on the scenario runtime (the loop is described in
// viewline/scenarios/mobile_capture.h) and the oracle that chases the same object path.

#include <Eigen/Core>
#include <cstdint>
#include <functional>
#include <limits>
#include <opencv2/core.hpp>
#include <vector>

#include "viewline/runtime/scheduler.h"
#include "viewline/runtime/telemetry.h"
#include "viewline/scenarios/mobile_capture/config.h"
#include "viewline/tracking/track_gate.h"

namespace viewline::scenarios {

/// Ground-localisation error accumulator (squared errors against truth, m²).
struct LocalizationErrors {
  double sse_exact = 0.0,       ///< exact back-projection onto the floor
         sse_printed = 0.0,     ///< [K]'s angle-per-pixel method as printed
         sse_horizontal = 0.0;  ///< [K]'s method with horizontal angles
  long count = 0;  ///< points accumulated
  /// Adds another accumulator's sums.
  void add(const LocalizationErrors& o) {
    sse_exact += o.sse_exact, sse_printed += o.sse_printed, sse_horizontal += o.sse_horizontal, count += o.count;
  }
};

/// What a display or the tuning tool sees at each vision step (our run only).
struct MobileCaptureFrame {
  double t = 0.0;                           ///< capture time, s
  const cv::Mat* image = nullptr;           ///< rendered camera image (BGR)
  bool detected = false;                    ///< the object was detected
  Eigen::Vector2d pixel = Eigen::Vector2d::Zero();  ///< detected blob centre, px
  robots::BasePose robot;                   ///< true base pose (x, y, θ), floor frame
  robots::PanTiltJoints joints;             ///< head joints (tilt, pan), rad
  Eigen::Vector2d object_true = Eigen::Vector2d::Zero();  ///< true object position on the floor, m
  bool fused = false;  ///< this frame's measurement is in the track (Start or Accept)
  /// NIS of this frame's measurement from the track's update report (2 dof, S = R + P_pos),
  /// fused or gated out; NaN without a measurement or without a live track to test it against.
  double nis = std::numeric_limits<double>::quiet_NaN();
  bool estimate_valid = false;              ///< a live track gives `estimate`
  Eigen::VectorXd estimate;                 ///< (x, y, θ, v, ω)
  std::vector<Eigen::Vector2d> prediction;  ///< p(k+1..k+M)
  planning::CapturePlan plan;               ///< the planner's current plan
  control::SearchMode mode = control::SearchMode::Tracking;  ///< tracking, lost or searching
};

/// Telemetry channels of a run (runtime::TelemetrySink records).
namespace mobile_capture::channel {
inline constexpr const char* kPixel = "pixel";            ///< measurement: blob centre (u, v), px
inline constexpr const char* kFloor = "floor";            ///< measurement: exact floor point (x, y), m
/// measurement: [K]'s angle-per-pixel floor points (printed x, y, horizontal x, y), m (NaN: none)
inline constexpr const char* kFloorAnglePerPixel = "floor_angle_per_pixel";
inline constexpr const char* kObject = "object";          ///< innovations and estimates (x, y, θ, v, ω) of the track
inline constexpr const char* kTruthObject = "truth_object";  ///< estimate record: true (x, y, θ, v, ω)
inline constexpr const char* kTruthRobot = "truth_robot";    ///< estimate record: (x, y, θ, tilt, pan)
inline constexpr const char* kPlan = "plan";              ///< command: (reachable, steps, capture x, y, mode)
inline constexpr const char* kBase = "base";              ///< command: (v, ω) every control period
inline constexpr const char* kHead = "head";              ///< command: head set point (tilt, pan)
}  // namespace mobile_capture::channel

/// Optional hooks of a mobile-capture run: per-frame view, telemetry, pacing and quit.
struct MobileCaptureHooks {
  std::function<void(const MobileCaptureFrame&)> on_frame;  ///< after every vision step
  runtime::TelemetrySink* telemetry = nullptr;              ///< records of the run (none: nothing built)
  runtime::Pacing pacing;                                   ///< wall-clock pacing (a display: 1)
  std::function<bool()> quit_requested;                     ///< polled after each frame: true ends the run
};

/// One run's result: capture and its time, the oracle's, detections, localisation errors, gate decisions.
struct MobileCaptureRun {
  std::uint64_t seed = 0;  ///< seed of the run
  bool captured = false;   ///< the object was grasped before max_time
  double capture_time = 0.0;           ///< s (max_time when not captured)
  bool oracle_captured = false;        ///< the oracle (planner fed the true path) captured it
  double oracle_time = 0.0;            ///< the oracle's capture time, s
  int grasp_attempts = 0;              ///< including the successful one
  int frames = 0,      ///< vision frames
      detections = 0;  ///< frames with the object detected
  double longest_lost = 0.0;           ///< s, longest gap between detections after the first one
  LocalizationErrors localization;    ///< ground-localisation errors of the detections
  tracking::GateCounts gate;           ///< the track's gate decisions
};

/// One run of our loop and of the oracle with the same object path (seed).
MobileCaptureRun runMobileCapture(const MobileCaptureConfig& cfg, std::uint64_t seed,
                                  const MobileCaptureHooks* hooks = nullptr);

/// The oracle alone: capture time of the planner fed the true path.
struct OracleResult {
  bool captured = false;  ///< captured before max_time
  double time = 0.0;      ///< capture time, s
};
OracleResult runOracle(const MobileCaptureConfig& cfg, std::uint64_t seed);

}  // namespace viewline::scenarios
