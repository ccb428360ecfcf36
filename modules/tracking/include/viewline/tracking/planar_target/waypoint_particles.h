#pragma once
// Waypoint particle filter: the Bayes reference for a target on a random polyline.
//
// Model (exactly the simulator's random path, sim::ScreenPath with shape random, in the screen plane's
// coordinates, m): waypoints W_0, W_1, … are drawn independently and uniformly in a known box B
// (filter.region); the target runs from waypoint to waypoint in straight legs at one constant speed s
// (learnt from a uniform prior, or known: speed_min = speed_max, as the replays set it, since our filter
// learns it within the first legs); at a waypoint it heads for the next. The state of particle i is
//   (p_i, W_i, s_i): position, the waypoint it heads for, speed.
// Propagation over dt moves p_i by d = s_i dt towards W_i; if the leg ends first (|W_i − p_i| < d), the
// rest of d is run towards a fresh waypoint W ~ U(B) (legs shorter than min_leg are drawn again, as the
// simulator does). Measurements z = p + v, v ~ N(0, R), with a small uniform outlier mass:
//   w_i ∝ w_i [(1 − ε) N(z; p_i, R) + ε / |B₊|]      (B₊: B grown by 3σ on each side)
// Systematic resampling when the effective sample size falls below N/2, then a small jitter of p, W and
// s (regularisation: without it the deterministic legs would collapse onto a few ancestors). When no
// particle explains reinit_after measurements in a row better than the outlier term, the prior is drawn
// again around the last one (tracking::TrackGate's restart: a measurement no particle explains counts
// as a rejection, although it is still weighted, as the outlier term says).
//
// Given the model and enough particles the weighted mean is the posterior mean E[p(t + h) | z_1..k]:
// the predictor with the least expected squared error, which is what the image error measures. It is
// used as a reference (pan_tilt_tracking --replay <log> --particles; bench/pan_tilt_seeds): what any
// causal filter that knows the path's generator could reach at the law's horizon. It is not a Kalman
// filter; the controller can use it as its target filter (filter.model: waypoint_particles, through
// PlanarTargetFilter, filter.h) to check that bound in the closed loop.
#include <Eigen/Core>
#include <cstddef>
#include <cstdint>
#include <vector>

#include "viewline/core/random.h"
#include "viewline/tracking/track_gate.h"

namespace viewline::tracking {

/// Configuration of the waypoint particle filter: particles, waypoint box, speed prior, jitters, outliers and seed.
struct WaypointParticleConfig {
  std::size_t particles = 20000;  ///< number of particles
  Eigen::Vector2d region_center = Eigen::Vector2d::Zero();  ///< box B of the waypoints (m)
  Eigen::Vector2d region_size = Eigen::Vector2d::Zero();    ///< its width and height (m), > 0
  double min_leg = 0.0;             ///< m, shorter legs are drawn again (the simulator's min segment)
  double speed_min = 0.02;          ///< m/s, uniform speed prior
  double speed_max = 0.5;           ///< m/s (= speed_min: the speed is known)
  double jitter_position = 0.0005;  ///< m, std of the position jitter after a resampling
  double jitter_waypoint = 0.005;   ///< m, std of the waypoint jitter after a resampling (kept in B)
  double jitter_speed = 0.0005;     ///< m/s, std of the speed jitter after a resampling
  /// Probability that a measurement is an outlier (uniform over the grown box), in [0, 1)
  double outlier_probability = 0.01;
  /// Measurements in a row that no particle explains better than an outlier (the cloud lost the target,
  /// e.g. it turned during an occlusion) before the filter starts again from the measurement.
  int reinit_after = 3;
  std::uint64_t seed = 1;  ///< seed of the filter's random stream
  void validate() const;  ///< throws core::InvalidInput
};

/// Particle filter of a target that runs at one speed between waypoints drawn uniformly in a box (plane
/// coordinates, m).
class WaypointParticleFilter {
 public:
  /// Filter with this configuration (validated; throws core::InvalidInput).
  explicit WaypointParticleFilter(const WaypointParticleConfig& config);

  /// True once the first measurement drew the prior.
  bool initialized() const { return initialized_; }
  /// Time of the particles (last measurement or propagation), s.
  double t() const { return t_; }
  /// The first call draws the prior (p ~ N(z, R), W ~ U(B), s ~ U(speed_min, speed_max)); later calls
  /// propagate to t (t ≥ the last stamp) and weight (or draw the prior again: reinit_after). R: the
  /// measurement's covariance (m²).
  void update(double t, const Eigen::Vector2d& z, const Eigen::Matrix2d& R);
  /// Propagates without a measurement (a missed detection).
  void propagateTo(double t);
  /// Posterior mean of the position at t ≥ t(): each particle run ahead once (fresh waypoints drawn
  /// from a stream of its own, so the estimate does not change the filter).
  Eigen::Vector2d predict(double t) const;
  /// Posterior mean position at t(), m.
  Eigen::Vector2d mean() const { return predict(t_); }
  /// Posterior moments at t ≥ t() (particles run ahead as in predict()): the mean position and velocity
  /// (a particle's velocity is s_i towards its waypoint) and their 4 x 4 covariance, order (p, v).
  struct Moments {
    Eigen::Vector2d p = Eigen::Vector2d::Zero(),  ///< mean position, m
                    v = Eigen::Vector2d::Zero();  ///< mean velocity, m/s
    Eigen::Matrix4d P = Eigen::Matrix4d::Zero();  ///< covariance of (p, v), order (p_x, p_y, v_x, v_y)
  };
  /// Posterior moments of (p, v) at t ≥ t().
  Moments moments(double t) const;
  /// Posterior mean of the speed (m/s).
  double speedMean() const;
  /// Effective sample size of the current weights.
  double effectiveSampleSize() const { return ess_; }
  /// Number of resamplings so far.
  std::size_t resamplings() const { return resamplings_; }
  /// Number of restarts from a measurement (reinit_after outliers in a row).
  std::size_t reinitialisations() const { return reinitialisations_; }
  /// The restart gate's decisions (Start: the first measurement; Reject: none of the particles explains it).
  const GateCounts& gateCounts() const { return gate_.counts(); }

 private:
  struct Particle {
    Eigen::Vector2d p, w;
    double s = 0.0;
  };
  Eigen::Vector2d drawWaypoint(const Eigen::Vector2d& from, core::Rng& rng) const;
  void advance(Particle& q, double dt, core::Rng& rng) const;
  void resample();
  void resetWeights();  ///< all weights 1 (after the prior and a resampling)
  /// p ~ N(z, R), W ~ U(B), s ~ U(speed_min, speed_max), at t.
  void drawPrior(double t, const Eigen::Vector2d& z, const Eigen::Matrix2d& R);

  WaypointParticleConfig cfg_;
  core::Rng rng_;
  std::vector<Particle> particles_;
  std::vector<double> log_w_;  ///< log weights, max 0
  std::vector<double> w_;      ///< exp(log_w_)
  double w_sum_ = 0.0, ess_ = 0.0;
  bool initialized_ = false;
  double t_ = 0.0;
  std::size_t resamplings_ = 0, updates_ = 0, reinitialisations_ = 0;
  TrackGate gate_;  ///< restart after reinit_after measurements in a row that no particle explains
};

}  // namespace viewline::tracking
