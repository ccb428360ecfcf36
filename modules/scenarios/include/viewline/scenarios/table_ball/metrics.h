#pragma once
// The table-ball scenario's figures (definitions in table_ball.h): the accumulators the loop
// feeds as the run goes (commands, physics ticks, frames), the scoring of set-point steps and
// pushes at the end, the JSON summary and the human one.

#include <Eigen/Core>
#include <cstdint>
#include <cstdio>
#include <nlohmann/json.hpp>
#include <string>
#include <utility>
#include <vector>

#include "viewline/scenarios/table_ball/config.h"
#include "viewline/scenarios/table_ball_observer.h"
#include "viewline/sim/physics.h"

namespace viewline::scenarios {

/// The response to one set-point step.
struct StepMetrics {
  double t = 0.0;              ///< time of the step, s
  double size_m = 0.0;         ///< step size, m
  double overshoot_pct = 0.0;  ///< overshoot along the step axis, % of the step
  double settling_time_s = 0.0;   ///< step axis (the stepped coordinate); +inf when it never settles
  double settling_time_2d_s = 0.0;  ///< same with the 2-D distance (includes the cross axis)
  double steady_state_error_mm = 0.0;  ///< mean distance to the set point over the steady window, mm
};
/// The recovery from one push.
struct PushMetrics {
  double t = 0.0;                 ///< time of the push, s
  double speed = 0.0;             ///< |Δv|, m/s
  double recovery_s = 0.0;        ///< +inf when it never recovers in its window
  double peak_excursion_mm = 0.0;  ///< largest distance from the set point after the push, mm
};

/// A table-ball run's figures (the --summary JSON): observer accuracy, step and push responses, timing, limits.
struct TableBallResult {
  std::uint64_t seed = 0;  ///< seed of the run
  double duration = 0.0;   ///< simulated time, s
  int frames = 0,            ///< frames captured
      frames_dropped = 0,    ///< frames lost
      table_detections = 0,  ///< frames with the table found
      ball_detections = 0;   ///< frames with the ball found
  int tracked_frames = 0;  ///< frames measured by the fast path (edge tracking), not [M]'s full pipeline
  double observer_rmse_mm = 0.0;     ///< observer's ball position vs truth (after the warmup), mm
  double measurement_rmse_mm = 0.0;  ///< raw measured ball position vs truth, mm
  double observer_rmse_mm_M_sw1_sv0005 = 0.0;   ///< [M]'s best tuning (side filter)
  double observer_rmse_mm_M_sw1_sv1 = 0.0;      ///< [M]'s lagging tuning (side filter)
  double observer_rmse_mm_stationary = 0.0;     ///< stationary (DARE) gain, configured σ
  double prediction_rmse_mm_10 = 0.0;           ///< 10-step (0.2 s) prediction vs truth
  double tilt_rmse_deg = 0.0;                   ///< measured table tilt vs truth
  double nis_mean = 0.0;            ///< mean NIS of the observer's filter
  std::vector<StepMetrics> steps;   ///< every scored step
  std::vector<PushMetrics> pushes;  ///< every push
  double overshoot_pct = 0.0,          ///< mean step overshoot, %
         settling_time_s = 0.0,        ///< mean step settling time, s
         steady_state_error_mm = 0.0,  ///< mean steady-state error, mm
         push_recovery_s = 0.0;        ///< mean push recovery time, s
  double observer_frame_ms = 0.0,              ///< wall time of the observer per frame, ms
         reference_frame_ms = 0.0,             ///< wall time of the plain OpenCV reference of [M]'s steps per frame, ms
         frame_time_ratio_to_reference = 0.0;  ///< observer_frame_ms / reference_frame_ms
  double observer_frame_cpu_ms = 0.0,         ///< CPU time of the observer per frame, ms
         reference_frame_cpu_ms = 0.0,        ///< CPU time of the reference per frame, ms
         frame_cpu_ratio_to_reference = 0.0;  ///< observer_frame_cpu_ms / reference_frame_cpu_ms
  double max_commanded_angle_deg = 0.0,   ///< largest commanded tilt, deg
         max_commanded_rate_deg_s = 0.0;  ///< largest commanded tilt rate, deg/s
  bool limits_respected = true;  ///< every command within the wrist's limits
  bool stopped_early = false;  ///< the run was stopped before its duration (a display's quit key)
  double wall_seconds = 0.0;   ///< wall-clock time of the run, s
};

nlohmann::json toJson(const TableBallResult& r);

/// The summary a person reads (stdout of the app). A figure the run could not score says why
/// ("not scored (run shorter than the warm-up ...)") instead of printing nan.
void printTableBallSummary(std::FILE* out, const TableBallResult& r, const TableBallConfig& cfg);

/// The side filters run beside the loop on the same measurements ([M]'s two tunings and the
/// stationary gain), in the order of the result's fields.
using SideFilters = std::vector<std::pair<std::string, RollingBallTracker>>;

/// Accumulates a table-ball run's metrics tick by tick and frame by frame, then gives the result.
class TableBallMetrics {
public:
  /// Metrics for a run of `config` (set points, pushes, windows); keeps a reference to it.
  explicit TableBallMetrics(const TableBallConfig& config);

  /// A position command sent to the wrist (one per physics tick, kTick apart).
  void command(const Eigen::Vector2d& cmd);
  /// The ball position at time t, the end of a physics tick.
  void tick(double t, const Eigen::Vector2d& p);
  /// One frame (stamp t), with the truth at its capture instant, what the observer made of it
  /// (dropped frames: its prediction), its filter, and the side filters after their step.
  void frame(double t, const sim::TiltTableState& truth, const ObserverFrame& of, const RollingBallTracker& tracker,
             const SideFilters& side);
  /// Wall-clock and thread-CPU seconds of the observer and of the plain reference on one frame.
  void timing(double observer_s, double reference_s, double observer_cpu_s, double reference_cpu_s);

  /// The figures of the run so far (steps and pushes scored on the ticks recorded).
  TableBallResult result(std::uint64_t seed) const;

private:
  struct Accumulator {
    double sum_sq = 0.0;
    long n = 0;
    void add(const Eigen::Vector2d& e) {
      sum_sq += e.squaredNorm();
      ++n;
    }
    double rmsMm() const;
  };
  void scoreEvents(TableBallResult& res) const;

  const TableBallConfig& cfg_;
  double period_;
  TableBallResult counts_;  ///< frame counts and command limits, as they accumulate
  bool have_cmd_ = false;
  Eigen::Vector2d last_cmd_ = Eigen::Vector2d::Zero();
  std::vector<double> tick_t_;
  std::vector<Eigen::Vector2d> tick_p_;
  Accumulator obs_, meas_, pred_, tilt_;
  std::vector<Accumulator> side_;
  std::vector<std::pair<double, Eigen::Vector2d>> pending_pred_;  // (time, predicted position N frames ahead)
  double nis_sum_ = 0.0;
  int nis_n_ = 0;
  double obs_time_ = 0.0, ref_time_ = 0.0, obs_cpu_ = 0.0, ref_cpu_ = 0.0;
  int timed_ = 0;
};

}  // namespace viewline::scenarios
