#pragma once
// Synthetic tracks and scores shared by the planar target filter tests: a corner, a square, random
// polylines through waypoints in a box (the pan-tilt app's random path), and the filter settings
// tuned for them.
#include <gtest/gtest.h>

#include <cmath>
#include <functional>
#include <vector>

#include "viewline/core/random.h"
#include "viewline/tracking/planar_target/filter.h"

namespace viewline::tracking::planar_test {

// RMS position error of x(k|k) over a track (the first second excluded), and the jumps detected.
struct TrackScore {
  double rms = 0.0;
  std::size_t jumps = 0;
  double first_jump_after_corner = -1.0;  ///< s from the corner to the detecting measurement
};
inline TrackScore scoreTrack(const tracking::TargetFilterConfig& cfg, const std::function<Eigen::Vector2d(double)>& truth,
                      double corner_t, std::uint64_t seed) {
  tracking::PlanarTargetFilter f(cfg);
  core::Rng rng = core::makeRng(seed);
  const double sigma = 0.04;  // [T]-like: 10 % of a 0.4 m amplitude
  const Eigen::Matrix2d R = sigma * sigma * Eigen::Matrix2d::Identity();
  double se = 0.0;
  int n = 0;
  TrackScore out;
  for (int k = 0; k < 360; ++k) {
    const double t = k / 30.0;
    const Eigen::Vector2d z = truth(t) + Eigen::Vector2d(core::gaussian(rng, sigma), core::gaussian(rng, sigma));
    const auto u = f.update(t, z, R);
    if (u.jump && out.first_jump_after_corner < 0.0) out.first_jump_after_corner = t - corner_t;
    if (t >= 1.0 && u.accepted) {
      se += (f.estimate().x().head<2>() - truth(t)).squaredNorm();
      ++n;
    }
  }
  out.rms = std::sqrt(se / n);
  out.jumps = f.jumps();
  return out;
}

// A square of side 0.45 m at 0.15 m/s (a 90° corner every 3 s, [T]'s rectangle-like legs), 30 s.
inline Eigen::Vector2d squareTrack(double t) {
  const double side = 0.45, speed = 0.15, s = std::fmod(speed * t, 4.0 * side);
  const int leg = static_cast<int>(s / side);
  const double r = s - leg * side;
  switch (leg) {
    case 0: return {r, 0.0};
    case 1: return {side, r};
    case 2: return {side - r, side};
    default: return {0.0, side - r};
  }
}

struct LongScore {
  double rms = 0.0;
  std::size_t jumps = 0;
  double speed = 0.0;
};
// RMS error of the filter's output estimate after `score_from` (by then the speed is known from the
// first legs), with white noise of std `sigma` per axis on the 30 Hz measurements. With `oracle`, legs
// are started at the true corner times (`corners`, increasing) with the true speed instead.
inline LongScore scoreLegs(const tracking::TargetFilterConfig& cfg, const std::function<Eigen::Vector2d(double)>& track,
                    const std::vector<double>& corners, double speed, const Eigen::Vector2d& sigma,
                    double duration, double score_from, std::uint64_t seed, bool oracle,
                    tracking::PlanarTargetFilter* filter) {
  tracking::PlanarTargetFilter own(cfg);
  tracking::PlanarTargetFilter& f = filter != nullptr ? *filter : own;
  core::Rng rng = core::makeRng(seed);
  const Eigen::Matrix2d R = sigma.cwiseAbs2().asDiagonal();
  double se = 0.0;
  std::size_t next_corner = 0;
  int n = 0;
  const int frames = static_cast<int>(duration * 30.0);
  for (int k = 0; k < frames; ++k) {
    const double t = k / 30.0;
    if (oracle && next_corner < corners.size() && t >= corners[next_corner]) {
      f.setSpeed(speed, 1e-12);
      f.startLeg(corners[next_corner++]);
    }
    const Eigen::Vector2d z = track(t) + Eigen::Vector2d(core::gaussian(rng, sigma.x()), core::gaussian(rng, sigma.y()));
    f.update(t, z, R);
    if (t >= score_from) {
      se += (f.estimate().x().head<2>() - track(t)).squaredNorm();
      ++n;
    }
  }
  return {std::sqrt(se / n), f.jumps(), f.speedEstimate()};
}

// The square above for 30 s, σ = 4 cm, scored after 7 s (two legs).
inline LongScore scoreSquare(const tracking::TargetFilterConfig& cfg, std::uint64_t seed, bool oracle = false,
                      tracking::PlanarTargetFilter* filter = nullptr) {
  std::vector<double> corners;
  for (double t = 3.0; t < 30.0; t += 3.0) corners.push_back(t);
  return scoreLegs(cfg, squareTrack, corners, 0.15, Eigen::Vector2d(0.04, 0.04), 30.0, 7.0, seed, oracle, filter);
}

// A random polyline at 0.15 m/s through waypoints drawn uniformly in a 0.80 x 0.43 m box (the pan-tilt
// app's random path), legs of at least 0.1 m; returns the track and fills the corner times.
inline std::function<Eigen::Vector2d(double)> randomPolyline(std::uint64_t seed, double duration, std::vector<double>& corners) {
  core::Rng rng = core::makeRng(1000 + seed);
  std::vector<Eigen::Vector2d> pts{Eigen::Vector2d::Zero()};
  std::vector<double> times{0.0};
  const double speed = 0.15;
  while (times.back() < duration) {
    const Eigen::Vector2d p(core::uniform(rng, -0.40, 0.40), core::uniform(rng, -0.215, 0.215));
    const double len = (p - pts.back()).norm();
    if (len < 0.1) continue;
    pts.push_back(p);
    times.push_back(times.back() + len / speed);
  }
  corners.assign(times.begin() + 1, times.end() - 1);
  return [pts, times](double t) -> Eigen::Vector2d {
    std::size_t i = 1;
    while (i + 1 < times.size() && times[i] <= t) ++i;
    const double a = (t - times[i - 1]) / (times[i] - times[i - 1]);
    return pts[i - 1] + a * (pts[i] - pts[i - 1]);
  };
}

// The kinks filter for the random path: CV, corners by the kink test, soft mixture from kinks.
inline tracking::TargetFilterConfig randomKinksFilter() {
  tracking::TargetFilterConfig c;
  c.model = tracking::TargetModel::ConstantVelocity;
  c.q = 0.003;
  c.init_velocity_sigma = 0.3;
  c.jump_window = 3.0;
  c.jump_threshold = 15.0;
  c.jump_min_samples = 8;
  c.jump_rate = 0.5;
  c.jump_prior_sigma = 0.2;
  return c;
}

// The legs filter for the random path: constant-speed legs, soft mixture from leg evidence, uniform turn prior.
inline tracking::TargetFilterConfig randomLegsFilter() {
  tracking::TargetFilterConfig c = randomKinksFilter();
  c.q = 1e-5;
  c.jump_rate = 1.0;
  c.constant_speed = true;
  c.constant_speed_sigma = 0.005;
  c.jump_corner_sigma = 0.01;
  c.jump_evidence = "legs";
  return c;
}

// config/pan_tilt_random.yaml's filter: the legs above, the 0.8 x 0.43 m waypoint region, jumps decided
// by the mixture's posterior.
inline tracking::TargetFilterConfig randomRegionFilter() {
  tracking::TargetFilterConfig c = randomLegsFilter();
  c.region_size = Eigen::Vector2d(0.80, 0.43);
  c.jump_decision = "posterior";
  return c;
}

// Mean over the four random polylines (40 s, [T]'s 10 % noise σ 3.6 / 2.1 cm unless `sigma` is given,
// scored after 8 s) of the filter's RMS error; `check` (optional) sees each seed's filter once its track is done.
inline double randomPolylineRms(const tracking::TargetFilterConfig& cfg, bool oracle = false,
                         const std::function<void(std::uint64_t, const tracking::PlanarTargetFilter&)>& check = nullptr,
                         const Eigen::Vector2d& sigma = Eigen::Vector2d(0.036, 0.021)) {
  double rms = 0.0;
  for (std::uint64_t seed = 1; seed <= 4; ++seed) {
    std::vector<double> corners;
    const auto track = randomPolyline(seed, 40.0, corners);
    EXPECT_GE(corners.size(), 10u) << seed;
    tracking::PlanarTargetFilter f(cfg);
    rms += scoreLegs(cfg, track, corners, 0.15, sigma, 40.0, 8.0, seed, oracle, &f).rms / 4.0;
    if (check) check(seed, f);
  }
  return rms;
}

}  // namespace viewline::tracking::planar_test
