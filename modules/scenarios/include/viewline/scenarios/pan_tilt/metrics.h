#pragma once
// Metrics of the pan-tilt scenario ([T]) and the summary JSON.
//
// Metrics (after `metrics_start`, and outside [occlusion start, end + 2 s]):
//   rmse_measured_cm    RMS of m̃_k − truth per axis (frames with a detection)
//   rmse_filtered_cm    RMS of the filter's x(k|k) − truth per axis (same frames, including those whose
//                       measurement the gate rejected: then x(k|k−1); ours only)
//   image_error_rms_px  RMS distance of the *true* target projection from the
//                       principal point, all frames (target off-image included)
// Occlusion: the disc is not rendered during [occlusion_start, + duration); reacquired when a
// measurement is accepted after it, with the delay from the occlusion's end.

#include <Eigen/Core>
#include <cmath>
#include <cstdint>
#include <nlohmann/json.hpp>
#include <optional>
#include <string>
#include <utility>

#include "viewline/control/pan_tilt_servo.h"
#include "viewline/core/statistics.h"
#include "viewline/estimation/consistency.h"
#include "viewline/runtime/live.h"
#include "viewline/scenarios/pan_tilt/config.h"
#include "viewline/tracking/track_gate.h"

namespace viewline::scenarios {

/// Consistency of ours' filter over the metric window (the simulator knows the truth): NIS of every
/// detected frame of a live track (innovation against the prediction the filter reported, 2 dof) and NEES
/// of x(k|k) = (p, v) against the true position and velocity (4 dof), with two-sided 99 % chi-square
/// bands for their means (core::averagedChiSquareInterval). Innovations of a consistent filter are white,
/// so the NIS band counts every sample; successive NEES values are correlated (the error drifts over
/// about a second), so its band counts one sample per second of NEES values (N = samples / fps).
struct FilterConsistency {
  estimation::ConsistencyStats nis;   ///< NIS values (2 dof)
  estimation::ConsistencyStats nees;  ///< NEES values of (p, v) (4 dof)
  double fps = 30.0;                  ///< frame rate, Hz: the NEES band's samples per independent one
  /// Adds one frame's NIS (skipped when not finite).
  void addNis(double value);
  /// Adds one frame's NEES of the estimate (p, v) and covariance P (4 x 4) against the truth.
  void addNees(const Eigen::Vector4d& estimate, const Eigen::Matrix4d& P, const Eigen::Vector4d& truth);
  /// NIS band [lo, hi] of the mean at 99 % (NaN when empty).
  core::Interval nisBand() const;
  /// NEES band [lo, hi] of the mean at 99 %, one sample per second (NaN when empty).
  core::Interval neesBand() const;
  /// Means, counts, bands and "inside" flags as JSON.
  nlohmann::json toJson() const;
};

/// One controller's run: image error, target-position errors, limits, occlusion and filter
/// figures. Errors are taken from metrics_start on, leaving out the occlusion and the 2 s after it.
struct PanTiltRunMetrics {
  std::string controller;  ///< "predictive" or "visp_baseline"
  std::size_t frames = 0,         ///< frames captured
              detections = 0,     ///< frames in which the target was detected
              metric_frames = 0;  ///< frames inside the metric window
  double image_error_rms_px = 0.0,  ///< RMS image error of the true target (from the desired pixel), px
         image_error_max_px = 0.0;  ///< its maximum, px
  /// RMSE (x, y) of the noisy measurements against the true target on the screen, cm ([T] Table 1).
  Eigen::Vector2d rmse_measured_cm = Eigen::Vector2d::Zero();
  /// RMSE (x, y) of ours' filtered target position, cm (NaN for the baseline).
  Eigen::Vector2d rmse_filtered_cm = Eigen::Vector2d::Constant(std::nan(""));
  Eigen::Vector2d noise_sigma_cm = Eigen::Vector2d::Zero();  ///< [T]'s measurement noise std (x, y), cm
  double detection_pixel_rmse_px = 0.0;  ///< detector error (before [T] noise) vs the true centre projection
  // limits
  std::size_t commands = 0,         ///< joint velocity commands sent
              unsafe_commands = 0,  ///< commands the law could not keep within the limits (predicted state)
              rate_violations = 0,  ///< commands above q̇max (the unit clipped them)
              limit_hits = 0;       ///< times a joint reached a hard stop while moving towards it
  double max_rate_fraction = 0.0;            ///< max |q̇ cmd| / q̇max
  Eigen::Vector2d min_limit_distance_deg = Eigen::Vector2d::Constant(1e9);  ///< (pan, tilt)
  Eigen::Vector2d pan_range_deg = Eigen::Vector2d::Zero(),   ///< (min, max) pan commanded at, degrees
                  tilt_range_deg = Eigen::Vector2d::Zero();  ///< (min, max) tilt commanded at, degrees
  // occlusion
  bool occlusion = false,   ///< the run had an occlusion (occlusion_start within the run)
       reacquired = false;  ///< a measurement was used again after the occlusion ended
  double reacquisition_delay_s = std::nan("");  ///< s from the occlusion's end to that measurement (NaN: never)
  std::size_t reacquisitions = 0;    ///< times ours' filter restarted after losing the target
  std::size_t frames_searching = 0;  ///< commands sent while searching for the target
  std::size_t filter_jumps = 0;              ///< velocity jumps (corners) the filter detected (ours)
  /// Ours, Kalman models with jump detection: the corner settings in force at the end of the run (the
  /// configured filter.jump_min_samples / jump_corner_sigma, or what "auto" made of them); 0 otherwise.
  int filter_min_samples = 0;
  double filter_corner_sigma = 0.0;  ///< the corner test's threshold in force, σ (see above)
  bool filter_region_dropped = false;        ///< ours: filter.region was dropped (the target left it: a wrong box)
  double wall_ms_per_frame = 0.0;            ///< wall-clock per frame, ms
  /// Ours: the gate's decisions on the detected frames (start, accept, reject, restart), as the
  /// telemetry's innovation records report them. (Not in the JSON summary.)
  tracking::GateCounts gate;
  FilterConsistency consistency;  ///< ours: NIS and NEES with their bands (empty for the baseline)
  bool stopped = false;  ///< the run ended early (a display's quit key)
  /// The frames came with truth (the simulator, or a recording of it): false for footage, where
  /// every figure that needs the true target is NaN ("not scored" in the summary).
  bool scored = true;
  runtime::FaultReport faults;  ///< injected faults and what the loop did (empty without faults)
  /// A live source (a V4L2 camera, paced footage): frames missed (dropped, processed past the
  /// deadline), the deadline and the per-frame processing times (runtime/live.h); unset otherwise.
  std::optional<runtime::LiveReport> live;

