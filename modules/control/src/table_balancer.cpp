#include "viewline/control/table_balancer.h"

#include <Eigen/Cholesky>
#include <Eigen/Eigenvalues>
#include <algorithm>
#include <cmath>
#include <string>

#include "viewline/core/checks.h"
#include "viewline/core/error.h"
#include "viewline/estimation/discretization.h"
#include "viewline/estimation/riccati.h"

namespace viewline::control {

namespace {
constexpr Eigen::Index kE = 0, kV = 1, kPhi = 2, kI = 3, kBuf = 4;

using core::requireNonNegative;
}  // namespace

void TableBalancerConfig::validate() const {
  core::requirePositive(period, "TableBalancerConfig.period");
  requireNonNegative(delay, "TableBalancerConfig.delay");
  core::requirePositive(max_angle, "TableBalancerConfig.max_angle");
  core::requirePositive(max_rate, "TableBalancerConfig.max_rate");
  core::requirePositive(gravity, "TableBalancerConfig.gravity");
  requireNonNegative(q_position, "TableBalancerConfig.q_position");
  requireNonNegative(q_velocity, "TableBalancerConfig.q_velocity");
  requireNonNegative(q_tilt, "TableBalancerConfig.q_tilt");
  requireNonNegative(q_integral, "TableBalancerConfig.q_integral");
  core::requirePositive(r_rate, "TableBalancerConfig.r_rate");
  core::requirePositive(integral_band, "TableBalancerConfig.integral_band");
  if (q_position <= 0.0) throw core::InvalidInput("TableBalancerConfig.q_position: expected > 0");
  if (delay > 50.0 * period) throw core::InvalidInput("TableBalancerConfig.delay: more than 50 periods");
}

Eigen::Vector2d TiltRamp::commandAt(double t) const {
  const double s = std::clamp(t - t0, 0.0, period);
  return start + s * rate;
}

TableBalancer::TableBalancer(const TableBalancerConfig& config) : config_(config) {
  config_.validate();
  const double T = config_.period;
  const double c = 5.0 / 7.0 * config_.gravity;
  m_ = static_cast<int>(std::floor(config_.delay / T + 1e-9));
  double tau = config_.delay - m_ * T;
  if (tau < 1e-12 * T) tau = 0.0;

  // Continuous chain s = (e, v, φ), input φ̇.
  estimation::ContinuousLinearModel chain;
  chain.A = Eigen::MatrixXd::Zero(3, 3);
  chain.A(0, 1) = 1.0;
  chain.A(1, 2) = c;
  chain.B = Eigen::MatrixXd::Zero(3, 1);
  chain.B(2, 0) = 1.0;
  chain.G = Eigen::MatrixXd::Zero(3, 1);
  chain.Qc = Eigen::MatrixXd::Zero(1, 1);
  const Eigen::VectorXd u1 = Eigen::VectorXd::Ones(1);
  const estimation::LinearTransition full = estimation::discretize(chain, T, u1);
  Eigen::VectorXd gamma_a = Eigen::VectorXd::Zero(3), gamma_b = full.Gamma.col(0);
  if (tau > 0.0) {
    const estimation::LinearTransition first = estimation::discretize(chain, tau, u1);
    const estimation::LinearTransition rest = estimation::discretize(chain, T - tau, u1);
    gamma_a = rest.Phi * first.Gamma.col(0);
    gamma_b = rest.Gamma.col(0);
  }

  nz_ = kBuf + m_ + 1;
  A_ = Eigen::MatrixXd::Zero(nz_, nz_);
  B_ = Eigen::MatrixXd::Zero(nz_, 1);
  A_.topLeftCorner(3, 3) = full.Phi;
  A_(kI, kI) = 1.0;
  A_(kI, kE) = T;
  // u(k−m−1) is the last buffer entry; u(k−m) is the input itself when m = 0, else buffer m−1.
  A_.block(0, kBuf + m_, 3, 1) = gamma_a;
  if (m_ == 0) {
    B_.topRows(3) = gamma_b;
  } else {
    A_.block(0, kBuf + m_ - 1, 3, 1) = gamma_b;
  }
  B_(kBuf, 0) = 1.0;
  for (int j = 1; j <= m_; ++j) A_(kBuf + j, kBuf + j - 1) = 1.0;

  Eigen::MatrixXd Q = Eigen::MatrixXd::Zero(nz_, nz_);
  Q(kE, kE) = config_.q_position;
  Q(kV, kV) = config_.q_velocity;
  Q(kPhi, kPhi) = config_.q_tilt;
  if (config_.q_integral > 0.0) Q(kI, kI) = config_.q_integral;
  // Without integral action the ι state is dropped from the design (it would be an undamped mode
  // that the cost does not see); its gain is then zero. S selects the designed states.
  const bool with_integral = config_.q_integral > 0.0;
  const Eigen::Index n = with_integral ? nz_ : nz_ - 1;
  Eigen::MatrixXd S = Eigen::MatrixXd::Zero(nz_, n);
  for (Eigen::Index i = 0, j = 0; i < nz_; ++i) {
    if (with_integral || i != kI) S(i, j++) = 1.0;
  }
  const Eigen::MatrixXd Ad = S.transpose() * A_ * S;
  const Eigen::MatrixXd Bd = S.transpose() * B_;
  Q = (S.transpose() * Q * S).eval();
  const Eigen::MatrixXd R = Eigen::MatrixXd::Constant(1, 1, config_.r_rate);
  // Control DARE = the filter DARE of the dual pair (Aᵀ, Bᵀ).
  const estimation::StationaryFilter dual = estimation::solveDare(Ad.transpose(), Bd.transpose(), Q, R);
  const Eigen::MatrixXd& X = dual.P;
  const Eigen::MatrixXd BtX = Bd.transpose() * X;
  const Eigen::MatrixXd Kd = (BtX * Bd + R).ldlt().solve(BtX * Ad);
  K_ = (Kd * S.transpose()).row(0);
  reset();
}

double TableBalancer::closedLoopSpectralRadius() const {
  Eigen::MatrixXd Acl = A_ - B_ * K_;
  if (config_.q_integral <= 0.0) Acl(kI, kI) = 0.0;  // ι is not used (zero gain, not integrated)
  const Eigen::EigenSolver<Eigen::MatrixXd> es(Acl, false);
  double rho = 0.0;
  for (Eigen::Index i = 0; i < Acl.rows(); ++i) rho = std::max(rho, std::abs(es.eigenvalues()[i]));
  return rho;
}

void TableBalancer::reset(const Eigen::Vector2d& tilt) {
  core::requireFinite(tilt, "TableBalancer::reset: tilt");
  const Eigen::Vector2d phi(tilt.y(), -tilt.x());
  z_ = Eigen::MatrixXd::Zero(nz_, 2);
  z_.row(kPhi) = phi.transpose();
  phi_cmd_ = phi;
}

void TableBalancer::hold(const Eigen::Vector2d& tilt) {
  core::requireFinite(tilt, "TableBalancer::hold: tilt");
  const Eigen::Vector2d phi(tilt.y(), -tilt.x());
  z_.row(kPhi) = phi.transpose();
  z_.bottomRows(nz_ - kBuf).setZero();  // no input in flight: the refused ramps never started
  phi_cmd_ = phi;
}

Eigen::Vector2d TableBalancer::commandedTilt() const { return {-phi_cmd_.y(), phi_cmd_.x()}; }
Eigen::Vector2d TableBalancer::modelTilt() const { return {-z_(kPhi, 1), z_(kPhi, 0)}; }

TiltRamp TableBalancer::update(double t, const Eigen::Vector2d& p, const Eigen::Vector2d& v,
                               const Eigen::Vector2d& setpoint) {
  core::requireFinite(t, "TableBalancer::update: t");
  core::requireFinite(p, "TableBalancer::update: position");
  core::requireFinite(v, "TableBalancer::update: velocity");
  core::requireFinite(setpoint, "TableBalancer::update: setpoint");
  const double T = config_.period;
  TiltRamp ramp;
  ramp.t0 = t;
  ramp.period = T;
  ramp.start = commandedTilt();
  Eigen::Vector2d u;
  for (int a = 0; a < 2; ++a) {
    auto z = z_.col(a);
    z(kE) = p[a] - setpoint[a];
    z(kV) = v[a];
    const double u_lqr = -K_.dot(z);
    // Rate limit, and the ramp's end inside the angle limit.
    const double lo = std::max(-config_.max_rate, (-config_.max_angle - phi_cmd_[a]) / T);
    const double hi = std::min(config_.max_rate, (config_.max_angle - phi_cmd_[a]) / T);
    u[a] = std::clamp(u_lqr, std::min(lo, 0.0), std::max(hi, 0.0));
    u[a] = std::clamp(u[a], -config_.max_rate, config_.max_rate);
    const bool saturated = std::abs(u[a] - u_lqr) > 1e-12;
    // Propagate the internal part of the model (φ, ι, inputs in flight) with the applied input.
    Eigen::VectorXd next = A_ * z + B_ * u[a];
    if (config_.q_integral <= 0.0 || saturated || std::abs(z(kE)) > config_.integral_band) next(kI) = z(kI);
    z = next;
    phi_cmd_[a] = std::clamp(phi_cmd_[a] + T * u[a], -config_.max_angle, config_.max_angle);
  }
  ramp.rate = Eigen::Vector2d(-u.y(), u.x());
  return ramp;
}

}  // namespace viewline::control
