#pragma once
// Pan-tilt visual servoing ([T], SPEC §5): keep a moving target at the image centre.
//
// Baseline (ViSP's own PTU-46 / Biclops examples): a point feature s = (x, y)
// (normalised image coordinates of the target, depth fixed at Z = 1), desired
// s* = (0, 0), task EYEINHAND_L_cVe_eJe:
//
//     q̇ = −λ (L cVe eJe)⁺ (s − s*)                                      (1)
//
// with L the 2x6 interaction matrix of the point (at s* for "desired", at s for
// "current"), cVe and eJe from the unit's kinematic model (vpPtu46). No
// prediction: the law reacts to where the target *was* when the image was taken.
//
// Ours: the same law plus feed-forward of the target motion predicted by a
// Kalman filter, with the latency compensated. The filter estimates the target
// on its (known) plane, in plane coordinates (m), with a constant-velocity,
// constant-acceleration (Wiener) or Singer model. At the issue time t of a
// command that acts from t_e = t + latency (+ lead), it predicts the target
// position P̂ and velocity V̂ at t_e, and the joints q_e at t_e (the drive model
// with the commands still in flight, robots::predictJointState). With the
// target in the camera at q_e, P_c = c_M_f(q_e) P̂ = (X, Y, Z), ŝ = (X/Z, Y/Z),
// and V_c = c_R_f(q_e) V̂, the feature motion that the target alone causes is
//
//     ṡ_T = ((V_cx − x V_cz) / Z, (V_cy − y V_cz) / Z),
//
// and the command is
//
//     q̇ = −λ J⁺ (ŝ − s*) − J⁺ ṡ_T,    J = L cVe eJe(q_e)                (2)
//
// so that ṡ = J q̇ + ṡ_T = −λ (ŝ − s*): the error decays at rate λ instead of
// settling at the lag ṡ_T / λ of law (1). J⁺ is vpServo's own pseudo-inverse.
// λ of (2) is PredictiveConfig::gain when set (the baseline keeps servo.gain): law
// (2) acts on the predicted error at the effect time, so a higher λ follows the
// filter's corrections faster without the delay that limits law (1)'s gain.
//
// Both laws' outputs go through robots::limitVelocityCommand (rate limit, and
// joint limits with braking from the predicted state at the effect time), so no
// command outside the limits is ever issued.
//
// Target lost (ours): for `coast_time` after the last accepted measurement the
// law keeps following the prediction (an occlusion shorter than that is
// bridged); after it, a search: an Archimedean spiral in joint space around the
// joints that pointed at the last prediction, growing at `search_growth` rad per
// turn up to `search_radius`, at `search_speed` rad/s along the path. The first
// detection after a loss re-initialises the filter at the measurement
// (reacquisition). While tracking, a measurement whose NIS exceeds the
// chi-square gate is rejected; `reinit_after` consecutive rejections also
// re-initialise the filter. The baseline stops (zero velocity) when the target is
// not detected, as the ViSP examples do.

#include <Eigen/Geometry>
#include <cstdint>
#include <limits>
#include <memory>
#include <optional>
#include <string>
#include <vector>
#include <visp3/core/vpMatrix.h>
#include <visp3/core/vpVelocityTwistMatrix.h>

#include "viewline/control/waypoint_particle_filter.h"
#include "viewline/core/time.h"
#include "viewline/estimation/discretization.h"
#include "viewline/estimation/imm.h"
#include "viewline/estimation/state.h"
#include "viewline/robots/pan_tilt_kinematics.h"
#include "viewline/robots/pan_tilt_unit.h"

namespace viewline::control {

// ---------------------------------------------------------------------------------------------
// The ViSP law (1).

struct PointServoConfig {
  double gain = 0.2;                     ///< λ (1/s)
  std::string interaction = "desired";   ///< "desired" (L at s*), "current" (L at s) or "mean"
  void validate() const;                 ///< throws core::InvalidInput naming the field
};

class VispPointServo {
public:
  explicit VispPointServo(const PointServoConfig& config = {});
  ~VispPointServo();
  VispPointServo(const VispPointServo&) = delete;
  VispPointServo& operator=(const VispPointServo&) = delete;

