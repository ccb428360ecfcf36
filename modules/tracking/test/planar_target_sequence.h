#pragma once
// A seeded measurement sequence that exercises every branch of the planar target filter's gate: a random
// polyline at 0.15 m/s through waypoints in the 0.8 x 0.43 m box, 30 Hz with jittered stamps, noise of
// [T]'s 10 % (σ 3.6 / 2.1 cm), single outliers, bursts of outliers that restart the track, and gaps
// (occlusions) after which a tracker re-initialises.
#include <Eigen/Core>
#include <cstdint>
#include <vector>

#include "viewline/core/random.h"

namespace viewline::tracking::planar_test {

struct SequenceSample {
  double t = 0.0;
  bool detected = false;
  Eigen::Vector2d z = Eigen::Vector2d::Zero();
  Eigen::Matrix2d R = Eigen::Matrix2d::Identity();
};

inline std::vector<SequenceSample> gateSequence(std::uint64_t seed, double duration = 30.0) {
  core::Rng rng = core::makeRng(seed);
  // The path: waypoints uniform in the box, legs of at least 0.1 m.
  std::vector<Eigen::Vector2d> pts{Eigen::Vector2d::Zero()};
  std::vector<double> times{0.0};
  const double speed = 0.15;
  while (times.back() < duration + 1.0) {
    const Eigen::Vector2d p(core::uniform(rng, -0.40, 0.40), core::uniform(rng, -0.215, 0.215));
    const double len = (p - pts.back()).norm();
    if (len < 0.1) continue;
    pts.push_back(p);
    times.push_back(times.back() + len / speed);
  }
  const auto truth = [&](double t) -> Eigen::Vector2d {
    std::size_t i = 1;
    while (i + 1 < times.size() && times[i] <= t) ++i;
    const double a = (t - times[i - 1]) / (times[i] - times[i - 1]);
    return pts[i - 1] + a * (pts[i] - pts[i - 1]);
  };
  const Eigen::Vector2d sigma(0.036, 0.021);
  std::vector<SequenceSample> out;
  int burst = 0;
  double gap_until = -1.0;
  for (int k = 0; k * (1.0 / 30.0) < duration; ++k) {
    SequenceSample s;
    s.t = k / 30.0 + core::uniform(rng, 0.0, 0.004);
    const double scale = core::uniform(rng, 0.8, 1.25);  // the noise level changes (the "auto" settings see it)
    s.R = (scale * sigma).cwiseAbs2().asDiagonal();
    if (gap_until < 0.0 && core::uniform(rng, 0.0, 1.0) < 0.004) gap_until = s.t + core::uniform(rng, 0.3, 2.5);
    s.detected = !(s.t < gap_until);
    if (!s.detected) {
      out.push_back(s);
      continue;
    }
    gap_until = -1.0;
    s.z = truth(s.t) + Eigen::Vector2d(core::gaussian(rng, scale * sigma.x()), core::gaussian(rng, scale * sigma.y()));
    if (burst == 0 && core::uniform(rng, 0.0, 1.0) < 0.01) burst = core::uniform(rng, 0.0, 1.0) < 0.5 ? 1 : 4;
    if (burst > 0) {
      --burst;
      s.z += Eigen::Vector2d(core::uniform(rng, -0.3, 0.3), core::uniform(rng, -0.3, 0.3));
    }
    out.push_back(s);
  }
  return out;
}

}  // namespace viewline::tracking::planar_test
