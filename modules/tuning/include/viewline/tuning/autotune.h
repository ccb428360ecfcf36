#pragma once
// Noise auto-tuning by maximum likelihood on the innovation sequence.
//
// Method. For noise parameters θ (process noise density q, measurement noise σ: the scenario's
// noiseParameters()), the filter is re-run on the recorded measurements (same time stamps, same
// data; ScenarioInstance::replay). A Kalman filter whose model is right produces innovations
// d_k ~ N(0, S_k), independent over k (prediction error decomposition, Schweppe 1965), so the
// log-likelihood of the measurements is, up to a constant,
//
//     −2 log L(θ) = Σ_k [ log |S_k(θ)| + d_k(θ)ᵀ S_k(θ)⁻¹ d_k(θ) ].
//
// Too small a noise makes d S⁻¹ d large (overconfident); too large makes log|S| large: the minimum
// balances them and, at the true noise, E[dᵀ S⁻¹ d] = m (the NIS is consistent). Gross outliers
// would dominate a Gaussian likelihood, so each term is a two-component mixture
//
//     p(d_k) = (1 − ε) N(d_k; 0, S_k) + ε u_k,
//
// with ε the prior outlier probability (sweep file autotune.outlier_prior; 0 gives the plain
// Gaussian likelihood) and u_k the density of a measurement uniform over the image, mapped to the
// innovation space (scenario-specific, independent of θ). The first measurements of a track
// (while the prior dominates) are left out of the sum (scenario-specific burn-in).
//
// Search (1-2 parameters, in log10 space, positive parameters): a grid of `grid_points` per
// parameter over start ± span_decades (evaluated in parallel, deterministic), then Nelder-Mead
// from the best grid point (initial step = grid spacing, stops when the simplex is smaller than
// 0.002 decades or after 200 evaluations). The grid makes the search robust to the cost being
// piecewise smooth (the outlier gate switches measurements in and out as θ changes); the simplex
// refines below the grid spacing.
//
// NIS before/after: the replay's NIS (accepted innovations) at the start and at the tuned values,
// with its chi-square band.

#include <atomic>
#include <functional>
#include <memory>
#include <nlohmann/json.hpp>
#include <string>
#include <vector>

#include "viewline/tuning/scenario.h"

namespace viewline::tuning {

/// How the noise search runs (see the file comment).
struct AutotuneOptions {
  double outlier_prior = 0.05;  ///< ε, prior probability that a measurement is a gross outlier (0: Gaussian)
  double span_decades = 2.5;    ///< the grid spans start ± this many decades per parameter
  int grid_points = 11;         ///< grid points per parameter
  int workers = 0;              ///< threads of the grid stage; 0: all cores
  double confidence = 0.99;     ///< of the NIS chi-square bands
  int max_simplex_evaluations = 200;  ///< Nelder-Mead stops after this many cost evaluations
  std::function<void(const std::string&)> progress;  ///< progress lines (optional)
};

/// One cost evaluation of the search.
struct AutotuneEvaluation {
  std::vector<double> values;  ///< noise values (noiseParameters() order, their units)
  double cost = 0.0;           ///< −2 log L of the replayed innovations
  double nis_mean = 0.0;       ///< NIS mean of the replay
};

/// What the noise search found.
struct AutotuneResult {
  std::vector<NoiseParameter> parameters;  ///< the tuned noise parameters
  std::vector<double> start;               ///< start values (parameter units)
  std::vector<double> tuned;               ///< values of least cost (parameter units)
  ReplayResult before;                     ///< replay at the start values (with series)
  ReplayResult after;                      ///< replay at the tuned values (with series)
  std::vector<AutotuneEvaluation> grid;    ///< the grid stage (for the cost plot)
  std::size_t evaluations = 0;             ///< cost evaluations in all
  std::string data_description;            ///< what was replayed (ReplayData::describe())
  double wall_s = 0.0;                     ///< s of wall-clock time of the search
  /// The result as JSON (the session summary's "autotune" object), bands at `confidence`.
  nlohmann::json toJson(double confidence) const;
};

/// Minimises the replay cost over the noise parameters (see the file comment).
AutotuneResult autotuneNoise(const ScenarioInstance& instance, const ReplayData& data, const std::vector<double>& start,
                             const AutotuneOptions& options);

/// Generic Nelder-Mead minimiser (used above; exposed for tests).
std::vector<double> nelderMead(const std::function<double(const std::vector<double>&)>& f, std::vector<double> x0,
                               double step, double tolerance, int max_evaluations, std::size_t* evaluations = nullptr);

}  // namespace viewline::tuning
