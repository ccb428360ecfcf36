#include "viewline/core/random.h"

#include <Eigen/Eigenvalues>

#include "viewline/core/checks.h"

namespace viewline::core {

std::uint64_t deriveSeed(std::uint64_t seed, std::uint64_t stream) {
  // splitmix64 of (seed, stream): well-spread, cheap and stable across platforms.
  std::uint64_t z = seed + 0x9E3779B97F4A7C15ULL * (stream + 1);
  z = (z ^ (z >> 30)) * 0xBF58476D1CE4E5B9ULL;
  z = (z ^ (z >> 27)) * 0x94D049BB133111EBULL;
  return z ^ (z >> 31);
}

Rng makeRng(std::uint64_t seed) { return Rng(deriveSeed(seed, 0)); }

double gaussian(Rng& rng, double sigma) {
  std::normal_distribution<double> n(0.0, sigma);
  return n(rng);
}

double uniform(Rng& rng, double lo, double hi) {
  std::uniform_real_distribution<double> u(lo, hi);
  return u(rng);
}

Eigen::VectorXd sampleGaussian(Rng& rng, const Eigen::VectorXd& mean, const Eigen::MatrixXd& cov) {
  requireSize(cov, mean.size(), mean.size(), "sampleGaussian: covariance");
  requireSymmetricPositiveSemiDefinite(cov, "sampleGaussian: covariance");
  // Eigen-decomposition works for singular (semi-definite) covariances too.
  Eigen::SelfAdjointEigenSolver<Eigen::MatrixXd> es(cov);
  const Eigen::VectorXd sd = es.eigenvalues().cwiseMax(0.0).cwiseSqrt();
  Eigen::VectorXd z(mean.size());
  for (Eigen::Index i = 0; i < z.size(); ++i) z[i] = gaussian(rng);
  return mean + es.eigenvectors() * sd.asDiagonal() * z;
}

}  // namespace viewline::core
