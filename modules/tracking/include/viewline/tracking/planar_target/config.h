#pragma once
// The planar target filter's settings: the motion model and the keys of its parts (jump detection,
// constant-speed legs, learnt turns, soft jump mixture, waypoint region, waypoint particles, gate).
// What each key does is described where it is used: filter.h (models, gate), corner_detector.h (jumps,
// "auto" corner settings), speed_legs.h (legs, turns), waypoint_region.h, waypoint_particles.h.

#include <Eigen/Core>
#include <cstddef>
#include <cstdint>
#include <optional>
#include <string>

namespace viewline::tracking {

/// Motion model of the planar target filter (plane coordinates).
enum class TargetModel { ConstantVelocity, ConstantAcceleration, Singer, CoordinatedTurn, Imm, WaypointParticles, Mixture };
/// "constant_velocity" | "cv", "constant_acceleration" | "ca", "singer", "coordinated_turn" | "ct", "imm",
/// "waypoint_particles", "mixture" (legs_or_turn: the cv filter with its corner keys beside the ct filter)
TargetModel targetModelFromString(const std::string& name);
/// The config spelling of a model ("constant_velocity", "constant_acceleration", "singer", ...).
const char* toString(TargetModel model);

/// Configuration of the planar target filter: model, noise densities, jump detection, constant-speed legs,
/// region, particles and gate.
struct TargetFilterConfig {
  TargetModel model = TargetModel::ConstantVelocity;  ///< motion model
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
  /// mixture: rate (1/s) at which the target may switch between the cv-legs and the ct motion (Markov chain
  /// of the two models' probabilities; > 0 keeps either model recoverable)
  double mixture_switch_rate = 0.05;
  double jump_window = 0.0;              ///< s searched back for a velocity jump (GLR; 0: no jump detection)
  double jump_threshold = 20.0;          ///< GLR statistic (χ², 2 dof) that declares a jump
  /// Measurements after a candidate jump time before it is tested; nullopt: "auto", scaled to the
  /// noise and the target's step per measurement (corner_detector.h, "Noise-scaled corner settings").
  std::optional<int> jump_min_samples = 4;
  bool constant_speed = false;           ///< constant-speed legs after each jump (cv; speed_legs.h)
  double constant_speed_sigma = 0.002;   ///< m/s, std of a leg's speed about the learnt ŝ (beside var ŝ)
  /// m, added to the corner's position std when a leg starts; nullopt: "auto" (noise-scaled, corner_detector.h).
  std::optional<double> jump_corner_sigma = 0.0;
  double turn_prior_weight = 0.0;        ///< constant-speed legs: prior mass on the learnt turn angles (0: θ uniform)
  double turn_prior_sigma_deg = 10.0;    ///< std (deg) of each learnt turn angle in that prior
  double jump_rate = 0.0;                ///< 1/s, prior rate of jumps; > 0: soft jump mixture (corner_detector.h)
  double jump_prior_sigma = 0.15;        ///< m/s, prior std of a velocity jump per axis (soft mixture)
  std::string jump_evidence = "kink";    ///< soft mixture's Bayes factors: "kink" (free Δv) or "legs" (corner_detector.h)
  std::string jump_decision = "test";    ///< what declares a jump: "test" (jump_threshold) or "posterior" (corner_detector.h)
  double jump_posterior = 0.99;          ///< "posterior": the soft mixture's jump mass that declares a jump
  /// Waypoint region (constant-speed legs; size 0: none): the target turns at points spread uniformly over
  /// this box (plane coordinates, m) and never leaves it. See waypoint_region.h.
  Eigen::Vector2d region_center = Eigen::Vector2d::Zero();
  Eigen::Vector2d region_size = Eigen::Vector2d::Zero();  ///< (width, height), m
  /// True when a waypoint region is set (both sizes > 0).
  bool hasRegion() const { return region_size.x() > 0.0 && region_size.y() > 0.0; }
  /// waypoint_particles (not a Kalman filter; see waypoint_particles.h): particle count, the uniform
  /// prior of the target's one speed (m/s; equal ends: the speed is known), the generator's shortest leg
  /// (m) and the particles' random stream.
  std::size_t particles = 20000;
  /// Waypoint_particles: uniform prior range (min, max) of the target's speed, m/s
  Eigen::Vector2d particle_speed{0.02, 0.5};
  double particle_min_leg = 0.0;  ///< waypoint_particles: shortest leg of the waypoint generator, m
  std::uint64_t particle_seed = 1;  ///< waypoint_particles: seed of the particles' random stream
  double gate_probability = 0.9999;      ///< chi-square (2 dof) gate on the NIS (TrackGate probability)
  int reinit_after = 3;                  ///< consecutive gated-out measurements that re-initialise (restart_after)
  void validate() const;  ///< throws core::InvalidInput naming the key
};

/// "auto" corner settings (TargetFilterConfig::jump_min_samples / jump_corner_sigma unset; see
/// corner_detector.h, "Noise-scaled corner settings").
inline constexpr double kAutoJumpSamplesScale = 2.44;
/// Largest "auto" jump_min_samples (also used when speed, cadence or noise is unknown).
inline constexpr int kAutoJumpSamplesMax = 30;
/// "auto" jump_corner_sigma per unit of measurement noise std (σ_c = this × noise σ).
inline constexpr double kAutoCornerSigmaPerNoise = 0.34;

}  // namespace viewline::tracking
