#pragma once
// Filter-only replays of a logged pan-tilt run ([T]): the measurements of
// `<log>/predictive_frames.csv` given again to a filter, without rendering.

#include <cstdint>
#include <nlohmann/json.hpp>
#include <string>

#include "viewline/io/log.h"
#include "viewline/scenarios/pan_tilt/config.h"
#include "viewline/scenarios/pan_tilt/metrics.h"

namespace viewline::scenarios {

/// Filter-only replay: the predictive controller's target filter (same config, same reacquisition
/// rule) re-run on the measurements of a logged run (`<log>/predictive_frames.csv` of
/// pan_tilt_tracking --log), scored against the path of `seed` with the run's metric windows.
/// Used to compare filters on identical measurements without rendering; the closed loop is not
/// re-run (the measurements depend on it only through the detector's sub-pixel error). A log whose truth
/// columns are not the path of `seed` (another seed, shape, size or speed) is refused (core::InvalidInput).
struct PanTiltReplayMetrics {
  std::size_t measurements = 0,  ///< logged measurements replayed
              jumps = 0;         ///< corners the estimator detected (or was told: OracleCorners)
  Eigen::Vector2d rmse_measured_cm = Eigen::Vector2d::Zero(),  ///< measurement RMSE (x, y), cm
                  rmse_filtered_cm = Eigen::Vector2d::Zero();  ///< estimate RMSE (x, y), cm
  double horizon_s = 0.0;  ///< processing delay + latency + lead: how far ahead the law predicts
  Eigen::Vector2d rmse_predicted_cm = Eigen::Vector2d::Zero();  ///< x(t + horizon | t) − truth, every frame
  double predicted_error_px = 0.0;  ///< its RMS norm × fx / screen distance (px near the image centre)
  /// The horizon the image error sees: a command issued after capture t acts from t + processing delay +
  /// latency, so the first frame it moves is n frames later, n = ⌊(processing delay + latency) fps⌋ + 1
  /// (66.7 ms at 40 ms and 30 fps), and each frame's error is set by a prediction that old.
  double frame_horizon_s = 0.0;
  double frame_predicted_error_px = 0.0;  ///< as predicted_error_px, at frame_horizon_s
  bool region_dropped = false;            ///< the filter dropped filter.region (the target left it)
  int min_samples = 0;                    ///< the filter's corner settings at the end (see PanTiltRunMetrics)
  double corner_sigma = 0.0;              ///< the corner test's threshold at the end, σ
  FilterConsistency consistency;          ///< Filter: NIS and NEES in the metric window (metrics.h)
  /// The figures above as JSON (the replay's summary).
  nlohmann::json toJson() const;
};
/// What a replay runs on the logged measurements.
enum class PanTiltReplayEstimator {
  /// The config's filter (the predictive controller's, same reacquisition rule).
  Filter,
  /// Rectangle and random paths: a bound, a constant-speed leg filter told the path's true corner times
  /// and speed (tracking::PlanarTargetFilter::startLeg); `jumps` is then the number of corners. No causal
  /// filter that must detect the corners can expect to beat it.
  OracleCorners,
  /// Random path: tracking::WaypointParticleFilter, the posterior mean under the path's generator
  /// (waypoints uniform in filter.region, one constant speed), the causal reference; `jumps` is 0.
  WaypointParticles,
};
/// Writes a frames CSV that replayPanTiltFilter reads (t, truth_x, truth_y, detected, meas_x, meas_y) without a
/// camera: the path of `seed` at every frame (fps, duration of the config), measured with [T]'s noise
/// (σ per axis as the scenario's, its own seeded stream, not the closed loop's draws) and not detected
/// during the occlusion. For filter studies over many seeds at a fraction of a closed loop's cost.
void writeSyntheticPanTiltFrames(const PanTiltScenarioConfig& config, std::uint64_t seed, const std::string& frames_csv);

/// With a log, writes the stream replay_frames (t, truth, detected, measurement, the estimator's output,
/// accepted, jumps so far) for per-frame comparisons. `particles`: the particle count of
/// WaypointParticles.
PanTiltReplayMetrics replayPanTiltFilter(const PanTiltScenarioConfig& config, std::uint64_t seed,
                                         const std::string& frames_csv,
                                         PanTiltReplayEstimator estimator = PanTiltReplayEstimator::Filter,
                                         io::LogDirectory* log = nullptr, std::size_t particles = 20000);

}  // namespace viewline::scenarios
