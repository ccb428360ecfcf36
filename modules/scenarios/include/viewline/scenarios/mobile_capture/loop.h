#pragma once
// Mobile capture: one chase on the scenario runtime (the loop is described in
// viewline/scenarios/mobile_capture.h) and the oracle that chases the same object path.

#include <Eigen/Core>
#include <cstdint>
#include <functional>
#include <limits>
#include <optional>
#include <string>
#include <opencv2/core.hpp>
#include <vector>

#include "viewline/runtime/scheduler.h"
#include "viewline/runtime/telemetry.h"
#include "viewline/scenarios/mobile_capture/config.h"
#include "viewline/scenarios/mobile_capture/world.h"
#include "viewline/tracking/track_gate.h"

namespace viewline::scenarios {

/// Ground-localisation error accumulator (squared errors against truth, m²).
struct LocalizationErrors {
  double sse_exact = 0.0,       ///< exact back-projection of the pixel onto the floor plane
         sse_printed = 0.0,     ///< [K]'s angle-per-pixel method, slant range as printed
         sse_horizontal = 0.0;  ///< the same with the corrected horizontal distance
  long count = 0;               ///< detections accumulated
  /// Accumulates another run's sums and count.
  void add(const LocalizationErrors& o) {
    sse_exact += o.sse_exact, sse_printed += o.sse_printed, sse_horizontal += o.sse_horizontal, count += o.count;
  }
};

/// What a display or the tuning tool sees at each vision step (our run only).
struct MobileCaptureFrame {
  double t = 0.0;                           ///< s, capture time of the frame
  const cv::Mat* image = nullptr;           ///< rendered camera image (BGR)
  bool detected = false;                    ///< the detector found the object
  Eigen::Vector2d pixel = Eigen::Vector2d::Zero();  ///< blob centre (u, v), px (when detected)
  robots::BasePose robot;                   ///< true base pose (x, y m; θ rad; world floor frame)
  robots::PanTiltJoints joints;             ///< head joints (tilt, pan), rad
  Eigen::Vector2d object_true = Eigen::Vector2d::Zero();  ///< true object position, m (world floor)
  bool fused = false;  ///< this frame's measurement is in the track (Start or Accept)
  /// The floor measurement of the detection with its white and bias parts (empty: none this frame).
  std::optional<mobile_capture::FloorMeasurement> measurement;
  /// m², bias covariance B of the latest detection: the object's position covariance is P_s + B.
  Eigen::Matrix2d bias_cov = Eigen::Matrix2d::Zero();
  /// NIS of this frame's measurement from the track's update report (2 dof, S = R + P_pos),
  /// fused or gated out; NaN without a measurement or without a live track to test it against.
  double nis = std::numeric_limits<double>::quiet_NaN();
  bool estimate_valid = false;              ///< the track exists (estimate and prediction are set)
  Eigen::VectorXd estimate;                 ///< (x, y, θ, v, ω)
  std::vector<Eigen::Vector2d> prediction;  ///< p(k+1..k+M)
  planning::CapturePlan plan;               ///< the planner's current capture plan
  control::SearchMode mode = control::SearchMode::Tracking;  ///< tracking, or which search phase
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

/// Optional observers of a run: live frames, telemetry, pacing and a quit request.
struct MobileCaptureHooks {
  std::function<void(const MobileCaptureFrame&)> on_frame;  ///< after every vision step
  runtime::TelemetrySink* telemetry = nullptr;              ///< records of the run (none: nothing built)
  runtime::Pacing pacing;                                   ///< wall-clock pacing (a display: 1)
  std::function<bool()> quit_requested;                     ///< polled after each frame: true ends the run
  /// Record the run's frames, head readings and truth into this new folder (recording.h); "": none.
  std::string record_dir;
  std::string replay_dir;  ///< run on the frames of this recorded run (recording.h) instead of the renderer; "" : render
};

/// One run's outcome, ours next to the oracle's on the same object path.
struct MobileCaptureRun {
  std::uint64_t seed = 0;              ///< the run's seed (object path, noise)
  bool captured = false;               ///< our loop grasped the object before max_time
  double capture_time = 0.0;           ///< s (max_time when not captured)
  bool oracle_captured = false;        ///< the oracle captured it before max_time
  double oracle_time = 0.0;            ///< s, the oracle's capture time (max_time when not captured)
  int grasp_attempts = 0;              ///< including the successful one
  int frames = 0,      ///< vision steps
      detections = 0;  ///< vision steps with a detection
  double longest_lost = 0.0;           ///< s, longest gap between detections after the first one
  LocalizationErrors localization;     ///< ground-localisation errors over the run's detections
  tracking::GateCounts gate;           ///< the track's gate decisions
  /// Consistency of the track once it has been valid for kConsistencySettle s: NIS (2 dof) of every
  /// tested detection, and position NEES (2 dof, e = p̂ − p against P_s + B) every kNeesSpacing s.
  double nis_sum = 0.0;
  long nis_count = 0;     ///< NIS samples in nis_sum
  double nees_sum = 0.0;  ///< Σ of the position NEES samples
  long nees_count = 0;    ///< NEES samples in nees_sum
  bool interrupted = false;            ///< a stop request (signal, closed view) ended the run early: not scored
  runtime::FaultReport faults;         ///< injected faults and what the loop did (empty without faults)
};

/// s a track must have been valid before its NIS and NEES samples count (the two-point start's
/// prior still dominates before).
inline constexpr double kConsistencySettle = 2.0;
/// s between position NEES samples of a run (errors of one track are correlated over time).
inline constexpr double kNeesSpacing = 1.0;

/// One run of our loop and of the oracle with the same object path (seed). A stop request
/// (core::interruptRequested(), the view's quit) ends it early with `interrupted` set and no oracle run.
MobileCaptureRun runMobileCapture(const MobileCaptureConfig& cfg, std::uint64_t seed,
                                  const MobileCaptureHooks* hooks = nullptr);

/// The oracle alone: capture time of the planner fed the true path.
struct OracleResult {
  bool captured = false;  ///< captured before max_time
  double time = 0.0;      ///< s, capture time (max_time when not captured)
};
/// Runs the oracle on the object path of `seed` (the same path runMobileCapture() chases).
OracleResult runOracle(const MobileCaptureConfig& cfg, std::uint64_t seed);

}  // namespace viewline::scenarios
