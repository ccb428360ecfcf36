#pragma once
// The dart experiment of [L] §VI: seeded Monte-Carlo runs of the viewline tracker on generated
// dart flights (world.h). Every run has its own seed: deriveSeed(seed, run).
//
//  A consistency  alternating cameras ([L] §VI.A: camera 1 at odd 100 Hz steps, camera 2 at even
//                 ones), no outliers: NEES (one sample per run at a fixed measurement index, so
//                 the samples are independent), position RMSE against the posterior Cramér-Rao
//                 bound computed from the true trajectories.
//  B gates        alternating cameras, gross outliers: the directional gate and the Mahalanobis
//                 gate on the same data, plus the image-space EKF baseline.
//  C async        free-running unsynchronised clocks (drift, phase, jitter), no outliers: exact
//                 propagation vs Δt-offset rows vs image EKF.
//  D scenario     the full scenario (free-running clocks, jitter, outliers) with the configured
//                 gate, in capture order and in arrival order (capture + U(0, max delay), delivered
//                 by the scenario clock, runtime::Scheduler): maximum difference of the final
//                 states and of the per-measurement decisions.
//  E single cam   one camera, priors up to `single_offset_max` off (position and velocity),
//                 P0 = std² I, vs a filter started at the truth; and the same criterion for two
//                 ideal linear filters with the true depth (its information limit).
//
// With the tracker's robust start (tracker.start) the RMSE, NEES and PCRLB pool only the
// estimates the tracker reports (a confirmed track); the share is each figure's reported_fraction.
//
//   const auto cfg = scenarios::loadDartScenario("config/dart_tracking.yaml");
//   const scenarios::DartSummary s = scenarios::runDartExperiments(cfg, seed, 500);

#include <cstdint>
#include <functional>
#include <string>
#include <vector>

#include "viewline/runtime/scheduler.h"
#include "viewline/runtime/telemetry.h"
#include "viewline/scenarios/dart/config.h"
#include "viewline/scenarios/dart/metrics.h"
#include "viewline/scenarios/dart/world.h"

namespace viewline::scenarios {

/// One logged detection (for --log): experiment, run, detection and the estimate after it.
struct DartLogRow {
  std::string experiment;  ///< experiment and variant, e.g. "A_alternating", "D_scenario"
  int run = 0;             ///< run index (its seed is deriveSeed(seed, run))
  DartDetection det;       ///< the detection as generated (stamp, camera, pixel, outlier flag)
  tracking::Fate fate = tracking::Fate::Fused;  ///< what the tracker did with it
  tracking::Vector6 estimate;  ///< state after it: position m, velocity m/s (world)
};

/// The columns of the --log detections CSV and one row of it.
std::vector<std::string> dartLogColumns();
/// One row of that CSV, in dartLogColumns() order.
std::vector<std::string> dartLogRow(const DartLogRow& r);

/// Optional observers of runDartExperiments(): progress, per-detection log, telemetry, pacing.
struct DartRunCallbacks {
  std::function<void(int done, int total)> progress;  ///< after each run
  std::function<void(const DartLogRow&)> log;         ///< per processed detection (optional)
  /// The full scenario's (D, capture order) detections, the tracker's updates (innovation, S,
  /// NIS, gate decision; channel "dart") and estimates, as they happen (optional).
  runtime::TelemetrySink* telemetry = nullptr;
  /// The full scenario's deliveries in arrival order run on a runtime::Scheduler: paced to the
  /// wall clock with factor > 0 (the app's --realtime), as fast as possible by default. Pacing
  /// changes when, never what: the figures are the same.
  runtime::Pacing pacing;
  std::string record_dir;   ///< --record DIR: every run's detections, truth and draws (recording.h); "" : none
  std::string replay_dir;   ///< --replay DIR: the trackers on a recording's detections (overrides `source:`)
  std::string config_text;  ///< the config as run, written into a recording (config.yaml)
};

/// Runs experiments A-E for `runs` seeded runs of a validated config (loadDartScenario validates;
/// a config built in code calls validate() first).
DartSummary runDartExperiments(const DartScenarioConfig& cfg, std::uint64_t seed, int runs,
                               const DartRunCallbacks& cb = {});

/// The tracker's update of one image as a telemetry record (channel `channel`).
runtime::InnovationRecord innovationRecord(const tracking::ImageUpdate& u, const std::string& channel);

}  // namespace viewline::scenarios
