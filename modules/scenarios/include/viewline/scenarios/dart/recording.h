#pragma once
// Record and replay for the dart experiments. The dart scenario renders no images: its "frames"
// are the simulated detections (stamp, camera, pixel, σ, outlier flag) with the true state at each
// capture. `--record DIR` writes them, per run and experiment, with the experiment's other random
// draws (D's arrival delays, E's prior offsets); `--replay DIR` runs the trackers on them instead
// of simulating, and with the same config it gives the same summary bit for bit (the wall-clock
// figures aside). The same detections could come from a real rig's detector: the file is what a
// tracker consumes, independent of how it was made.
//
// Layout of DIR (a session recording, runtime/recording.h):
//   session.json   {"scenario": "dart_tracking", "seed": S, "units": N, "unit": "run"}
//   config.yaml    the scenario config as run (after --set edits)
//   run_iii.json   run i: {"<experiment>": {"duration_s": d, "detections": [[id, camera, t, u, v,
//                  sigma_px, outlier, x, y, z, vx, vy, vz], ...], "draws": [...]}, ...}
//                  (t in s on the run's clock; u, v, σ in px; x..z in m and vx..vz in m/s, world;
//                  numbers written as the shortest text that reads back as the same double)
// Experiments: A_alternating, B_gates, C_async, D_scenario, E_single (dart/loop.h).

#include <cstdint>
#include <functional>
#include <map>
#include <string>
#include <vector>

#include <nlohmann/json.hpp>

#include "viewline/core/random.h"
#include "viewline/scenarios/dart/config.h"
#include "viewline/scenarios/dart/world.h"

namespace viewline::scenarios {

/// The flights of the dart experiments: simulated (and recorded when asked) or replayed from a recording.
class DartFlights {
public:
  /// Simulates every flight; record_dir not empty: records the session into that new folder (its
  /// config.yaml from config_text); replay_dir not empty: reads the flights from that recording
  /// instead (recorded with `seed` and at least `runs` runs, else core::InvalidInput).
  DartFlights(const std::string& record_dir, const std::string& replay_dir, std::uint64_t seed, int runs,
              const std::string& config_text);
  /// Starts run `run` (replay: reads its file).
  void beginRun(int run);
  /// The flight of `experiment` in the current run: simulateDartFlight(cfg, cameras, mode,
  /// outlier_rate, rng), recorded; or the recorded one (rng then untouched).
  DartFlight flight(const std::string& experiment, const DartScenarioConfig& cfg, const std::vector<core::Camera>& cameras,
                    DartClockMode mode, double outlier_rate, core::Rng& rng);
  /// The experiment's next random draw: draw() (recorded), or the recorded value.
  double draw(const std::string& experiment, const std::function<double()>& draw);
  /// The same for a 3-vector drawn as one (its components in order).
  Eigen::Vector3d draw3(const std::string& experiment, const std::function<Eigen::Vector3d()>& draw);
  /// Ends the current run (record: writes run_iii.json atomically; replay: checks every recorded draw was used).
  void endRun();

private:
  nlohmann::json& experimentOf(const std::string& experiment);
  std::string record_dir_, replay_dir_;
  std::string file_;     ///< the current run's file
  nlohmann::json run_;   ///< the current run (recorded so far, or read)
  std::map<std::string, std::size_t> next_draw_;  ///< replay: the next draw per experiment
};

}  // namespace viewline::scenarios
