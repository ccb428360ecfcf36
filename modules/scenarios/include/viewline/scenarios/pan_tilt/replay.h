#pragma once
// Filter-only replays of a logged pan-tilt run ([T]): the measurements of
// `<log>/predictive_frames.csv` given again to a filter, without rendering.

#include <cstdint>
#include <nlohmann/json.hpp>
#include <string>

#include "viewline/io/log.h"
#include "viewline/scenarios/pan_tilt/config.h"

namespace viewline::scenarios {

/// Filter-only replay: the predictive controller's target filter (same config, same reacquisition
/// rule) re-run on the measurements of a logged run (`<log>/predictive_frames.csv` of
/// pan_tilt_tracking --log), scored against the path of `seed` with the run's metric windows.
/// Used to compare filters on identical measurements without rendering; the closed loop is not
/// re-run (the measurements depend on it only through the detector's sub-pixel error). A log whose truth
/// columns are not the path of `seed` (another seed, shape, size or speed) is refused (core::InvalidInput).
struct PanTiltReplayMetrics {
  std::size_t measurements = 0,  ///< logged measurements re-filtered
              jumps = 0;         ///< velocity jumps (corners) the filter detected
  Eigen::Vector2d rmse_measured_cm = Eigen::Vector2d::Zero(),  ///< RMSE of the measurements (x, y), cm
                  rmse_filtered_cm = Eigen::Vector2d::Zero();  ///< RMSE of the filtered position (x, y), cm
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
  double corner_sigma = 0.0;              ///< jump_corner_sigma in force at the end, m
  /// The figures as JSON (the replay's summary).
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
/// With a log, writes the stream replay_frames (t, truth, detected, measurement, the estimator's output,
/// accepted, jumps so far) for per-frame comparisons. `particles`: the particle count of
/// WaypointParticles.
PanTiltReplayMetrics replayPanTiltFilter(const PanTiltScenarioConfig& config, std::uint64_t seed,
                                         const std::string& frames_csv,
                                         PanTiltReplayEstimator estimator = PanTiltReplayEstimator::Filter,
                                         io::LogDirectory* log = nullptr, std::size_t particles = 20000);

}  // namespace viewline::scenarios
