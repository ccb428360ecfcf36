#pragma once
// Constant-speed legs of the planar target filter (TargetFilterConfig::constant_speed, cv, with jump
// detection), and the turn angles learnt at the corners between them.
//
// The target moves along straight legs
// at one unknown speed s (a polyline at constant speed). At each detected jump the leg that ended gives
// a speed measurement s_k = |b|, b the slope of a weighted least-squares line through its measurements
// (var s_k = b̂ᵀ cov(b) b̂), and ŝ is their inverse-variance mean (kept across re-initialisations:
// the target's speed does not change when it is lost). Once ŝ is known, each jump starts a
// leg p(t) = c + s (t − t_c) u(θ) from the corner c ~ N(x(j|j) position, its covariance + σ_c² I,
// σ_c = jump_corner_sigma) at the jump time t_c, with s ~ N(ŝ, var ŝ + constant_speed_sigma²) and θ
// uniform: (c, s) is marginalised in closed form, the posterior of θ is evaluated on a grid (refined
// around the mode as it narrows), and the filter's state is the posterior's moments of (p, v). After a
// corner only the direction is learnt (one unknown instead of a 2-D velocity), without linearising.
// The leg's start is re-chosen within ±6 measurements of the test's t_j by evidence (straight on
// until t_j', then the leg): a leg started a few samples off bends towards the old direction.
// Learnt turn angles (turn_prior_weight w > 0): at every detected jump the turn of the leg that ended
// (its direction, that of x(j|j)'s velocity, minus the previous leg's) is remembered, the last 8 kept;
// a new leg's θ then has the prior p(θ) = (1 − w) / 2π + w / K Σ_k N_wrapped(θ; θ_old + Δ_k, σ_Δ²),
// θ_old the direction of the leg that ended, Δ_k the remembered turns, σ_Δ = turn_prior_sigma_deg.
// A target that repeats its manoeuvres (a rectangle, a patrol route) thus has its new direction
// nearly known at the corner; random turns give a diffuse prior, and w < 1 keeps any direction open.
//
// One leg: measurements z_i = c + s τ_i u(θ) + e_i, τ_i = t_i − t_c,
// e_i ~ N(0, R_i), θ uniform, and β = (c, s) ~ N(β₀, P₀) with β₀ = (ĉ, ŝ), P₀ = diag(P_c, σ_s²). Given θ
// the model is linear in β (H_i = [I  τ_i u]), so β is marginalised in closed form from the sufficient
// statistics A = Σ R_i⁻¹, B_z = Σ R_i⁻¹ z_i, B_τ = Σ τ_i R_i⁻¹, C_τz = Σ τ_i R_i⁻¹ z_i, C_ττ = Σ τ_i² R_i⁻¹,
// zz = Σ z_iᵀ R_i⁻¹ z_i:
//   Λ(θ) = P₀⁻¹ + [[A, B_τ u], [uᵀ B_τ, uᵀ C_ττ u]],  η(θ) = P₀⁻¹ β₀ + (B_z, uᵀ C_τz),
//   β | θ ~ N(Λ⁻¹ η, Λ⁻¹),  log p(z | θ) = −½ (zz + β₀ᵀ P₀⁻¹ β₀ − ηᵀ Λ⁻¹ η) − ½ log det Λ  (+ const).
// The speed is thus re-estimated on every leg around the learnt ŝ (it absorbs a scale error of the
// measurements), and only θ needs a grid. θ's prior is uniform, or the learnt-turn mixture
// p(θ) = (1 − w) / 2π + w / K Σ_k N_wrapped(θ; μ_k, σ²), times the waypoint-region prior R(θ)² / 2A when a
// region is set (normalised on a grid when both are on): logPrior() is log(2π p(θ)), 0 when uniform.

#include <Eigen/Core>
#include <cstdint>
#include <functional>
#include <limits>
#include <memory>
#include <vector>

#include "viewline/core/time.h"
#include "viewline/estimation/state.h"
#include "viewline/tracking/planar_target/history.h"

