#pragma once
// Seeded randomness. One engine is created from the run's seed and passed to
// whoever draws numbers; nothing draws from a global engine, so every run is
// reproducible from its seed.

#include <Eigen/Core>
#include <cstdint>
#include <random>

namespace viewline::core {

/// The one random engine type: seeded once per run and passed in, so every run is reproducible.
using Rng = std::mt19937_64;

/// An engine seeded from `seed` (mixed so that nearby seeds give unrelated streams).
Rng makeRng(std::uint64_t seed);

/// A seed derived from a parent seed and a stream index (e.g. run number).
std::uint64_t deriveSeed(std::uint64_t seed, std::uint64_t stream);

/// N(0, sigma²).
double gaussian(Rng& rng, double sigma = 1.0);

/// U(lo, hi).
double uniform(Rng& rng, double lo, double hi);

/// A draw of N(mean, cov); cov must be symmetric positive semi-definite.
Eigen::VectorXd sampleGaussian(Rng& rng, const Eigen::VectorXd& mean, const Eigen::MatrixXd& cov);

}  // namespace viewline::core
