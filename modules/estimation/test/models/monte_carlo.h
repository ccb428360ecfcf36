#pragma once
// Test helper: seeded Monte-Carlo consistency runs of a linear model.
//
// Each run draws x(0) ~ N(m0, P0), simulates the model's own discrete process
// (x ← Φ x + Γ u + v, v drawn from the transition's Q) and measurements
// (y = C x + e, e drawn from R), and runs the filter with the transition's Q
// multiplied by `q_scale` (1 = the true model; 0.1 = 10× too small). One NEES
// per run at the final step, so the samples are independent and the
// chi-square band of their average is valid.

#include <gtest/gtest.h>

#include <Eigen/Cholesky>
#include <Eigen/Eigenvalues>
#include <cstdint>
#include <functional>
#include <iostream>
#include <string>
#include <vector>

#include "viewline/core/error.h"
#include "viewline/core/random.h"
#include "viewline/estimation/consistency.h"
#include "viewline/estimation/kalman_filter.h"

namespace viewline::estimation::test {

/// Zero-mean Gaussian draws with a fixed covariance (symmetric PSD, possibly singular).
class NoiseSampler {
public:
  NoiseSampler() = default;
  explicit NoiseSampler(const Eigen::MatrixXd& cov) {
    Eigen::SelfAdjointEigenSolver<Eigen::MatrixXd> es(cov);
    F_ = es.eigenvectors() * es.eigenvalues().cwiseMax(0.0).cwiseSqrt().asDiagonal();
  }
  Eigen::VectorXd operator()(core::Rng& rng) const {
    Eigen::VectorXd z(F_.cols());
    for (Eigen::Index i = 0; i < z.size(); ++i) z[i] = core::gaussian(rng);
    return F_ * z;
  }

private:
  Eigen::MatrixXd F_;
};

inline Eigen::VectorXd drawNoise(core::Rng& rng, const Eigen::MatrixXd& cov) { return NoiseSampler(cov)(rng); }

struct LinearMcSetup {
  std::function<LinearTransition(int step)> transition;  ///< the true transition of step k
  std::function<LinearMeasurement()> measurement;         ///< C and R (y is filled in)
  Eigen::VectorXd m0;
  Eigen::MatrixXd P0;
  int steps = 50;
  int runs = 300;
  std::uint64_t seed = 1;
};

inline ConsistencyStats runLinearMc(const LinearMcSetup& setup, double q_scale) {
  ConsistencyStats stats;
  // The transitions are the same for every run: build them once.
  std::vector<LinearTransition> truth, filt;
  std::vector<NoiseSampler> qs;
  for (int k = 0; k < setup.steps; ++k) {
    truth.push_back(setup.transition(k));
    qs.emplace_back(truth.back().Q);
    filt.push_back(truth.back());
    filt.back().Q *= q_scale;
  }
  const LinearMeasurement meas0 = setup.measurement();
  const NoiseSampler rs(meas0.R), p0s(setup.P0);
  for (int run = 0; run < setup.runs; ++run) {
    core::Rng rng(core::deriveSeed(setup.seed, static_cast<std::uint64_t>(run)));
    Eigen::VectorXd x = setup.m0 + p0s(rng);
    StateEstimate s(setup.m0, setup.P0);
    for (int k = 0; k < setup.steps; ++k) {
      const LinearTransition& tr = truth[static_cast<std::size_t>(k)];
      x = tr.Phi * x + qs[static_cast<std::size_t>(k)](rng);
      if (tr.u.size() > 0) x += tr.Gamma * tr.u;
      predict(s, filt[static_cast<std::size_t>(k)]);
      LinearMeasurement m = meas0;
      m.y = m.C * x + rs(rng);
      update(s, m);
    }
    stats.add(nees(s, x), static_cast<double>(x.size()));
  }
  return stats;
}

/// Expects `fn` to throw core::InvalidInput whose message contains `field`.
template <class Fn>
void expectInvalid(Fn fn, const std::string& field) {
  try {
    fn();
    ADD_FAILURE() << "expected core::InvalidInput naming " << field;
  } catch (const core::InvalidInput& e) {
    EXPECT_NE(std::string(e.what()).find(field), std::string::npos) << e.what();
  }
}

inline void report(const char* what, const ConsistencyStats& st) {
  const core::Interval b = st.bounds(0.99);
  std::cout << "  " << what << ": mean NEES " << st.mean() << " over " << st.count() << " runs, 99% band [" << b.lo
            << ", " << b.hi << "]\n";
}

inline void expectConsistent(const ConsistencyStats& st) {
  report("consistent filter", st);
  const core::Interval b = st.bounds(0.99);
  EXPECT_TRUE(b.contains(st.mean())) << "mean NEES " << st.mean() << " outside [" << b.lo << ", " << b.hi << "]";
}

inline void expectOverconfident(const ConsistencyStats& st) {
  report("filter with Q/10", st);
  const core::Interval b = st.bounds(0.99);
  EXPECT_GT(st.mean(), b.hi) << "mean NEES " << st.mean() << " band [" << b.lo << ", " << b.hi << "]";
}

}  // namespace viewline::estimation::test
