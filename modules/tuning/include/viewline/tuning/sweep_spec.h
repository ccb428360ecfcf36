#pragma once
// Sweep files (config/sweeps/*.yaml): which scenario keys to vary, how, how many seeds, which
// metric to optimise. Read with io::ConfigNode, so every error (unknown key, wrong type, empty
// range) names the sweep file, line and key.
//
//   scenario: dart                      # adapter name (viewline_tune --list)
//   config: ../dart_tracking.yaml       # scenario config (relative to this file; --config overrides)
//   seeds: 4                            # runs per setting; run j uses seed deriveSeed(base_seed, j)
//   base_seed: 1
//   metric: rmse_position_m             # a metric the scenario reports
//   direction: minimize                 # minimize | maximize
//   mode: grid                          # grid (cartesian product) | random (samples draws)
//   samples: 20                         # random mode only
//   sample_seed: 7                      # random mode only
//   confidence: 0.99                    # NEES/NIS bands
//   parameters:
//     - key: tracker.accel_psd          # dotted scenario key
//       values: [0, 0.5, 2]             # explicit values (any type the key takes), or
//     - key: tracker.mahalanobis_alpha
//       range: [1.0e-4, 1.0e-1]         # [lo, hi] with
//       count: 4                        # grid points (grid mode)
//       scale: log                      # linear | log
//       type: double                    # double | int
//   adapter: {flights: 20}              # scenario-specific run options (viewline_tune --list)
//   autotune:                           # optional: noise auto-tuning in the same session
//     start_scale: 10                   # start from the config's noise values times this factor
//     record_seed: 1000                 # live runs recorded for the tuning
//     record_runs: 1
//     outlier_prior: 0.05               # prior probability of a gross outlier in the likelihood
//     span_decades: 2.5                 # grid search +- this around the start (log10 units)
//     grid_points: 11                   # per noise parameter
//
// Seeds: every setting uses the same seeds (common random numbers: the settings are compared on
// the same throws/paths/noise draws, which removes most of the seed-to-seed spread from the
// comparison), and they depend on the run index only, never on the thread that runs it.

#include <cstdint>
#include <optional>
#include <string>
#include <vector>
#include <yaml-cpp/yaml.h>

#include "viewline/io/config.h"
#include "viewline/tuning/scenario.h"

namespace viewline::tuning {

enum class SweepMode { Grid, Random };

struct SweepParameter {
  std::string key;
  std::string location;              ///< "<file>:<line>:<col>" of the entry (for later errors)
  std::vector<YAML::Node> values;    ///< explicit values (grid points are generated into it)
  bool has_range = false;
  double lo = 0.0, hi = 0.0;
  bool log_scale = false;
  bool integer = false;
  int count = 0;
};

struct AutotuneSpec {
  bool enabled = false;
  double start_scale = 1.0;
  std::uint64_t record_seed = 1000;
  int record_runs = 1;
  double outlier_prior = 0.05;
  double span_decades = 2.5;
  int grid_points = 11;
};

struct SweepSpec {
  std::string file;
  std::string scenario;
  std::string config_path;           ///< resolved against the sweep file's folder ("" when absent)
  int seeds = 3;
  std::uint64_t base_seed = 1;
  std::string metric;
  bool minimize = true;
  SweepMode mode = SweepMode::Grid;
  int samples = 0;
  std::uint64_t sample_seed = 7;
  double confidence = 0.99;
  std::vector<SweepParameter> parameters;
  AdapterOptions adapter_options;
  AutotuneSpec autotune;
};

/// Parses a sweep file (strict keys; adapter options checked against the named adapter).
SweepSpec loadSweepSpec(const std::string& path, const AdapterRegistry& registry);
SweepSpec sweepSpecFromString(const std::string& yaml, const std::string& name, const AdapterRegistry& registry,
                              const std::string& base_dir = ".");

struct Setting {
  std::size_t index = 0;
  std::vector<YAML::Node> values;  ///< one per parameter
  std::vector<double> numeric;     ///< numeric value per parameter (NaN for text values)
  std::string label() const;       ///< "tracker.accel_psd=0.5 gate=none" style (needs keys)
};

/// The settings of a sweep: cartesian product (grid) or `samples` seeded draws (random).
std::vector<Setting> generateSettings(const SweepSpec& spec);

/// "k1=v1, k2=v2".
std::string settingLabel(const SweepSpec& spec, const Setting& s);

/// Applies a setting to a scenario tree.
YAML::Node applySetting(const YAML::Node& scenario, const SweepSpec& spec, const Setting& s);

}  // namespace viewline::tuning
