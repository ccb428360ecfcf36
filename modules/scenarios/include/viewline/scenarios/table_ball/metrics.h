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

#include "viewline/estimation/consistency.h"
#include "viewline/scenarios/table_ball/config.h"
#include "viewline/scenarios/table_ball/observer.h"
#include "viewline/sim/physics.h"

namespace viewline::scenarios {

/// One scored set-point step (changes of at least min_step), from the ball's true path.
struct StepMetrics {
  double t = 0.0;                 ///< s, time of the set-point change
  double size_m = 0.0;            ///< m, distance between the old and the new set point
  double overshoot_pct = 0.0;     ///< max travel past the new set point along the step, % of size_m
  double settling_time_s = 0.0;   ///< step axis (the stepped coordinate); +inf when it never settles
  double settling_time_2d_s = 0.0;  ///< 2-D distance |p − set point| within max(fraction · step, settle_min_band)
  double steady_state_error_mm = 0.0;  ///< mean |p − set point| over the window's last steady_window, mm
};
/// One scored push: how far the ball was knocked from its set point and how long recovery took.
struct PushMetrics {
  double t = 0.0;                 ///< s, time of the push
  double speed = 0.0;             ///< |Δv|, m/s
  double recovery_s = 0.0;        ///< +inf when it never recovers in its window
  double peak_excursion_mm = 0.0;  ///< largest |p − set point| in the push's window, mm
};
/// One robot fault window (robot_silent, robot_limit_error in the config's `faults:`), scored
/// on the ball's true path up to the next event (set-point change or push) or the run's end.
struct RobotFaultMetrics {
  std::string kind;                ///< "robot_silent" or "robot_limit_error"
  double from_s = 0.0;             ///< start of the window, s
  double to_s = 0.0;               ///< end of the window, s
  double peak_excursion_mm = 0.0;  ///< largest |p − set point| from the window's start, mm
  /// From the window's end until |p − set point| <= push_band for good, s (0: within it
  /// already; +inf: not within it before the next event).
  double resettle_s = 0.0;
  bool border_contact = false;  ///< the ball reached a border (|p_i| = L/2 − r) from the window's start
};

/// The figures of one run (definitions in table_ball.h): counts, observer and prediction errors,
/// step and push responses, timing and command limits. NaN: not scored.
struct TableBallResult {
  std::uint64_t seed = 0;   ///< the run's seed
  double duration = 0.0;    ///< s, simulated time
  int frames = 0,            ///< frames captured (dropped ones included)
      frames_dropped = 0,    ///< frames lost (the observer predicted through them)
      table_detections = 0,  ///< frames in which the table was found
      ball_detections = 0;   ///< frames in which the ball was found
  int tracked_frames = 0;  ///< frames measured by the fast path (edge tracking), not [M]'s full pipeline
  double observer_rmse_mm = 0.0;     ///< RMS |p̂ − p| after warmup, mm
  double measurement_rmse_mm = 0.0;  ///< RMS |y − p| of the raw ball measurements (own table pose) after warmup, mm
  /// RMS |y − p| of the ball measurements the filter fused (filtered table pose) after warmup, mm.
  double fused_measurement_rmse_mm = 0.0;
  double observer_rmse_mm_M_sw1_sv0005 = 0.0;   ///< [M]'s best tuning (side filter)
  double observer_rmse_mm_M_sw1_sv1 = 0.0;      ///< [M]'s lagging tuning (side filter)
  double observer_rmse_mm_stationary = 0.0;     ///< stationary (DARE) gain, configured σ
  double prediction_rmse_mm_10 = 0.0;           ///< 10-step (0.2 s) prediction vs truth
  double tilt_rmse_deg = 0.0;                   ///< measured table tilt vs truth
  double nis_mean = 0.0;                         ///< mean NIS of the ball measurements after warmup (2 dof: 2 expected)
  /// NIS of the ball updates sampled every metrics.nis_spacing after warmup (2 dof each): the
  /// sample mean and its two-sided 99 % chi-square band (samples spaced to be nearly independent).
  estimation::ConsistencyStats nis_sampled;
  /// NEES of the ball position and velocity (4 dof) against the truth, one sample every
  /// metrics.nees_spacing after warmup (a sample due in the frame of a push waits two frames).
  estimation::ConsistencyStats nees;
  std::vector<StepMetrics> steps;    ///< every scored step, in time order
  std::vector<PushMetrics> pushes;   ///< every scored push, in time order
  /// Every robot fault window of the config that starts within the run (empty without them).
  std::vector<RobotFaultMetrics> robot_faults;
  double overshoot_pct = 0.0,          ///< worst step overshoot, %
         settling_time_s = 0.0,        ///< worst step settling time, s (+inf: one never settled)
         settling_time_2d_s = 0.0,     ///< worst step 2-D settling time, s (+inf: one never settled)
         steady_state_error_mm = 0.0,  ///< worst step steady-state error, mm
         push_recovery_s = 0.0;        ///< worst push recovery time, s (+inf: one never recovered)
  double observer_frame_ms = 0.0,              ///< mean wall-clock per frame of the observer, ms
         reference_frame_ms = 0.0,             ///< the same for the plain OpenCV reference, ms
         frame_time_ratio_to_reference = 0.0;  ///< observer_frame_ms / reference_frame_ms
  double observer_frame_cpu_ms = 0.0,         ///< mean thread-CPU per frame of the observer, ms
         reference_frame_cpu_ms = 0.0,        ///< the same for the reference, ms
         frame_cpu_ratio_to_reference = 0.0;  ///< observer_frame_cpu_ms / reference_frame_cpu_ms
  double max_commanded_angle_deg = 0.0,   ///< largest |tilt| commanded on either axis, degrees
         max_commanded_rate_deg_s = 0.0;  ///< largest commanded tilt rate, degrees/s
  bool limits_respected = true;  ///< every command within the wrist's angle and rate limits
  bool stopped_early = false;  ///< the run was stopped before its duration (a display's quit key)
  double wall_seconds = 0.0;   ///< wall-clock time of the run, s
  runtime::FaultReport faults;  ///< injected faults and what the loop did (empty without faults)
};

/// The result as the summary JSON (NaN and ±inf as null; steps and pushes as arrays).
nlohmann::json toJson(const TableBallResult& r);

/// The summary a person reads (stdout of the app). A figure the run could not score says why
/// ("not scored (run shorter than the warm-up ...)") instead of printing nan.
void printTableBallSummary(std::FILE* out, const TableBallResult& r, const TableBallConfig& cfg);

/// The side filters run beside the loop on the same measurements ([M]'s two tunings and the
/// stationary gain), in the order of the result's fields.
using SideFilters = std::vector<std::pair<std::string, tracking::RollingBallTracker>>;

/// The accumulators the loop feeds as the run goes; result() turns them into a TableBallResult.
class TableBallMetrics {
public:
  /// config is kept by reference (it must outlive the metrics).
  explicit TableBallMetrics(const TableBallConfig& config);

  /// A position command sent to the wrist (one per physics tick, kTick apart).
  void command(const Eigen::Vector2d& cmd);
  /// The ball position at time t, the end of a physics tick.
  void tick(double t, const Eigen::Vector2d& p);
  /// One frame (stamp t), with the truth at its capture instant, what the observer made of it
  /// (dropped frames: its prediction), its filter, and the side filters after their step.
  void frame(double t, const sim::TiltTableState& truth, const ObserverFrame& of, const tracking::RollingBallTracker& tracker,
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
  Accumulator obs_, meas_, fused_meas_, pred_, tilt_;
  std::vector<Accumulator> side_;
  std::vector<std::pair<double, Eigen::Vector2d>> pending_pred_;  // (time, predicted position N frames ahead)
  double next_nis_ = 0.0, next_nees_ = 0.0;
  double nis_sum_ = 0.0;
  int nis_n_ = 0;
  double obs_time_ = 0.0, ref_time_ = 0.0, obs_cpu_ = 0.0, ref_cpu_ = 0.0;
  int timed_ = 0;
};

}  // namespace viewline::scenarios
