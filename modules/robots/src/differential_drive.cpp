#include "viewline/robots/differential_drive.h"

#include <algorithm>
#include <cmath>

#include "viewline/core/checks.h"
#include "viewline/core/error.h"

namespace viewline::robots {

BasePose integrateUnicycle(const BasePose& p, double v, double omega, double dt) {
  BasePose n = p;
  if (std::abs(omega * dt) < 1e-9) {
    const double phi = p.theta + 0.5 * omega * dt;
    n.x += v * dt * std::cos(phi);
    n.y += v * dt * std::sin(phi);
  } else {
    n.x += v / omega * (std::sin(p.theta + omega * dt) - std::sin(p.theta));
    n.y += v / omega * (std::cos(p.theta) - std::cos(p.theta + omega * dt));
  }
  n.theta = std::remainder(p.theta + omega * dt, 2.0 * M_PI);
  return n;
}

void DifferentialDriveParams::validate() const {
  core::requirePositive(track, "DifferentialDriveParams.track");
  core::requirePositive(max_speed, "DifferentialDriveParams.max_speed");
  core::requirePositive(max_turn_rate, "DifferentialDriveParams.max_turn_rate");
  core::requirePositive(wheel_speed_max, "DifferentialDriveParams.wheel_speed_max");
  if (wheel_speed_max < max_speed) {
    throw core::InvalidInput("DifferentialDriveParams.wheel_speed_max: expected >= max_speed");
  }
  core::requirePositive(motor_time_constant, "DifferentialDriveParams.motor_time_constant");
  core::requirePositive(control_period, "DifferentialDriveParams.control_period");
  if (substeps < 1) throw core::InvalidInput("DifferentialDriveParams.substeps: expected >= 1");
  for (const auto& [value, name] : {std::pair{kp, "kp"}, std::pair{ki, "ki"}, std::pair{kd, "kd"},
                                    std::pair{encoder_noise, "encoder_noise"}, std::pair{command_timeout, "command_timeout"}}) {
    core::requireFinite(value, std::string("DifferentialDriveParams.") + name);
    if (value < 0.0) throw core::InvalidInput(std::string("DifferentialDriveParams.") + name + ": expected >= 0");
  }
}

DifferentialDrive::DifferentialDrive(const DifferentialDriveParams& params, const BasePose& start)
    : params_(params), pose_(start) {
  params_.validate();
  core::requireFinite(start.x, "DifferentialDrive: start.x");
  core::requireFinite(start.y, "DifferentialDrive: start.y");
  core::requireFinite(start.theta, "DifferentialDrive: start.theta");
}

void DifferentialDrive::setCommand(double v, double omega) {
  core::requireFinite(v, "DifferentialDrive::setCommand: v");
  core::requireFinite(omega, "DifferentialDrive::setCommand: omega");
  omega = std::clamp(omega, -params_.max_turn_rate, params_.max_turn_rate);
  const double half = 0.5 * params_.track;
  // Turning has priority: the largest |ω| the wheels allow, then what is left for v.
  omega = std::clamp(omega, -params_.wheel_speed_max / half, params_.wheel_speed_max / half);
  const double v_room = std::max(0.0, params_.wheel_speed_max - std::abs(omega) * half);
  v = std::clamp(v, -std::min(params_.max_speed, v_room), std::min(params_.max_speed, v_room));
  ref_ = Eigen::Vector2d(v - omega * half, v + omega * half);
  last_command_t_ = t_;
}

void DifferentialDrive::step(core::Rng& rng) {
  const double dt = params_.control_period;
  if (watchdogStopped()) ref_.setZero();  // no command for command_timeout: brake to rest
  Eigen::Vector2d u;
  for (int i = 0; i < 2; ++i) {
    const double meas = wheel_[i] + (params_.encoder_noise > 0.0 ? core::gaussian(rng, params_.encoder_noise) : 0.0);
    const double e = ref_[i] - meas;
    const double de = (e - last_error_[i]) / dt;
    last_error_[i] = e;
    const double raw = ref_[i] + params_.kp * e + params_.ki * (integral_[i] + e * dt) + params_.kd * de;
    u[i] = std::clamp(raw, -params_.wheel_speed_max, params_.wheel_speed_max);
    if (raw == u[i]) integral_[i] += e * dt;  // conditional integration (anti-windup)
  }
  // Motors (exact first-order response) and pose (exact arcs on sub-steps).
  const double h = dt / params_.substeps;
  const double a = std::exp(-h / params_.motor_time_constant);
  for (int s = 0; s < params_.substeps; ++s) {
    const Eigen::Vector2d w0 = wheel_;
    wheel_ = u + (wheel_ - u) * a;
    const Eigen::Vector2d wm = 0.5 * (w0 + wheel_);
    pose_ = integrateUnicycle(pose_, 0.5 * (wm.x() + wm.y()), (wm.y() - wm.x()) / params_.track, h);
  }
  t_ += dt;
}

double JointRateLimiter::step(double current, double target, double rate_max, double dt) {
  const double d = std::clamp(target - current, -rate_max * dt, rate_max * dt);
  return current + d;
}

}  // namespace viewline::robots