  /// q̇ = −λ (L cVe eJe)⁺ (s − s*) for the normalised point s (depth 1), s* = (0, 0).
  Eigen::Vector2d command(const Eigen::Vector2d& s, const vpVelocityTwistMatrix& cVe, const vpMatrix& eJe);
  /// (L cVe eJe)⁺ (2 x 2) of the last command().
  Eigen::Matrix2d jacobianPinv() const;
  const PointServoConfig& config() const { return config_; }

private:
  struct Impl;
  PointServoConfig config_;
  std::unique_ptr<Impl> impl_;
};

// ---------------------------------------------------------------------------------------------
// The planar target filter.

enum class TargetModel { ConstantVelocity, ConstantAcceleration, Singer, CoordinatedTurn, Imm, WaypointParticles };
/// "constant_velocity" | "cv", "constant_acceleration" | "ca", "singer", "coordinated_turn" | "ct", "imm",
/// "waypoint_particles"
TargetModel targetModelFromString(const std::string& name);
const char* toString(TargetModel model);

struct TargetFilterConfig {
  TargetModel model = TargetModel::ConstantVelocity;
  double q = 0.05;                 ///< CV: acceleration density (m²/s³); CA: jerk density (m²/s⁵)
  double singer_tau = 2.0;         ///< Singer manoeuvre time constant (s)
  double singer_sigma = 0.2;       ///< Singer acceleration std (m/s²)
  double init_velocity_sigma = 0.5;      ///< prior std of the velocity at (re)initialisation (m/s)
  double init_acceleration_sigma = 0.5;  ///< prior std of the acceleration (m/s²), CA/Singer
  double init_omega_sigma = 1.0;         ///< prior std of the turn rate (rad/s), CT/IMM
  double ct_q_accel = 1e-4;              ///< CT (and the IMM's CT mode): acceleration density (m²/s³)
  double ct_q_omega = 1e-3;              ///< CT/IMM: turn-rate random-walk density (rad²/s³)
  double maneuver_q = 0.5;               ///< IMM manoeuvre mode: CV acceleration density (m²/s³)
  Eigen::Vector3d imm_sojourn{5.0, 5.0, 0.2};  ///< IMM mean sojourn times (s) of the cv, ct, manoeuvre modes
  double jump_window = 0.0;              ///< s searched back for a velocity jump (GLR; 0: no jump detection)
  double jump_threshold = 20.0;          ///< GLR statistic (χ², 2 dof) that declares a jump
  /// Measurements after a candidate jump time before it is tested; nullopt: "auto", scaled to the
  /// noise and the target's step per measurement (see "Noise-scaled corner settings" below).
  std::optional<int> jump_min_samples = 4;
  bool constant_speed = false;           ///< constant-speed legs after each jump (cv; see PlanarTargetFilter)
  double constant_speed_sigma = 0.002;   ///< m/s, std of a leg's speed about the learnt ŝ (beside var ŝ)
  /// m, added to the corner's position std when a leg starts; nullopt: "auto" (noise-scaled, see below).
  std::optional<double> jump_corner_sigma = 0.0;
  double turn_prior_weight = 0.0;        ///< constant-speed legs: prior mass on the learnt turn angles (0: θ uniform)
  double turn_prior_sigma_deg = 10.0;    ///< std (deg) of each learnt turn angle in that prior
  double jump_rate = 0.0;                ///< 1/s, prior rate of jumps; > 0: soft jump mixture (see below)
  double jump_prior_sigma = 0.15;        ///< m/s, prior std of a velocity jump per axis (soft mixture)
  std::string jump_evidence = "kink";    ///< soft mixture's Bayes factors: "kink" (free Δv) or "legs" (see below)
  std::string jump_decision = "test";    ///< what declares a jump: "test" (jump_threshold) or "posterior" (see below)
  double jump_posterior = 0.99;          ///< "posterior": the soft mixture's jump mass that declares a jump
  /// Waypoint region (constant-speed legs; size 0: none): the target turns at points spread uniformly over
  /// this box (plane coordinates, m) and never leaves it. See "Waypoint region" below.
  Eigen::Vector2d region_center = Eigen::Vector2d::Zero();
  Eigen::Vector2d region_size = Eigen::Vector2d::Zero();  ///< (width, height), m
  bool hasRegion() const { return region_size.x() > 0.0 && region_size.y() > 0.0; }
  /// waypoint_particles (not a Kalman filter; see "Waypoint particles" below): particle count, the uniform
  /// prior of the target's one speed (m/s; equal ends: the speed is known), the generator's shortest leg
  /// (m) and the particles' random stream.
  std::size_t particles = 20000;
  Eigen::Vector2d particle_speed{0.02, 0.5};
  double particle_min_leg = 0.0;
  std::uint64_t particle_seed = 1;
  double gate_probability = 0.9999;      ///< chi-square (2 dof) gate on the NIS
  int reinit_after = 3;                  ///< consecutive gated-out measurements that re-initialise
  void validate() const;
};

/// The density p(θ) = R(θ)² / (2A) of the direction θ from c to a point drawn uniformly in the box
/// (centre, size = (width, height), area A), R(θ) the distance from c to the box's boundary along
/// (cos θ, sin θ); c is clamped into the box. ∫ p dθ over [−π, π) = 1. (The waypoint-region prior.)
double waypointDirectionDensity(const Eigen::Vector2d& c, const Eigen::Vector2d& center, const Eigen::Vector2d& size,
                                double theta);

/// "auto" corner settings (TargetFilterConfig::jump_min_samples / jump_corner_sigma unset; see the filter's
/// comment "Noise-scaled corner settings").
inline constexpr double kAutoJumpSamplesScale = 2.44;
inline constexpr int kAutoJumpSamplesMax = 30;
inline constexpr double kAutoCornerSigmaPerNoise = 0.34;

/// Kalman filter of a target moving on a plane, state (p, v[, a]) in plane coordinates (m),
/// models built as continuous-time systems and discretised exactly (estimation::discretize,
/// Van Loan) for the actual interval of every step:
///   CV:     ṗ = v, v̇ = w,                 w ~ q I₂
///   CA:     ṗ = v, v̇ = a, ȧ = w,          w ~ q I₂
///   Singer: ṗ = v, v̇ = a, ȧ = −a/τ + w,   w ~ (2 σm² / τ) I₂
///   CT:     state (p, v, ω), coordinated turn (estimation/models/coordinated_turn.h), EKF
///   IMM:    state (p, v, ω), three modes (estimation/imm.h): "cv" = CV with density q (ω kept,
///           random walk ct_q_omega), "ct" = CT (ct_q_accel, ct_q_omega), "maneuver" = CV with
///           density maneuver_q; mean sojourn times imm_sojourn, jumps uniform to the other modes.
///           (CT alone is the one-mode IMM, i.e. a plain EKF.)
/// Measurement: the position, y = [I 0] x + e, cov e = R.
/// Jump detection (jump_window > 0, any model): a generalised likelihood-ratio test for a step in
/// velocity at one of the measurement times of the last jump_window seconds (a corner of a
/// polyline at constant speed); on detection the filter restarts from its estimate at that time
/// with the velocity prior re-opened and processes the later measurements again (detectJump()).
/// Constant-speed legs (constant_speed, cv, with jump detection): the target moves along straight legs
/// at one unknown speed s (a polyline at constant speed). At each detected jump the leg that ended gives
/// a speed measurement s_k = |b|, b the slope of a weighted least-squares line through its measurements
/// (var s_k = b̂ᵀ cov(b) b̂), and ŝ is their inverse-variance mean (kept across re-initialisations:
/// the target's speed does not change when it is lost). Once ŝ is known, each jump starts a
/// leg p(t) = c + s (t − t_c) u(θ) from the corner c ~ N(x(j|j) position, its covariance + σ_c² I,
/// σ_c = jump_corner_sigma) at the jump time t_c, with s ~ N(ŝ, var ŝ + constant_speed_sigma²) and θ
/// uniform: (c, s) is marginalised in closed form, the posterior of θ is evaluated on a grid (refined
/// around the mode as it narrows), and the filter's state is the posterior's moments of (p, v). After a
/// corner only the direction is learnt (one unknown instead of a 2-D velocity), without linearising.
/// The leg's start is re-chosen within ±6 measurements of the test's t_j by evidence (straight on
/// until t_j', then the leg): a leg started a few samples off bends towards the old direction.
/// Learnt turn angles (turn_prior_weight w > 0): at every detected jump the turn of the leg that ended
/// (its direction, that of x(j|j)'s velocity, minus the previous leg's) is remembered, the last 8 kept;
/// a new leg's θ then has the prior p(θ) = (1 − w) / 2π + w / K Σ_k N_wrapped(θ; θ_old + Δ_k, σ_Δ²),
/// θ_old the direction of the leg that ended, Δ_k the remembered turns, σ_Δ = turn_prior_sigma_deg.
/// A target that repeats its manoeuvres (a rectangle, a patrol route) thus has its new direction
/// nearly known at the corner; random turns give a diffuse prior, and w < 1 keeps any direction open.
/// Soft jump mixture (jump_rate > 0; cv, ca, singer): between detected jumps the output is not the
/// filter's x(k|k) alone but the posterior mixture of "no jump in the window" and "a jump at t_j"
/// for the window's measurement times, with prior probability jump_rate × (t_j − t_{j−1}) and Bayes
/// factor from the same fits as the test, the jump having the prior Δv ~ N(0, jump_prior_sigma² I);
/// so the estimate starts to turn before the test is sure of a corner (estimate(), at()).
/// With jump_evidence "legs" (constant-speed legs, once ŝ is known) the Bayes factor of "a jump at t_j"
/// is instead the evidence of the measurements after t_j under a constant-speed leg from x(j|j) (θ with
/// its learnt-turn prior) over their evidence under "straight on from x(j|j)" (both linear-Gaussian,
/// closed form): a specific alternative (this speed, these turns), so the mixture turns sooner.
/// Jump decision "posterior" (soft mixture on): a jump is declared, at the most probable t_j, once the
/// mixture's hypotheses "a jump at t_j" that have jump_min_samples measurements after t_j hold more than
/// jump_posterior of its posterior mass, instead of when the test statistic passes jump_threshold; the
/// prior odds then count, and jump_threshold is not used.
/// Waypoint region (region_size > 0; constant-speed legs): the legs join waypoints drawn uniformly in a
/// known box B (area A) — a target confined to a known workspace, e.g. [T]'s projection screen. From a
/// corner c, the next waypoint w is uniform in B, so in polar coordinates about c its density is r / A
/// for r < R(θ), R(θ) the distance from c to B's boundary along u(θ). Hence:
///  - a new leg's direction has the prior p(θ) = R(θ)² / (2A) (more room, more likely; ∫ p dθ = 1),
///    multiplied with the learnt-turn prior when both are on (then normalised on a grid);
///  - the soft mixture's prior odds of "the turn was at t_j" against "no turn yet" come from where the
///    target is along its leg: with s the distance travelled from the leg's start c along u and R = R(θ_u),
///    P(turn in (s_{j−1}, s_j]) : P(no turn by s_n) = (s_j² − s_{j−1}²) : (R² − s_n²),
///    instead of jump_rate × (t_j − t_{j−1}) : 1. A leg cannot leave B, so the odds of a turn grow without
///    bound as the target nears the boundary, and are small just after a corner.
///  The model says the target never leaves B. Once 5 accepted measurements in a row lie outside B by
///  more than 2 of their standard deviations (on either axis), the region is taken to be wrong and is
///  dropped for good (regionDropped()): the filter goes on as without one (θ uniform, jump_rate odds). A
///  too small or shifted box would otherwise make every step near its edge look like a turn. (The
///  measurements, not the estimate: a turn at the edge is detected late, and the estimate overshoots.)
/// Noise-scaled corner settings (jump_min_samples and/or jump_corner_sigma "auto", nullopt): with
/// σ = √(tr R / 2) the measurement noise (its latest R, per-axis RMS), Δt the median of the last 16
/// measurement intervals, ŝ the learnt speed (before the first leg has ended: |v̂| of the state once
/// it exceeds its own std; until then jump_min_samples is kAutoJumpSamplesMax) and ρ = σ / (ŝ Δt),
/// the noise in units of the target's step between measurements,
///   jump_min_samples = clamp(round(kAutoJumpSamplesScale ρ^(2/3)), 2, kAutoJumpSamplesMax),
///   jump_corner_sigma = kAutoCornerSigmaPerNoise σ.
/// Why ρ^(2/3): n measurements after a turn that changes the velocity by Δv (∝ ŝ at constant speed)
/// depart from straight on by Δv Δt k, k = 1..n, a log-likelihood ratio of about Δv² Δt² n³ / (3 σ²);
/// the same evidence for every setting needs n ∝ ρ^(2/3). The two factors are the values tuned for [T]'s
/// random path at 10 % noise (ρ = 5.9: 8 and 0.01 m), checked by grid search at 5-20 % noise, at
/// 0.3 m/s and at 60 fps: "auto" is within 1.5 % of the best fixed pair of each setting, where the
/// 10 %-tuned pair loses up to 12 % (docs/results.md, pan-tilt round 11).
/// Waypoint particles (model waypoint_particles; needs the region): instead of a Kalman filter, the
/// waypoint particle filter (waypoint_particle_filter.h), the posterior of the random path's own
/// generator (waypoints uniform in the region, one speed). state() and estimate() are its posterior
/// moments of (p, v) at the last measurement, at() its moments run ahead; its outlier term replaces
/// the gate (every measurement is accepted; NIS against the predicted moments), and a reset() draws
/// a fresh cloud from the next stream. The Kalman keys (q, jumps, legs, turns) are not used. It is
/// the Bayes reference of the replays put in the loop, for targets whose generator is known.
class PlanarTargetFilter {
public:
  explicit PlanarTargetFilter(const TargetFilterConfig& config = {});