  /// Every figure above but the gate counts, as JSON (NaN as null; "truth": "not scored" when not scored).
  nlohmann::json toJson() const;
};

/// Ours against the baseline on the same seed, and the summary JSON they make.
struct PanTiltComparison {
  PanTiltRunMetrics ours,      ///< the predictive controller's run
                    baseline;  ///< ViSP's law's run (when has_baseline)
  bool has_baseline = false;   ///< the baseline ran (run_baseline, and not stopped)
  std::string path;            ///< the path shape's name ("rectangle", "circle", "random")
  std::uint64_t seed = 0;      ///< the seed both runs used
  /// The summary (keys: rmse_measured_cm, rmse_filtered_cm, image_error_rms_px,
  /// baseline_image_error_rms_px, [T]'s Table 1 beside ours, limits, occlusion).
  nlohmann::json toJson(const PanTiltScenarioConfig& config) const;
};

/// [T] Table 1 (RMSE in cm, (x, y)): noisy measurement and Kalman filter; nothing for the random path.
struct TTable1Row {
  bool available = false;  ///< [T] reports this path (rectangle, circle)
  Eigen::Vector2d measured = Eigen::Vector2d::Zero(),  ///< noisy measurement RMSE (x, y), cm
                  kalman = Eigen::Vector2d::Zero();    ///< [T]'s Kalman filter RMSE (x, y), cm
};
/// [T]'s Table 1 row for the path shape (available = false for the random path).
TTable1Row tTable1(sim::PathShape shape);

namespace pan_tilt {

/// The filter's corner settings in force (its configured values or what "auto" made of them);
/// (0, 0) for the particle filter and without jump detection, where they do not apply.
std::pair<int, double> cornerSettings(const tracking::PlanarTargetFilter& filter);

/// A sum of squares and its count: the RMS of a metric accumulated frame by frame.
struct SquareSum {
  double sum = 0.0;  ///< sum of the squares added
  long n = 0;        ///< how many were added
  /// Adds one squared value v (already squared by the caller).
  void add(double v) {
    sum += v;
    ++n;
  }
  /// √(sum / n); 0 when empty.
  double rms() const { return core::rmsFromSum(sum, n); }
};

/// "met" or "not met" of a target line.
const char* metText(bool met);

/// Accumulates one run's metrics frame by frame (the loop feeds it in frame order).
class Scorer {
public:
  /// Occlusion window [occlusion_start, occlusion_end) in s; sigma: [T]'s noise std (x, y), m.
  /// config is kept by reference.
  Scorer(const PanTiltScenarioConfig& config, double occlusion_start, double occlusion_end,
         const Eigen::Vector2d& sigma, std::string controller);
  /// Counts a captured frame (detected or not).
  void frameCaptured() { ++m_.frames; }
  /// The detector's pixel (before [T]'s noise) against the true projection (from metrics_start).
  void detectorError(double tc, const Eigen::Vector2d& detected_px, const Eigen::Vector2d& truth_px);
  /// One processed frame: `used` = ours accepted it (the baseline: it was detected); `filtered`:
  /// ours' estimate at the frame (NaN when none).
  void frame(double tc, double error_px, bool detected, const Eigen::Vector2d& measured, const Eigen::Vector2d& truth,
             bool used, const Eigen::Vector2d& filtered);
  /// Ours' filter at a detected frame: the NIS it reported (decision Accept or Reject) and, when the
  /// measurement was fused, its x(k|k) = (p, v) with covariance against the true (p, v).
  void consistency(double tc, double nis, bool fused, const Eigen::Vector4d& estimate, const Eigen::Matrix4d& P,
                   const Eigen::Vector4d& truth);
  /// One command issued at the joints q (`safe`: within the limits from the predicted state).
  void command(const robots::PanTiltLimits& limits, const Eigen::Vector2d& q, const Eigen::Vector2d& qdot, bool safe,
               bool searching);
  /// Counts one gate decision of ours' filter on a detected frame.
  void decision(tracking::GateDecision d);
  /// The figures; `ours`: the predictive controller (filter figures), null for the baseline.
  PanTiltRunMetrics finish(const control::PredictivePanTiltController* ours, const robots::SimulatedPanTiltUnit& unit,
                           double wall_ms);

private:
  const PanTiltScenarioConfig& cfg_;
  double occ0_, occ1_;
  PanTiltRunMetrics m_;
  SquareSum img_, mx_, my_, fx_, fy_, det_px_;
  Eigen::Vector2d pan_rng_{1e9, -1e9}, tilt_rng_{1e9, -1e9};
};

}  // namespace pan_tilt
}  // namespace viewline::scenarios
