#include "viewline/control/pan_tilt_servo.h"

#include <algorithm>
#include <cmath>
#include <visp3/core/vpColVector.h>
#include <visp3/visual_features/vpFeaturePoint.h>
#include <visp3/vs/vpServo.h>

#include "viewline/core/checks.h"
#include "viewline/core/error.h"
#include "viewline/core/frames.h"
#include "viewline/core/statistics.h"
#include "viewline/estimation/kalman_filter.h"
#include "viewline/estimation/models/coordinated_turn.h"

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

TargetModel targetModelFromString(const std::string& name) {
  if (name == "constant_velocity" || name == "cv") return TargetModel::ConstantVelocity;
  if (name == "constant_acceleration" || name == "ca") return TargetModel::ConstantAcceleration;
  if (name == "singer") return TargetModel::Singer;
  if (name == "coordinated_turn" || name == "ct") return TargetModel::CoordinatedTurn;
  if (name == "imm") return TargetModel::Imm;
  throw core::InvalidInput("target model: expected constant_velocity (cv), constant_acceleration (ca), singer, "
                           "coordinated_turn (ct) or imm, got '" + name + "'");
}

const char* toString(TargetModel model) {
  switch (model) {
    case TargetModel::ConstantVelocity: return "constant_velocity";
    case TargetModel::ConstantAcceleration: return "constant_acceleration";
    case TargetModel::Singer: return "singer";
    case TargetModel::CoordinatedTurn: return "coordinated_turn";
    case TargetModel::Imm: return "imm";
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
  if (!(jump_window >= 0.0) || !std::isfinite(jump_window)) throw core::InvalidInput("filter.jump_window must be >= 0");
  core::requirePositive(jump_threshold, "filter.jump_threshold");
  if (jump_min_samples < 2) throw core::InvalidInput("filter.jump_min_samples must be >= 2");
}

namespace {
// CV on (p, v) with the turn rate carried along as a random walk (state (p, v, ω)).
estimation::NonlinearTransition cvWithOmega(double q, double q_omega, double dt) {
  Eigen::MatrixXd Phi = Eigen::MatrixXd::Identity(5, 5);
  Phi(0, 2) = Phi(1, 3) = dt;
  estimation::models::CoordinatedTurnParams p;
  p.q_accel = q;
  p.q_omega = q_omega;
  estimation::NonlinearTransition tr;
  tr.f = [Phi](const Eigen::VectorXd& x) { return Eigen::VectorXd(Phi * x); };
  tr.F = [Phi](const Eigen::VectorXd&) { return Phi; };
  tr.Q = estimation::models::coordinatedTurnNoise(p, dt);  // same blocks: CV on (p, v), q_ω dt on ω
  tr.dt = dt;
  return tr;
}

}  // namespace

int PlanarTargetFilter::stateDim() const {
  switch (config_.model) {
    case TargetModel::ConstantVelocity: return 4;
    case TargetModel::CoordinatedTurn:
    case TargetModel::Imm: return 5;
    default: return 6;
  }
}

Eigen::VectorXd PlanarTargetFilter::modeProbabilities() const {
  if (imm_ && imm_->initialized()) return imm_->probabilities();
  return {};
}

PlanarTargetFilter::PlanarTargetFilter(const TargetFilterConfig& config) : config_(config) {
  config_.validate();
  const int n = stateDim();
  const Eigen::Matrix2d I = Eigen::Matrix2d::Identity();
  model_.A = Eigen::MatrixXd::Zero(n, n);
  model_.G = Eigen::MatrixXd::Zero(n, 2);
  model_.B = Eigen::MatrixXd(n, 0);
  model_.A.block(0, 2, 2, 2) = I;
  if (n == 4) {
    model_.G.block(2, 0, 2, 2) = I;
    model_.Qc = config_.q * I;
  } else if (n == 6) {
    model_.A.block(2, 4, 2, 2) = I;
    model_.G.block(4, 0, 2, 2) = I;
    if (config_.model == TargetModel::Singer) {
      model_.A.block(4, 4, 2, 2) = -I / config_.singer_tau;
      model_.Qc = (2.0 * config_.singer_sigma * config_.singer_sigma / config_.singer_tau) * I;
    } else {
      model_.Qc = config_.q * I;
    }
  }
  gate_ = core::chiSquareQuantile(2.0, config_.gate_probability);
  if (usesImm()) {
    estimation::models::CoordinatedTurnParams ct;
    ct.q_accel = config_.ct_q_accel;
    ct.q_omega = config_.ct_q_omega;
    std::vector<estimation::ImmMode> modes;
    if (config_.model == TargetModel::Imm) {
      const TargetFilterConfig c = config_;
      modes.push_back({"cv", [c](double dt) { return cvWithOmega(c.q, c.ct_q_omega, dt); }, c.imm_sojourn(0)});
      modes.push_back({"ct", [ct](double dt) { return estimation::models::coordinatedTurnTransition(ct, dt); },
                       c.imm_sojourn(1)});
      modes.push_back({"maneuver", [c](double dt) { return cvWithOmega(c.maneuver_q, c.ct_q_omega, dt); },
                       c.imm_sojourn(2)});
    } else {
      modes.push_back({"ct", [ct](double dt) { return estimation::models::coordinatedTurnTransition(ct, dt); }, 1.0});
    }
    imm_.emplace(std::move(modes));
  }
}

void PlanarTargetFilter::reset(core::Timestamp t, const Eigen::Vector2d& z, const Eigen::Matrix2d& R) {
  core::requireFinite(z, "PlanarTargetFilter: z");
  const int n = std::max(stateDim(), 4);  // (the max tells gcc n > 2: no false null-dereference warning)
  Eigen::VectorXd x = Eigen::VectorXd::Zero(n);
  x(0) = z(0);
  x(1) = z(1);
  Eigen::MatrixXd P = Eigen::MatrixXd::Zero(n, n);
  P.block(0, 0, 2, 2) = R;
  P.block(2, 2, 2, 2) = std::pow(config_.init_velocity_sigma, 2) * Eigen::Matrix2d::Identity();
  if (n == 6) P.block(4, 4, 2, 2) = std::pow(config_.init_acceleration_sigma, 2) * Eigen::Matrix2d::Identity();
  if (n == 5) P(4, 4) = std::pow(config_.init_omega_sigma, 2);
  state_ = estimation::StateEstimate(x, P, t);
  if (imm_) imm_->reset(x, P, t);
  initialized_ = true;
  rejected_in_a_row_ = 0;
  history_.clear();
  if (config_.jump_window > 0.0) history_.push_back(snapshot(t, z, R));
}

PlanarTargetFilter::Update PlanarTargetFilter::update(core::Timestamp t, const Eigen::Vector2d& z,
                                                      const Eigen::Matrix2d& R) {
  Update out = step(t, z, R);
  if (config_.jump_window <= 0.0 || out.reinitialized || !out.accepted) return out;
  history_.push_back(snapshot(t, z, R));
  while (history_.size() > 1 && history_.front().t < t - config_.jump_window) history_.erase(history_.begin());
  out.jump = detectJump();
  return out;
}

PlanarTargetFilter::Snapshot PlanarTargetFilter::snapshot(core::Timestamp t, const Eigen::Vector2d& z,
                                                          const Eigen::Matrix2d& R) const {
  Snapshot s;
  s.t = t;
  s.z = z;
  s.R = R;
  s.state = state_;
  if (imm_) s.imm = *imm_;
  return s;
}

Eigen::Vector2d PlanarTargetFilter::extrapolatePosition(const Eigen::VectorXd& x, double tau) const {
  if (x.size() == 5) {
    // Coordinated turn, either direction in time: p(τ) = p + (sin ωτ / ω) v + ((1 − cos ωτ) / ω) J v.
    const double w = x(4), wt = w * tau;
    const double s = std::abs(wt) < 1e-4 ? tau * (1.0 - wt * wt / 6.0) : std::sin(wt) / w;
    const double c = std::abs(wt) < 1e-4 ? 0.5 * wt * tau : (1.0 - std::cos(wt)) / w;
    const Eigen::Vector2d v = x.segment<2>(2);
    return x.head<2>() + s * v + c * Eigen::Vector2d(-v.y(), v.x());
  }
  Eigen::Vector2d p = x.head<2>() + tau * x.segment<2>(2);
  if (x.size() == 6) p += 0.5 * tau * tau * x.segment<2>(4);
  return p;
}

bool PlanarTargetFilter::detectJump() {
  // Likelihood-ratio test for a step Δv in velocity at one of the recent measurement times t_j, the
  // position staying continuous (a corner of a polyline at constant speed). For a candidate j, the
  // measurements of the window are compared with the state x(j|j) run by the model to their times
  // (forwards and backwards), r_i = z_i − p̂_j(τ_i), τ_i = t_i − t_j. Per axis a, with weights
  // w_i = 1 / R_i,aa, the residuals are fitted by
  //   H0: r = α + β τ + γ τ²            (x(j|j)'s own position, velocity and turn-rate errors)
  //   H1: r = α + β τ + γ τ² + Δv_a τ₊  (τ₊ = max(τ, 0): a kink at t_j)
  // α, β free, γ with the prior N(0, (½ |v_j| σ_ω,j)²) of x(j|j)'s turn-rate error (CT/IMM state;
  // γ = 0 for CV/CA), by penalised least squares; ℓ_j, the drop of the penalised weighted residual
  // sum from H0 to H1 summed over both axes, is about χ² with 2 dof when there is no jump (for one
  // candidate; the scan over candidates and steps makes false jumps more frequent: at 15, 3 over
  // four straight 12 s tracks of 30 measurements/s with a 3 s window, in the unit test).
  // The largest ℓ_j above jump_threshold, with at least jump_min_samples measurements on each side
  // of t_j, declares a jump at t_j: the filter goes back
  // to x(j|j), its velocity (and turn rate or acceleration) prior is re-opened as at initialisation,
  // the position kept, and the measurements after t_j are processed again. x(k|k) stays a filtered
  // estimate (it uses measurements up to t_k only).
  const int n = static_cast<int>(history_.size());
  const int m = config_.jump_min_samples;
  if (n < 2 * m + 1) return false;
  double best = config_.jump_threshold;
  int best_j = -1;
  std::vector<double> tau(static_cast<std::size_t>(n));
  std::vector<Eigen::Vector2d> r(static_cast<std::size_t>(n));
  for (int j = m; j + m < n; ++j) {
    const Snapshot& sj = history_[static_cast<std::size_t>(j)];
    for (int i = 0; i < n; ++i) {
      const Snapshot& si = history_[static_cast<std::size_t>(i)];
      tau[static_cast<std::size_t>(i)] = si.t - sj.t;
      r[static_cast<std::size_t>(i)] = si.z - extrapolatePosition(sj.state.x(), si.t - sj.t);
    }
    // Prior std of γ: the turn-rate uncertainty of x(j|j) bends the extrapolation by ½ |v| δω τ².
    const Eigen::VectorXd& xj = sj.state.x();
    double sigma_gamma = 0.0;
    if (xj.size() == 5) sigma_gamma = 0.5 * xj.segment<2>(2).norm() * std::sqrt(std::max(sj.state.P()(4, 4), 0.0));
    const bool curved = sigma_gamma > 0.0;  // (CV/CA: no γ column)
    const double gamma_weight = curved ? 1.0 / (sigma_gamma * sigma_gamma) : 1.0;
    double l = 0.0;
    for (int a = 0; a < 2; ++a) {
      // Penalised least squares (γ with its prior, α, β and Δv free) under H0 and H1:
      // min ‖r − X θ‖²_W + θᵀ Λ θ = rᵀ W r − (Xᵀ W r)ᵀ (Xᵀ W X + Λ)⁻¹ Xᵀ W r.
      Eigen::Matrix4d M = Eigen::Matrix4d::Zero();
      Eigen::Vector4d g = Eigen::Vector4d::Zero();
      for (int i = 0; i < n; ++i) {
        const double w = 1.0 / history_[static_cast<std::size_t>(i)].R(a, a);
        const double ti = tau[static_cast<std::size_t>(i)];
        const Eigen::Vector4d xi(1.0, ti, curved ? ti * ti : 0.0, std::max(ti, 0.0));
        M += w * xi * xi.transpose();
        g += w * r[static_cast<std::size_t>(i)](a) * xi;
      }
      M(2, 2) += gamma_weight;
      const Eigen::Vector3d g0 = g.head<3>();
      const double fit0 = g0.dot(M.topLeftCorner<3, 3>().ldlt().solve(g0));
      const double fit1 = g.dot(M.ldlt().solve(g));
      l += fit1 - fit0;
    }
    if (l > best) {
      best = l;
      best_j = j;
    }
  }
  if (best_j < 0) return false;
  // Back to x(j|j) with the motion prior re-opened, then the later measurements again.
  std::vector<Snapshot> later(history_.begin() + best_j + 1, history_.end());
  history_.erase(history_.begin(), history_.begin() + best_j);
  history_.resize(1);
  Snapshot& sj = history_.front();
  Eigen::VectorXd x = sj.state.x();
  Eigen::MatrixXd P = sj.state.P();
  const int dim = static_cast<int>(x.size());
  const Eigen::Matrix2d P_pos = P.block(0, 0, 2, 2);
  P.setZero();
  P.block(0, 0, 2, 2) = P_pos;
  P.block(2, 2, 2, 2) = std::pow(config_.init_velocity_sigma, 2) * Eigen::Matrix2d::Identity();
  if (dim == 5) {
    x(4) = 0.0;
    P(4, 4) = std::pow(config_.init_omega_sigma, 2);
  }
  if (dim == 6) P.block(4, 4, 2, 2) = std::pow(config_.init_acceleration_sigma, 2) * Eigen::Matrix2d::Identity();
  state_ = estimation::StateEstimate(x, P, sj.t);
  if (imm_) {
    imm_ = *sj.imm;
    imm_->reset(x, P, sj.t, sj.imm->probabilities());
  }
  sj = snapshot(sj.t, sj.z, sj.R);
  rejected_in_a_row_ = 0;
  ++jumps_;
  for (const Snapshot& s : later) {
    const Update u = step(s.t, s.z, s.R);
    if (u.reinitialized) history_.clear();
    if (u.accepted) history_.push_back(snapshot(s.t, s.z, s.R));
  }
  return true;
}

PlanarTargetFilter::Update PlanarTargetFilter::step(core::Timestamp t, const Eigen::Vector2d& z,
                                                    const Eigen::Matrix2d& R) {
  Update out;
  if (!initialized_) {
    reset(t, z, R);
    out.accepted = out.reinitialized = true;
    return out;
  }
  const double dt = t - state_.t();
  estimation::LinearMeasurement m;
  m.C = Eigen::MatrixXd::Zero(2, stateDim());
  m.C.block(0, 0, 2, 2) = Eigen::Matrix2d::Identity();
  m.y = z;
  m.R = R;
  if (imm_) {
    if (dt > 1e-9) imm_->predict(t);
    state_ = imm_->combined();
    out.nis = imm_->combinedNis(m);
    if (out.nis > gate_) {
      if (++rejected_in_a_row_ >= config_.reinit_after) {
        reset(t, z, R);
        out.accepted = out.reinitialized = true;
      }
      return out;
    }
    rejected_in_a_row_ = 0;
    imm_->update(m);
    state_ = imm_->combined();
    out.accepted = true;
    return out;
  }
  if (dt > 1e-9) estimation::predict(state_, estimation::discretize(model_, dt));
  const Eigen::MatrixXd S = estimation::innovationCovariance(state_, m.C, m.R);
  const Eigen::Vector2d d = z - state_.x().head<2>();
  out.nis = d.dot(S.ldlt().solve(d));
  if (out.nis > gate_) {
    if (++rejected_in_a_row_ >= config_.reinit_after) {
      reset(t, z, R);
      out.accepted = out.reinitialized = true;
    }
    return out;
  }
  rejected_in_a_row_ = 0;
  estimation::update(state_, m);
  out.accepted = true;
  return out;
}

PlanarTargetFilter::Kinematics PlanarTargetFilter::at(core::Timestamp t) const {
  if (!initialized_) throw core::Error("PlanarTargetFilter::at: filter not initialised");
  Kinematics k;
  const double dt = t - state_.t();
  Eigen::VectorXd x = state_.x();
  Eigen::MatrixXd P = state_.P();
  if (imm_) {
    estimation::Imm ahead = *imm_;
    if (dt > 1e-9) ahead.predict(t);
    const estimation::StateEstimate s = ahead.combined();
    k.p = s.x().head<2>();
    k.v = s.x().segment<2>(2);
    k.a = s.x()(4) * Eigen::Vector2d(-k.v.y(), k.v.x());  // ω J v
    k.P_pos = s.P().block(0, 0, 2, 2);
    return k;
  }
  if (dt > 1e-9) {
    const estimation::LinearTransition tr = estimation::discretize(model_, dt);
    x = tr.Phi * x;
    P = tr.Phi * P * tr.Phi.transpose() + tr.Q;
  }
  k.p = x.head<2>();
  k.v = x.segment<2>(2);
  if (stateDim() == 6) k.a = x.segment<2>(4);
  k.P_pos = P.block(0, 0, 2, 2);
  return k;
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
  } else {
    last_update_ = filter_.update(obs.stamp, obs.plane, obs.plane_cov);
  }
  if (last_update_.accepted) {
    last_accepted_ = obs.stamp;
    filtered_ = filter_.state().x().head<2>();
    searching_ = false;
  }
}

ControlOutput PredictivePanTiltController::command(const ControlInput& in) {
  ControlOutput out;
  const robots::JointState e = effectState(limits_, in, latency_);
  const double t_e = in.t + latency_ + config_.lead;
  if (filter_.initialized() && in.t - last_accepted_ <= config_.coast_time) {
    out.mode = (in.t - last_accepted_ <= 2.5 * in.period) ? TrackingMode::Tracking : TrackingMode::Coasting;
    const PlanarTargetFilter::Kinematics k = filter_.at(t_e);
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
      const PlanarTargetFilter::Kinematics k = filter_.at(std::max(in.t, filter_.state().t()));
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
