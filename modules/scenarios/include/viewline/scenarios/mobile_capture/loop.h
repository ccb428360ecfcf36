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
  double sse_exact = 0.0, sse_printed = 0.0, sse_horizontal = 0.0;
  long count = 0;
  void add(const LocalizationErrors& o) {
    sse_exact += o.sse_exact, sse_printed += o.sse_printed, sse_horizontal += o.sse_horizontal, count += o.count;
  }
};

/// What a display or the tuning tool sees at each vision step (our run only).
struct MobileCaptureFrame {
  double t = 0.0;
  const cv::Mat* image = nullptr;           ///< rendered camera image (BGR)
  bool detected = false;
  Eigen::Vector2d pixel = Eigen::Vector2d::Zero();
  robots::BasePose robot;
  robots::PanTiltJoints joints;
  Eigen::Vector2d object_true = Eigen::Vector2d::Zero();
  bool fused = false;  ///< this frame's measurement is in the track (Start or Accept)
  /// NIS of this frame's measurement from the track's update report (2 dof, S = R + P_pos),
  /// fused or gated out; NaN without a measurement or without a live track to test it against.
  double nis = std::numeric_limits<double>::quiet_NaN();
  bool estimate_valid = false;
  Eigen::VectorXd estimate;                 ///< (x, y, θ, v, ω)
  std::vector<Eigen::Vector2d> prediction;  ///< p(k+1..k+M)
  planning::CapturePlan plan;
  control::SearchMode mode = control::SearchMode::Tracking;
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

struct MobileCaptureHooks {
  std::function<void(const MobileCaptureFrame&)> on_frame;  ///< after every vision step
  runtime::TelemetrySink* telemetry = nullptr;              ///< records of the run (none: nothing built)
  runtime::Pacing pacing;                                   ///< wall-clock pacing (a display: 1)
  std::function<bool()> quit_requested;                     ///< polled after each frame: true ends the run
};

struct MobileCaptureRun {
  std::uint64_t seed = 0;
  bool captured = false;
  double capture_time = 0.0;           ///< s (max_time when not captured)
  bool oracle_captured = false;
  double oracle_time = 0.0;
  int grasp_attempts = 0;              ///< including the successful one
  int frames = 0, detections = 0;
  double longest_lost = 0.0;           ///< s, longest gap between detections after the first one
  LocalizationErrors localization;
  tracking::GateCounts gate;           ///< the track's gate decisions
};

/// One run of our loop and of the oracle with the same object path (seed).
MobileCaptureRun runMobileCapture(const MobileCaptureConfig& cfg, std::uint64_t seed,
                                  const MobileCaptureHooks* hooks = nullptr);

/// The oracle alone: capture time of the planner fed the true path.
struct OracleResult {
  bool captured = false;
  double time = 0.0;
};
OracleResult runOracle(const MobileCaptureConfig& cfg, std::uint64_t seed);

}  // namespace viewline::scenarios
