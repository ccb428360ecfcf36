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

/// How the settings of a sweep are made.
enum class SweepMode {
  Grid,    ///< the cartesian product of every parameter's values
  Random   ///< `samples` seeded draws
};

/// One swept scenario key (an entry of `parameters:`).
struct SweepParameter {
  std::string key;                   ///< dotted scenario key
  std::string location;              ///< "<file>:<line>:<col>" of the entry (for later errors)
  std::vector<YAML::Node> values;    ///< explicit values (grid points are generated into it)
  bool has_range = false;            ///< given as `range: [lo, hi]`
  double lo = 0.0;                   ///< low end of the range (the key's units)
  double hi = 0.0;                   ///< high end of the range (the key's units)
  bool log_scale = false;            ///< range points spaced in log
  bool integer = false;              ///< range values are integers (`type: int`)
  int count = 0;                     ///< grid points of the range
};

/// The `autotune:` section of a sweep file (see AutotuneOptions).
struct AutotuneSpec {
  bool enabled = false;              ///< the section is present
  double start_scale = 1.0;          ///< start from the config's noise values times this
  std::uint64_t record_seed = 1000;  ///< seed of the live recording
  int record_runs = 1;               ///< runs of the live recording
  double outlier_prior = 0.05;       ///< AutotuneOptions::outlier_prior
  double span_decades = 2.5;         ///< AutotuneOptions::span_decades
  int grid_points = 11;              ///< AutotuneOptions::grid_points
};

/// A sweep file as read (keys documented in the file comment).
struct SweepSpec {
  std::string file;                  ///< the sweep file's path
  std::string scenario;              ///< adapter name
  std::string config_path;           ///< resolved against the sweep file's folder ("" when absent)
  int seeds = 3;                     ///< runs per setting
  std::uint64_t base_seed = 1;       ///< run j uses deriveSeed(base_seed, j)
  std::string metric;                ///< the metric optimised
  bool minimize = true;              ///< direction of `metric`
  SweepMode mode = SweepMode::Grid;  ///< grid or random settings
  int samples = 0;                   ///< settings drawn in random mode
  std::uint64_t sample_seed = 7;     ///< seed of the random draws
  double confidence = 0.99;          ///< of the NEES/NIS bands
  std::vector<SweepParameter> parameters;  ///< the swept keys
  AdapterOptions adapter_options;    ///< the `adapter:` map, checked, with defaults
  AutotuneSpec autotune;             ///< the `autotune:` section
};

/// Parses a sweep file (strict keys; adapter options checked against the named adapter).
SweepSpec loadSweepSpec(const std::string& path, const AdapterRegistry& registry);
/// The same from YAML text; `name` names the file in messages, `config:` resolves against `base_dir`.
SweepSpec sweepSpecFromString(const std::string& yaml, const std::string& name, const AdapterRegistry& registry,
                              const std::string& base_dir = ".");

/// One setting of a sweep: a value per parameter.
struct Setting {
  std::size_t index = 0;           ///< position in the sweep's settings
  std::vector<YAML::Node> values;  ///< one per parameter
  std::vector<double> numeric;     ///< numeric value per parameter (NaN for text values)
  std::string label() const;       ///< "tracker.accel_psd=0.5 gate=none" style (needs keys)
};

/// The settings of a sweep: cartesian product (grid) or `samples` seeded draws (random).
std::vector<Setting> generateSettings(const SweepSpec& spec);

/// "k1=v1, k2=v2".
std::string settingLabel(const SweepSpec& spec, const Setting& s);

/// The scenario tree with the setting's values (editedTree: the untouched nodes keep the file's marks).
YAML::Node applySetting(const YAML::Node& scenario, const SweepSpec& spec, const Setting& s);

}  // namespace viewline::tuning
