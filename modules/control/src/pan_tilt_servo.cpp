#include "viewline/control/pan_tilt_servo.h"

#include <algorithm>
#include <cmath>
#include <visp3/core/vpColVector.h>
#include <visp3/visual_features/vpFeaturePoint.h>
#include <visp3/vs/vpServo.h>

#include "viewline/core/checks.h"
#include "viewline/core/error.h"
#include "viewline/core/frames.h"

namespace viewline::control {

// ---------------------------------------------------------------------------------------------

void PointServoConfig::validate() const {
  core::requirePositive(gain, "servo.gain");
  if (interaction != "desired" && interaction != "current" && interaction != "mean") {
    throw core::InvalidInput("servo.interaction: expected desired, current or mean, got '" + interaction + "'");
  }
}

struct VispPointServo::Impl {
  vpServo task;
  vpFeaturePoint s, sd;
};

VispPointServo::VispPointServo(const PointServoConfig& config) : config_(config), impl_(std::make_unique<Impl>()) {
  config_.validate();
  auto& task = impl_->task;
  task.setServo(vpServo::EYEINHAND_L_cVe_eJe);
  const vpServo::vpServoIteractionMatrixType type =
      config_.interaction == "desired" ? vpServo::DESIRED
                                       : (config_.interaction == "current" ? vpServo::CURRENT : vpServo::MEAN);
  task.setInteractionMatrixType(type, vpServo::PSEUDO_INVERSE);
  impl_->sd.buildFrom(0.0, 0.0, 1.0);
  impl_->s.buildFrom(0.0, 0.0, 1.0);
  task.addFeature(impl_->s, impl_->sd);
  task.setLambda(config_.gain);
}

VispPointServo::~VispPointServo() = default;

Eigen::Vector2d VispPointServo::command(const Eigen::Vector2d& s, const vpVelocityTwistMatrix& cVe, const vpMatrix& eJe) {
  core::requireFinite(s, "VispPointServo: s");
  impl_->s.buildFrom(s.x(), s.y(), 1.0);  // depth fixed at 1, as in ViSP's pan-tilt examples
  impl_->task.set_cVe(cVe);
  impl_->task.set_eJe(eJe);
  const vpColVector v = impl_->task.computeControlLaw();
  return {v[0], v[1]};
}

Eigen::Matrix2d VispPointServo::jacobianPinv() const {
  const vpMatrix Jp = impl_->task.getTaskJacobianPseudoInverse();
  Eigen::Matrix2d out;
  for (unsigned i = 0; i < 2; ++i)
    for (unsigned j = 0; j < 2; ++j) out(i, j) = Jp[i][j];
  return out;
}

// ---------------------------------------------------------------------------------------------

const char* toString(TrackingMode mode) {
  switch (mode) {
    case TrackingMode::Tracking: return "tracking";
    case TrackingMode::Coasting: return "coasting";
    case TrackingMode::Searching: return "searching";
    case TrackingMode::Idle: return "idle";
  }
  return "?";
}

namespace {
// The predicted state of the joints when a command issued now takes effect.
robots::JointState effectState(const robots::PanTiltLimits& limits, const ControlInput& in, double latency) {
  return robots::predictJointState(limits, in.joints, in.recent, latency, in.t + latency);
}
}  // namespace

BaselinePanTiltController::BaselinePanTiltController(const PointServoConfig& servo, const robots::PanTiltLimits& limits,
                                                     double latency, const LimitConfig& limit_config,
                                                     const robots::PanTiltKinematics& kinematics)
    : kinematics_(kinematics), servo_(servo), limits_(limits), latency_(latency), limit_config_(limit_config) {
  limits_.validate();
}

ControlOutput BaselinePanTiltController::command(const ControlInput& in) {
  ControlOutput out;
  if (last_.detected) {
    out.mode = TrackingMode::Tracking;
    out.qdot_unlimited = servo_.command(last_.feature, kinematics_.cVe(), kinematics_.eJe(in.joints.q));
  } else {
    out.mode = TrackingMode::Idle;
  }
  const robots::JointState e = effectState(limits_, in, latency_);
  out.qdot = robots::limitVelocityCommand(limits_, e.q, e.qdot, out.qdot_unlimited, in.period, limit_config_.margin);
  return out;
}

namespace {
PointServoConfig predictiveServo(const PredictiveConfig& c) {
  PointServoConfig s = c.servo;
  if (c.gain > 0.0) s.gain = c.gain;
  return s;
}
}  // namespace

void PredictiveConfig::validate() const {
  servo.validate();
  if (!(gain >= 0.0) || !std::isfinite(gain)) throw core::InvalidInput("predictive gain must be >= 0");
  filter.validate();
  if (!(lead >= 0.0)) throw core::InvalidInput("lead must be >= 0");
  if (!(coast_time >= 0.0)) throw core::InvalidInput("coast_time must be >= 0");
  core::requirePositive(search_speed, "search.speed");
  core::requirePositive(search_growth, "search.growth");
  core::requirePositive(search_radius, "search.radius");
  core::requirePositive(search_gain, "search.gain");
  if (!(limits.margin >= 0.0)) throw core::InvalidInput("limit margin must be >= 0");
}

PredictivePanTiltController::PredictivePanTiltController(const PredictiveConfig& config,
                                                         const robots::PanTiltLimits& limits, double latency,
                                                         const Eigen::Isometry3d& f_M_plane,
                                                         const robots::PanTiltKinematics& kinematics)
    : config_(config), kinematics_(kinematics), servo_(predictiveServo(config)), limits_(limits), latency_(latency), f_M_plane_(f_M_plane),
      filter_(config.filter) {
  config_.validate();
  limits_.validate();
  core::requireFinite(f_M_plane.matrix(), "PredictivePanTiltController: f_M_plane");
}

void PredictivePanTiltController::observe(const TargetObservation& obs) {
  last_update_ = {};
  if (!obs.detected) return;
  const bool lost = obs.stamp - last_accepted_ > config_.coast_time;
  if (lost || !filter_.initialized()) {
    if (filter_.initialized()) ++reacquisitions_;
    filter_.reset(obs.stamp, obs.plane, obs.plane_cov);
    last_update_.accepted = last_update_.reinitialized = true;
    last_update_.decision = tracking::GateDecision::Start;
  } else {
    last_update_ = filter_.update(obs.stamp, obs.plane, obs.plane_cov);
  }
  if (last_update_.accepted) {
    last_accepted_ = obs.stamp;
    filtered_ = filter_.estimate().x().head<2>();
    searching_ = false;
  }
}

ControlOutput PredictivePanTiltController::command(const ControlInput& in) {
  ControlOutput out;
  const robots::JointState e = effectState(limits_, in, latency_);
  const double t_e = in.t + latency_ + config_.lead;
  if (filter_.initialized() && in.t - last_accepted_ <= config_.coast_time) {
    out.mode = (in.t - last_accepted_ <= 2.5 * in.period) ? TrackingMode::Tracking : TrackingMode::Coasting;
    const tracking::PlanarTargetFilter::Kinematics k = filter_.at(t_e);
    const Eigen::Vector3d P_f = f_M_plane_ * Eigen::Vector3d(k.p.x(), k.p.y(), 0.0);
    const Eigen::Vector3d V_f = f_M_plane_.linear() * Eigen::Vector3d(k.v.x(), k.v.y(), 0.0);
    const Eigen::Isometry3d c_M_f = kinematics_.c_M_f(e.q);
    const Eigen::Vector3d P_c = c_M_f * P_f;
    const Eigen::Vector3d V_c = c_M_f.linear() * V_f;
    out.predicted_plane = k.p;
    if (P_c.z() > 1e-3) {
      const double x = P_c.x() / P_c.z(), y = P_c.y() / P_c.z();
      out.has_prediction = true;
      out.predicted_feature = Eigen::Vector2d(x, y);
      out.qdot_unlimited = servo_.command(out.predicted_feature, kinematics_.cVe(), kinematics_.eJe(e.q));
      if (config_.feed_forward) {
        const Eigen::Vector2d sdot_target((V_c.x() - x * V_c.z()) / P_c.z(), (V_c.y() - y * V_c.z()) / P_c.z());
        out.qdot_unlimited -= servo_.jacobianPinv() * sdot_target;
      }
    }
  } else if (filter_.initialized()) {
    // Search: spiral in joint space around the joints that pointed at the last prediction.
    out.mode = TrackingMode::Searching;
    if (!searching_) {
      searching_ = true;
      search_start_ = in.t;
      const tracking::PlanarTargetFilter::Kinematics k = filter_.at(std::max(in.t, filter_.state().t()));
      const Eigen::Vector3d P_f = f_M_plane_ * Eigen::Vector3d(k.p.x(), k.p.y(), 0.0);
      search_center_ = kinematics_.pointAt(P_f);
    }
    // Archimedean spiral r = b θ / 2π with arc-length speed ~ search_speed: dθ/dt = v / sqrt(r² + (b/2π)²).
    const double b = config_.search_growth / (2.0 * core::kPi);
    const double tau = in.t + latency_ - search_start_;
    // Closed form of θ(t) for ds/dt = v with s(θ) ≈ b θ² / 2 (r >> b): θ = sqrt(2 v t / b).
    double theta = std::sqrt(2.0 * config_.search_speed * tau / b);
    const double theta_max = config_.search_radius / b;
    theta = std::fmod(theta, theta_max);
    const double r = b * theta;
    const Eigen::Vector2d q_s = search_center_ + r * Eigen::Vector2d(std::cos(theta), std::sin(theta));
    const double dtheta = config_.search_speed / std::sqrt(r * r + b * b);
    const Eigen::Vector2d dq_s = dtheta * (b * Eigen::Vector2d(std::cos(theta), std::sin(theta)) +
                                           r * Eigen::Vector2d(-std::sin(theta), std::cos(theta)));
    Eigen::Vector2d q_goal = q_s;
    for (int i = 0; i < 2; ++i) q_goal(i) = std::clamp(q_goal(i), limits_.q_min(i), limits_.q_max(i));
    out.qdot_unlimited = dq_s + config_.search_gain * (q_goal - e.q);
  }
  out.qdot = robots::limitVelocityCommand(limits_, e.q, e.qdot, out.qdot_unlimited, in.period, config_.limits.margin);
  return out;
}

}  // namespace viewline::control