namespace viewline::tracking {

/// One leg's prior and the sufficient statistics of its measurements (the model above).
struct ConstantSpeedLeg {
  double t_c = 0.0;  ///< corner time t_c, s
  /// Prior mean β₀ = (ĉ_x, ĉ_y, ŝ) of the corner position (m) and speed (m/s)
  Eigen::Vector3d beta0 = Eigen::Vector3d::Zero();
  Eigen::Matrix3d P0_inv = Eigen::Matrix3d::Identity();  ///< prior information P₀⁻¹ of β
  std::vector<double> prior_mu;  ///< μ_k (rad); empty: θ uniform
  double prior_sigma = 0.1,   ///< σ of each learnt-turn component, rad
         prior_weight = 0.0;  ///< weight w of the learnt-turn mixture in θ's prior
  bool region = false;            ///< waypoint-region prior p(θ) = R(θ)² / (2A) from region_c
  Eigen::Vector2d region_c = Eigen::Vector2d::Zero(),   ///< corner the region prior is taken from, m
                  region_lo = Eigen::Vector2d::Zero(),  ///< lower corner of the waypoint box, m
                  region_hi = Eigen::Vector2d::Zero();  ///< upper corner of the waypoint box, m
  double region_log_scale = 0.0;  ///< log(π / A)
  double log_norm = 0.0;          ///< normalises the product of the two priors (0 when at most one is on)
  Eigen::Matrix2d A = Eigen::Matrix2d::Zero(),    ///< Σ R_i⁻¹
                  Bt = Eigen::Matrix2d::Zero(),   ///< B_τ = Σ τ_i R_i⁻¹
                  Ctt = Eigen::Matrix2d::Zero();  ///< C_ττ = Σ τ_i² R_i⁻¹
  Eigen::Vector2d Bz = Eigen::Vector2d::Zero(),   ///< B_z = Σ R_i⁻¹ z_i
                  Ctz = Eigen::Vector2d::Zero();  ///< C_τz = Σ τ_i R_i⁻¹ z_i
  double zz = 0.0;  ///< Σ z_iᵀ R_i⁻¹ z_i
  /// Optional: logPrior(θ_k) at θ_k = −π + 2π k / N, k < N = its size (logEvidence(N) reads it instead of
  /// evaluating logPrior; the same values, made by logPriorOnGrid from this leg's prior fields).
  std::shared_ptr<const std::vector<double>> log_prior_evidence;
  /// Optional: logPrior(θ_k) at θ_k = −π + (2π / 180) k, k < 180: moments()' first grid, as above.
  std::shared_ptr<const std::vector<double>> log_prior_moments;

  /// Adds the measurement z (covariance R) at t to the statistics.
  void add(double t, const Eigen::Vector2d& z, const Eigen::Matrix2d& R);
  /// The statistics A, B_z, B_τ, C_τz, C_ττ, zz of `from` (a leg of the same t_c), the prior fields kept.
  void copySums(const ConstantSpeedLeg& from);
  /// log(2π p(θ)): 0 when θ is uniform.
  double logPrior(double th) const;
  /// logPrior(th) with u = (cos th, sin th) given (the region prior's direction, not evaluated again).
  double logPrior(double th, const Eigen::Vector2d& u) const;
  /// −log of the mean of 2π p(θ_k) = exp(logPrior(θ_k)) over θ_k = −π + 2π k / points: the log_norm that
  /// normalises the prior on that grid.
  double logPriorNormalisation(int points) const;
  /// log p(z | θ) (up to a constant), and the posterior mean and covariance of β = (c, s) given θ.
  double logLikelihood(double th, Eigen::Vector3d* m = nullptr, Eigen::Matrix3d* cov = nullptr) const;
  /// log p(measurements | leg) up to the terms every candidate corner time shares (see the source).
  double logEvidence(int points = 360) const;
  /// The posterior moments of (p, v) at time t (p = c + s (t − t_c) u, v = s u).
  estimation::StateEstimate moments(double t) const;
  /// logPrior on the evidence grid of `points` (evidence = true: θ_k = −π + 2π k / points) or on moments()'
  /// first grid (θ_k = −π + (2π / points) k), for the tables above.
  std::vector<double> logPriorOnGrid(int points, bool evidence) const;
};

/// The θ grid legBayesFactor integrates on: steps of 3° or the turn prior's σ (deg) if smaller.
int legEvidencePoints(double turn_prior_sigma_deg);

/// Makes the leg from the corner (t_c, c ~ N(c, P_c)); from_direction: the direction (rad) of the leg
/// that ended there, centre of the learnt turn prior (NaN: θ uniform). The filter's current priors.
using LegFactory = std::function<ConstantSpeedLeg(core::Timestamp t_c, const Eigen::Vector2d& c,
                                                  const Eigen::Matrix2d& P_c, double from_direction)>;

/// The target's one speed ŝ, learnt from the legs between detected jumps (inverse-variance mean of
/// each leg's least-squares speed), or set from outside.
class LegSpeed {
public:
  /// s_k of the segment history[0..end] (skipped when shorter than 0.5 s or 2 min_samples measurements,
  /// or when its speed is not resolved).
  void learn(const PlanarHistory& history, std::size_t end, int min_samples);
  /// Sets ŝ (m/s) and its variance (m²/s²) from outside.
  void set(double speed, double variance);
  /// True once ŝ is known (learnt or set).
  bool known() const { return info_ > 0.0; }
  /// ŝ (m/s) and its variance; 0 / 1e300 before the first segment has ended.
  double estimate() const { return info_ > 0.0 ? sum_ / info_ : 0.0; }
  /// Variance of ŝ, m²/s² (1e300 before the first segment has ended).
  double variance() const { return info_ > 0.0 ? 1.0 / info_ : 1e300; }

private:
  double sum_ = 0.0, info_ = 0.0;  ///< Σ s_k / var s_k, Σ 1 / var s_k
};

/// The turn angles of the last corners (turn_prior_weight > 0; the last 8 kept).
class LearntTurns {
public:
  /// Learns turns only when `enabled` (turn_prior_weight > 0).
  explicit LearntTurns(bool enabled) : enabled_(enabled) {}
  /// A leg of this direction (rad; NaN: unknown) ended at a detected jump.
  void legEnded(double direction);
  /// The track restarted: the next leg's predecessor is unknown (the turns are kept).
  void forgetDirection() { last_direction_ = std::numeric_limits<double>::quiet_NaN(); }
  /// rad, in [−π, π], oldest first.
  const std::vector<double>& turns() const { return turns_; }

private:
  bool enabled_;
  std::vector<double> turns_;
  double last_direction_ = std::numeric_limits<double>::quiet_NaN();  ///< of the leg before the current one
};

/// log BF of "a constant-speed leg from x(j|j) at t_j" against "straight on from x(j|j)" for the
/// measurements after history[j] (the soft mixture's jump_evidence "legs"); turn_prior_sigma_deg sets
/// the θ grid.
double legBayesFactor(const PlanarHistory& history, int j, const LegFactory& make, double turn_prior_sigma_deg);

/// legBayesFactor for the candidate corners of successive scans, from sums kept between the scans. Per
/// candidate history[j]: the leg's statistics and the straight-on fit's information Λ, vector η and
/// Σ zᵀR⁻¹z over the measurements after it. A scan adds to them only the measurements that arrived since the
/// previous one, each to the sum so far in the order legBayesFactor adds them (history[j+1], ..., history[n−1]),
/// so every sum, and the factor, is legBayesFactor's to the last bit (its O(n) sums per candidate per scan
/// become O(1)). Candidates are told apart by PlanarSnapshot::serial; one that left the history is dropped.
class LegBayesFactors {
public:
  /// Drops the candidates no longer in `history` (call before each scan; no allocation).
  void sync(const PlanarHistory& history);
  /// legBayesFactor(history, j, make, turn_prior_sigma_deg) from the kept sums, brought up to date first.
  double operator()(const PlanarHistory& history, int j, const LegFactory& make, double turn_prior_sigma_deg);
  /// The leg statistics over history[j+1..n−1] (ConstantSpeedLeg's sums, t_c = history[j].t) when they are
  /// up to date with the history's last measurement, else nullptr (a candidate this scan did not score).
  const ConstantSpeedLeg* legSums(const PlanarHistory& history, int j) const;
  /// Drops every candidate.
  void clear() { candidates_.clear(); }

