#pragma once
// The filter settings the gate-decision test runs: every model and part of the planar target filter.
#include <Eigen/Core>
#include <optional>
#include <string>

namespace viewline::tracking::planar_test {

inline constexpr int kGateConfigs = 9;

template <class Config, class Model>
Config gateConfig(int which) {
  Config c;
  c.gate_probability = 0.99;  // a tight gate: rejections and restarts happen
  switch (which) {
    case 0:  // plain CV
      c.model = Model::ConstantVelocity;
      c.q = 1e-3;
      break;
    case 1:  // CA, hard jump test
      c.model = Model::ConstantAcceleration;
      c.q = 1e-3;
      c.jump_window = 2.0;
      c.jump_threshold = 15.0;
      c.jump_min_samples = 6;
      break;
    case 2:  // Singer, soft mixture from kinks
      c.model = Model::Singer;
      c.jump_window = 2.0;
      c.jump_threshold = 15.0;
      c.jump_min_samples = 6;
      c.jump_rate = 0.5;
      break;
    case 3:  // CT
      c.model = Model::CoordinatedTurn;
      c.jump_window = 2.0;
      c.jump_min_samples = 6;
      break;
    case 4:  // IMM
      c.model = Model::Imm;
      c.q = 1e-3;
      break;
    case 5:  // constant-speed legs, learnt turns, leg evidence
      c.model = Model::ConstantVelocity;
      c.q = 1e-5;
      c.init_velocity_sigma = 0.3;
      c.jump_window = 3.0;
      c.jump_threshold = 20.0;
      c.jump_min_samples = 8;
      c.jump_rate = 1.0;
      c.constant_speed = true;
      c.jump_corner_sigma = 0.01;
      c.jump_evidence = "legs";
      c.turn_prior_weight = 0.5;
      break;
    case 6:  // config/pan_tilt_random.yaml-like: legs, waypoint region, posterior decisions, "auto" corners
      c.model = Model::ConstantVelocity;
      c.q = 1e-5;
      c.init_velocity_sigma = 0.3;
      c.jump_window = 3.0;
      c.jump_threshold = 15.0;
      c.jump_min_samples = std::nullopt;
      c.jump_corner_sigma = std::nullopt;
      c.jump_rate = 1.0;
      c.jump_prior_sigma = 0.2;
      c.constant_speed = true;
      c.constant_speed_sigma = 0.005;
      c.jump_evidence = "legs";
      c.region_size = Eigen::Vector2d(0.80, 0.43);
      c.jump_decision = "posterior";
      break;
    case 7:  // a region too small: it is dropped
      c = gateConfig<Config, Model>(6);
      c.region_size = Eigen::Vector2d(0.40, 0.20);
      break;
    default:  // waypoint particles
      c.model = Model::WaypointParticles;
      c.region_size = Eigen::Vector2d(0.80, 0.43);
      c.particles = 500;
      c.particle_speed = Eigen::Vector2d(0.15, 0.15);
      c.particle_min_leg = 0.1;
      c.reinit_after = 2;
      break;
  }
  return c;
}

}  // namespace viewline::tracking::planar_test
