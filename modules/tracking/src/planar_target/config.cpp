// The planar target filter's settings: names of the models and the checks of the keys, once, at load.
#include "viewline/tracking/planar_target/config.h"

#include <cmath>

#include "viewline/core/checks.h"
#include "viewline/core/error.h"

namespace viewline::tracking {

TargetModel targetModelFromString(const std::string& name) {
  if (name == "constant_velocity" || name == "cv") return TargetModel::ConstantVelocity;
  if (name == "constant_acceleration" || name == "ca") return TargetModel::ConstantAcceleration;
  if (name == "singer") return TargetModel::Singer;
  if (name == "coordinated_turn" || name == "ct") return TargetModel::CoordinatedTurn;
  if (name == "imm") return TargetModel::Imm;
  if (name == "waypoint_particles") return TargetModel::WaypointParticles;
  if (name == "mixture") return TargetModel::Mixture;
  throw core::InvalidInput("target model: expected constant_velocity (cv), constant_acceleration (ca), singer, "
                           "coordinated_turn (ct), imm, waypoint_particles or mixture, got '" + name + "'");
}

const char* toString(TargetModel model) {
  switch (model) {
    case TargetModel::ConstantVelocity: return "constant_velocity";
    case TargetModel::ConstantAcceleration: return "constant_acceleration";
    case TargetModel::Singer: return "singer";
    case TargetModel::CoordinatedTurn: return "coordinated_turn";
    case TargetModel::Imm: return "imm";
    case TargetModel::WaypointParticles: return "waypoint_particles";
    case TargetModel::Mixture: return "mixture";
  }
  return "?";
}

void TargetFilterConfig::validate() const {
  if (!(q >= 0.0) || !std::isfinite(q)) throw core::InvalidInput("filter.q must be >= 0");
  core::requirePositive(singer_tau, "filter.singer_tau");
  if (!(singer_sigma >= 0.0)) throw core::InvalidInput("filter.singer_sigma must be >= 0");
  core::requirePositive(init_velocity_sigma, "filter.init_velocity_sigma");
  core::requirePositive(init_acceleration_sigma, "filter.init_acceleration_sigma");
  if (!(gate_probability > 0.0 && gate_probability < 1.0)) throw core::InvalidInput("filter.gate_probability must be in (0, 1)");
  if (reinit_after < 1) throw core::InvalidInput("filter.reinit_after must be >= 1");
  core::requirePositive(init_omega_sigma, "filter.init_omega_sigma");
  if (!(ct_q_accel >= 0.0) || !std::isfinite(ct_q_accel)) throw core::InvalidInput("filter.ct_q_accel must be >= 0");
  if (!(ct_q_omega >= 0.0) || !std::isfinite(ct_q_omega)) throw core::InvalidInput("filter.ct_q_omega must be >= 0");
  if (!(maneuver_q >= 0.0) || !std::isfinite(maneuver_q)) throw core::InvalidInput("filter.maneuver_q must be >= 0");
  for (int i = 0; i < 3; ++i) core::requirePositive(imm_sojourn(i), "filter.imm_sojourn");
  if (!(mixture_switch_rate >= 0.0) || !std::isfinite(mixture_switch_rate))
    throw core::InvalidInput("filter.mixture_switch_rate must be >= 0");
  if (!(jump_window >= 0.0) || !std::isfinite(jump_window)) throw core::InvalidInput("filter.jump_window must be >= 0");
  core::requirePositive(jump_threshold, "filter.jump_threshold");
  if (jump_min_samples && *jump_min_samples < 2)
    throw core::InvalidInput("filter.jump_min_samples must be >= 2 (or auto)");
  if (!(constant_speed_sigma >= 0.0) || !std::isfinite(constant_speed_sigma))
    throw core::InvalidInput("filter.constant_speed_sigma must be >= 0");
  if (!(jump_rate >= 0.0) || !std::isfinite(jump_rate)) throw core::InvalidInput("filter.jump_rate must be >= 0");
  core::requirePositive(jump_prior_sigma, "filter.jump_prior_sigma");
  if (jump_corner_sigma && (!(*jump_corner_sigma >= 0.0) || !std::isfinite(*jump_corner_sigma)))
    throw core::InvalidInput("filter.jump_corner_sigma must be >= 0 (or auto)");
  if (!(turn_prior_weight >= 0.0 && turn_prior_weight < 1.0))
    throw core::InvalidInput("filter.turn_prior_weight must be in [0, 1) (1 would forbid any new turn angle)");
  if (!(turn_prior_sigma_deg > 0.0 && turn_prior_sigma_deg <= 45.0))
    throw core::InvalidInput("filter.turn_prior_sigma_deg must be in (0, 45]");
  if (jump_evidence != "kink" && jump_evidence != "legs")
    throw core::InvalidInput("filter.jump_evidence must be kink or legs, not '" + jump_evidence + "'");
  if (!region_center.allFinite() || !region_size.allFinite() || region_size.minCoeff() < 0.0)
    throw core::InvalidInput("filter.region: center and size must be finite, size >= 0");
  if ((region_size.x() > 0.0) != (region_size.y() > 0.0))
    throw core::InvalidInput("filter.region.size: both width and height > 0 (or both 0: no region)");
  if (model == TargetModel::WaypointParticles) {  // the Kalman keys are not used: their interplay is not checked
    if (!hasRegion())
      throw core::InvalidInput("filter.model waypoint_particles needs filter.region (the box the waypoints are drawn in)");
    if (particles < 100) throw core::InvalidInput("filter.particles must be >= 100");
    if (!(particle_speed.x() > 0.0 && particle_speed.y() >= particle_speed.x() && std::isfinite(particle_speed.y())))
      throw core::InvalidInput("filter.particle_speed: [min, max] with 0 < min <= max (m/s)");
    if (!(particle_min_leg >= 0.0 && particle_min_leg < 0.5 * region_size.minCoeff()))
      throw core::InvalidInput("filter.particle_min_leg must be in [0, half the region's smaller side)");
    return;
  }
  const bool cv = model == TargetModel::ConstantVelocity || model == TargetModel::Mixture;  // mixture: its cv part
  if (constant_speed && (!cv || !(jump_window > 0.0)))
    throw core::InvalidInput("filter.constant_speed needs model constant_velocity (or mixture) and jump detection "
                             "(filter.jump_window > 0): the speed is learnt from the legs between detected jumps");
  if (hasRegion() && !constant_speed)
    throw core::InvalidInput("filter.region needs filter.constant_speed (the region is where the legs' waypoints lie)");
  if (jump_decision != "test" && jump_decision != "posterior")
    throw core::InvalidInput("filter.jump_decision must be test or posterior, not '" + jump_decision + "'");
  if (jump_decision == "posterior" && !(jump_rate > 0.0))
    throw core::InvalidInput("filter.jump_decision: posterior needs the soft jump mixture (filter.jump_rate > 0)");
  if (!(jump_posterior > 0.0 && jump_posterior < 1.0))
    throw core::InvalidInput("filter.jump_posterior must be in (0, 1)");
  if (jump_evidence == "legs" && !constant_speed)
    throw core::InvalidInput("filter.jump_evidence: legs needs filter.constant_speed");
  if (turn_prior_weight > 0.0 && !constant_speed)
    throw core::InvalidInput("filter.turn_prior_weight needs filter.constant_speed (the prior is on a leg's direction)");
  if (jump_rate > 0.0 && !(jump_window > 0.0))
    throw core::InvalidInput("filter.jump_rate needs jump detection (filter.jump_window > 0)");
  if (jump_rate > 0.0 && (model == TargetModel::CoordinatedTurn || model == TargetModel::Imm))
    throw core::InvalidInput("filter.jump_rate (the soft jump mixture) is for the linear models cv, ca and singer");
}

}  // namespace viewline::tracking