  /// One candidate corner: legBayesFactor's two fits from x(j|j), without the leg's prior (made at evaluation).
  struct Candidate {
    /// From history[j] (serial, t, state), no measurement summed yet.
    explicit Candidate(const PlanarSnapshot& sj);
    /// Adds the measurement of snapshot si (after the corner) to both fits.
    void add(const PlanarSnapshot& si);
    /// log BF (legBayesFactor) from the sums so far and the leg make() gives for the corner.
    double value(const LegFactory& make, double turn_prior_sigma_deg) const;

    std::uint64_t serial = 0;  ///< of the corner's snapshot
    std::uint64_t last = 0;    ///< serial of the last measurement summed (the corner's own: none)
    Eigen::Vector4d x = Eigen::Vector4d::Zero();          ///< x(j|j)'s (p, v)
    Eigen::Matrix2d P_pos = Eigen::Matrix2d::Zero();      ///< its position covariance (+ 1e-10 I), make's P_c
    double direction = 0.0;                               ///< velocityDirection(x(j|j)), make's from_direction
    Eigen::Matrix4d P_inv = Eigen::Matrix4d::Zero();      ///< (P + 1e-10 I)⁻¹
    double logdet_P = 0.0;                                ///< log det (P + 1e-10 I)
    Eigen::Matrix4d L = Eigen::Matrix4d::Zero();          ///< straight on: Λ = P⁻¹ + Σ H_iᵀR_i⁻¹H_i
    Eigen::Vector4d eta = Eigen::Vector4d::Zero();        ///< straight on: η = P⁻¹ x̂ + Σ H_iᵀR_i⁻¹z_i
    double zz = 0.0;                                      ///< straight on: Σ z_iᵀR_i⁻¹z_i
    ConstantSpeedLeg leg;                                 ///< t_c and the leg's statistics (no prior)
  };

private:
  std::vector<Candidate> candidates_;  ///< by serial, increasing
};

/// The constant-speed leg's most likely start within ±6 measurements of history[j] (see the source).
int refineCornerTime(const PlanarHistory& history, int j, const LegFactory& make);

}  // namespace viewline::tracking