  struct Update {
    bool accepted = false;
    bool reinitialized = false;
    bool jump = false;  ///< a velocity jump was detected and the recent measurements processed again
    double nis = 0.0;
  };
  bool initialized() const { return initialized_; }
  void reset(core::Timestamp t, const Eigen::Vector2d& z, const Eigen::Matrix2d& R);
  /// Predicts to t (>= the state's time) and fuses z (gated). Initialises on the first call.
  Update update(core::Timestamp t, const Eigen::Vector2d& z, const Eigen::Matrix2d& R);

  struct Kinematics {
    Eigen::Vector2d p = Eigen::Vector2d::Zero(), v = Eigen::Vector2d::Zero(), a = Eigen::Vector2d::Zero();
    Eigen::Matrix2d P_pos = Eigen::Matrix2d::Zero();
  };
  /// The state extrapolated to t (no change to the filter); t may be before the state's time
  /// only by rounding (it is then evaluated at the state's time). With an active waypoint region, an
  /// extrapolation that would leave the box stops on its boundary with v = a = 0 (the model's target
  /// never leaves it; it turns there, direction unknown): what coasting through an occlusion follows.
  Kinematics at(core::Timestamp t) const;
  const estimation::StateEstimate& state() const { return state_; }
  /// The output estimate at the last measurement: the soft jump mixture when it applies, else state().
  const estimation::StateEstimate& estimate() const { return output_ ? *output_ : state_; }
  const TargetFilterConfig& config() const { return config_; }
  int stateDim() const;
  /// IMM mode probabilities (cv, ct, maneuver); empty for the other models.
  Eigen::VectorXd modeProbabilities() const;
  /// Velocity jumps detected since construction.
  std::size_t jumps() const { return jumps_; }
  /// Starts a constant-speed leg at t_c (>= the last measurement time) from the estimate there: a
  /// jump known from outside (e.g. the corner times of a known path, for a bound). Needs constant_speed
  /// and a known speed.
  void startLeg(core::Timestamp t_c);
  /// Sets ŝ and its variance (instead of learning them from the legs).
  void setSpeed(double speed, double variance);
  /// The corner settings in force now: the configured values, or the "auto" ones (see the class comment).
  int minSamples() const;
  double cornerSigma() const;
  /// The learnt speed ŝ (m/s) and its variance; 0 / infinity before the first segment has ended.
  double speedEstimate() const { return speed_info_ > 0.0 ? speed_sum_ / speed_info_ : 0.0; }
  double speedVariance() const { return speed_info_ > 0.0 ? 1.0 / speed_info_ : 1e300; }
  /// The configured waypoint region was dropped because the estimate left it (see the class comment).
  bool regionDropped() const { return region_dropped_; }
  /// The turn angles (rad, in [−π, π], oldest first) learnt at the last corners (turn_prior_weight > 0).
  const std::vector<double>& learntTurns() const { return turns_; }

private:
  struct Snapshot {
    core::Timestamp t = 0.0;
    Eigen::Vector2d z = Eigen::Vector2d::Zero();
    Eigen::Matrix2d R = Eigen::Matrix2d::Identity();
    estimation::StateEstimate state;       ///< x(t|t) after this measurement
    std::optional<estimation::Imm> imm;
  };
  Update step(core::Timestamp t, const Eigen::Vector2d& z, const Eigen::Matrix2d& R);
  Snapshot snapshot(core::Timestamp t, const Eigen::Vector2d& z, const Eigen::Matrix2d& R) const;
  Eigen::Vector2d extrapolatePosition(const Eigen::VectorXd& x, double tau) const;
  bool detectJump();
  void applyJump(int j);  ///< restart from history_[j] with the motion prior re-opened, re-process the rest
  void softMixture(std::vector<std::pair<double, int>>& log_odds);
  struct Leg;
  /// The constant-speed leg from the corner (t_c, c ~ N(c, P_c)); from_direction: the direction (rad) of
  /// the leg that ended there, centre of the learnt turn prior (NaN: θ uniform).
  Leg makeLeg(core::Timestamp t_c, const Eigen::Vector2d& c, const Eigen::Matrix2d& P_c, double from_direction) const;
  static double direction(const estimation::StateEstimate& s);  ///< atan2 of the velocity (NaN if ~0)
  void learnTurn(double direction);  ///< a leg of this direction ended at a detected jump
  std::vector<double> turns_;        ///< the last learnt turn angles (rad, in (−π, π])
  double last_direction_ = std::numeric_limits<double>::quiet_NaN();  ///< of the leg before the current one
  estimation::StateEstimate reopened(const Snapshot& sj) const;  ///< x(j|j) with the motion prior re-opened
  estimation::StateEstimate alternative(int j) const;            ///< the state now after a jump at history_[j]
  int refineCornerTime(int j) const;  ///< the constant-speed leg's most likely start near history_[j]
  bool legEvidenceMixture() const;    ///< the soft mixture's Bayes factors from constant-speed legs
  double legBayesFactor(int j) const; ///< log BF of a leg from history_[j] against straight on
  /// Distance from c (clamped into the region) to the region's boundary along u(θ) (region set).
  double regionReach(const Eigen::Vector2d& c, double theta) const;
  /// log prior odds of a turn at each soft-mixture candidate j (index into history_) against none,
  /// from the waypoint region; empty if it does not apply (no region, or the leg's direction unknown).
  std::vector<double> regionJumpOdds() const;
  bool regionActive() const { return config_.hasRegion() && !region_dropped_; }
  void checkRegion(const Eigen::Vector2d& z, const Eigen::Matrix2d& R);  ///< drops the region (see the class comment)
  bool region_dropped_ = false;
  int region_outside_run_ = 0;
  std::shared_ptr<const Leg> leg_;  ///< the current constant-speed leg (immutable: copies share it until it changes)
  std::optional<estimation::StateEstimate> output_;  ///< the soft mixture, when it differs from state_
  void learnSpeed(std::size_t end);  ///< s_k of the segment history_[0..end]
  void noteMeasurement(core::Timestamp t, const Eigen::Matrix2d& R);  ///< for the "auto" corner settings
  Eigen::Matrix2d last_R_ = Eigen::Matrix2d::Zero();
  double noiseSigma() const;  ///< √(tr R / 2) of the latest measurement: the per-axis RMS noise (m)
  core::Timestamp last_t_ = std::numeric_limits<double>::quiet_NaN();
  std::vector<double> intervals_;  ///< the last 16 measurement intervals (s)
  double speed_sum_ = 0.0, speed_info_ = 0.0;  ///< Σ s_k / var s_k, Σ 1 / var s_k
  std::vector<Snapshot> history_;  ///< accepted measurements of the last jump_window s (since the last jump)
  std::size_t jumps_ = 0;
  bool usesImm() const { return config_.model == TargetModel::CoordinatedTurn || config_.model == TargetModel::Imm; }
  TargetFilterConfig config_;
  std::optional<estimation::Imm> imm_;
  std::optional<WaypointParticleFilter> particles_;  ///< model waypoint_particles
  std::uint64_t particle_resets_ = 0;
  void setParticleState();  ///< state_ from the particles' moments at their time
  estimation::ContinuousLinearModel model_;
  estimation::StateEstimate state_;
  bool initialized_ = false;
  int rejected_in_a_row_ = 0;
  double gate_ = 0.0;
};

// ---------------------------------------------------------------------------------------------
// Controllers (one interface for the scenario loop).

/// What the camera saw in one image, time-stamped with the capture time.
struct TargetObservation {
  core::Timestamp stamp = 0.0;
  bool detected = false;
  Eigen::Vector2d feature = Eigen::Vector2d::Zero();    ///< normalised (x, y) in the capture camera
  Eigen::Vector2d plane = Eigen::Vector2d::Zero();      ///< measured position on the target plane (m)
  Eigen::Matrix2d plane_cov = Eigen::Matrix2d::Identity();  ///< its covariance (m²)
};

struct ControlInput {
  core::Timestamp t = 0.0;              ///< issue time of the command
  robots::JointState joints;            ///< measured joint state at t
  std::vector<robots::IssuedCommand> recent;  ///< commands issued in the last latency + period
  double period = 1.0 / 30.0;           ///< s until the next command (the hold time)
};

enum class TrackingMode { Tracking, Coasting, Searching, Idle };
const char* toString(TrackingMode mode);

struct ControlOutput {
  Eigen::Vector2d qdot = Eigen::Vector2d::Zero();            ///< the command (limited)
  Eigen::Vector2d qdot_unlimited = Eigen::Vector2d::Zero();  ///< before the limiter
  TrackingMode mode = TrackingMode::Idle;
  bool has_prediction = false;
  Eigen::Vector2d predicted_feature = Eigen::Vector2d::Zero();  ///< ŝ at the effect time (normalised)
  Eigen::Vector2d predicted_plane = Eigen::Vector2d::Zero();    ///< P̂ on the plane at the effect time
};

struct LimitConfig {
  double margin = 0.0087;   ///< rad kept from the joint limits (0.5°)
};

class PanTiltController {
public:
  virtual ~PanTiltController() = default;
  virtual std::string name() const = 0;
  virtual void observe(const TargetObservation& observation) = 0;
  virtual ControlOutput command(const ControlInput& input) = 0;
};

/// Law (1) on the raw measured feature; zero velocity when the target is not detected.
class BaselinePanTiltController : public PanTiltController {
public:
  /// `kinematics`: the unit's model as the controller knows it (camera mount from the hand-eye
  /// calibration; vpPtu46's nominal mount by default).
  BaselinePanTiltController(const PointServoConfig& servo, const robots::PanTiltLimits& limits, double latency,
                            const LimitConfig& limit_config = {},
                            const robots::PanTiltKinematics& kinematics = robots::PanTiltKinematics());
  std::string name() const override { return "visp_baseline"; }
  void observe(const TargetObservation& observation) override { last_ = observation; }
  ControlOutput command(const ControlInput& input) override;

private:
  robots::PanTiltKinematics kinematics_;
  VispPointServo servo_;
  robots::PanTiltLimits limits_;
  double latency_;
  LimitConfig limit_config_;
  TargetObservation last_;
};

struct PredictiveConfig {
  PointServoConfig servo;
  TargetFilterConfig filter;
  double gain = 0.0;              ///< λ (1/s) of law (2); 0: servo.gain (the baseline's)
  double lead = 0.0;              ///< s predicted beyond the command latency (e.g. half a period)
  bool feed_forward = true;       ///< the −J⁺ ṡ_T term of (2)
  double coast_time = 1.5;        ///< s of following the prediction without measurements
  double search_speed = 0.6;      ///< rad/s along the search spiral
  double search_growth = 0.12;    ///< rad of radius per turn
  double search_radius = 0.8;     ///< rad, largest spiral radius (then it restarts)
  double search_gain = 4.0;       ///< 1/s, pull towards the spiral point
  LimitConfig limits;
  void validate() const;
};

/// Law (2): prediction, feed-forward, latency compensation, search and reacquisition.
class PredictivePanTiltController : public PanTiltController {
public:
  /// f_M_plane: pose of the target plane (x, y in the plane) in the unit's base frame;
  /// `kinematics`: the unit's model as the controller knows it (see BaselinePanTiltController).
  PredictivePanTiltController(const PredictiveConfig& config, const robots::PanTiltLimits& limits, double latency,
                              const Eigen::Isometry3d& f_M_plane,
                              const robots::PanTiltKinematics& kinematics = robots::PanTiltKinematics());
  std::string name() const override { return "predictive"; }
  void observe(const TargetObservation& observation) override;
  ControlOutput command(const ControlInput& input) override;

  const PlanarTargetFilter& filter() const { return filter_; }
  /// The filter's x(k|k) position after the last fused measurement (valid when lastUpdate().accepted).
  const Eigen::Vector2d& filteredPlane() const { return filtered_; }
  const PlanarTargetFilter::Update& lastUpdate() const { return last_update_; }
  std::size_t reacquisitions() const { return reacquisitions_; }

private:
  PredictiveConfig config_;
  robots::PanTiltKinematics kinematics_;
  VispPointServo servo_;
  robots::PanTiltLimits limits_;
  double latency_;
  Eigen::Isometry3d f_M_plane_;
  PlanarTargetFilter filter_;
  Eigen::Vector2d filtered_ = Eigen::Vector2d::Zero();
  PlanarTargetFilter::Update last_update_;
  core::Timestamp last_accepted_ = -1e300;
  bool searching_ = false;
  core::Timestamp search_start_ = 0.0;
  Eigen::Vector2d search_center_ = Eigen::Vector2d::Zero();
  std::size_t reacquisitions_ = 0;
};

}  // namespace viewline::control
