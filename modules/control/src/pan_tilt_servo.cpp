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
  if (name == "waypoint_particles") return TargetModel::WaypointParticles;
  throw core::InvalidInput("target model: expected constant_velocity (cv), constant_acceleration (ca), singer, "
                           "coordinated_turn (ct), imm or waypoint_particles, got '" + name + "'");
}

const char* toString(TargetModel model) {
  switch (model) {
    case TargetModel::ConstantVelocity: return "constant_velocity";
    case TargetModel::ConstantAcceleration: return "constant_acceleration";
    case TargetModel::Singer: return "singer";
    case TargetModel::CoordinatedTurn: return "coordinated_turn";
    case TargetModel::Imm: return "imm";
    case TargetModel::WaypointParticles: return "waypoint_particles";
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
  if (constant_speed && (model != TargetModel::ConstantVelocity || !(jump_window > 0.0)))
    throw core::InvalidInput("filter.constant_speed needs model constant_velocity and jump detection "
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

// ---------------------------------------------------------------------------------------------
// A constant-speed leg (see the class comment): measurements z_i = c + s τ_i u(θ) + e_i, τ_i = t_i − t_c,
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
namespace {
// Distance from c (inside the box [lo, hi]) to the box's boundary along u(θ).
double boxReach(const Eigen::Vector2d& c, const Eigen::Vector2d& lo, const Eigen::Vector2d& hi, double th) {
  const Eigen::Vector2d u(std::cos(th), std::sin(th));
  double r = std::numeric_limits<double>::infinity();
  for (int a = 0; a < 2; ++a) {
    if (u(a) > 1e-12) r = std::min(r, (hi(a) - c(a)) / u(a));
    if (u(a) < -1e-12) r = std::min(r, (lo(a) - c(a)) / u(a));
  }
  return std::max(r, 0.0);
}
}  // namespace

double waypointDirectionDensity(const Eigen::Vector2d& c, const Eigen::Vector2d& center, const Eigen::Vector2d& size,
                                double theta) {
  if (!(size.x() > 0.0 && size.y() > 0.0)) throw core::InvalidInput("waypointDirectionDensity: size must be > 0");
  const Eigen::Vector2d lo = center - 0.5 * size, hi = center + 0.5 * size;
  const double R = boxReach(c.cwiseMax(lo).cwiseMin(hi), lo, hi, theta);
  return R * R / (2.0 * size.x() * size.y());
}

struct PlanarTargetFilter::Leg {
  double t_c = 0.0;
  Eigen::Vector3d beta0 = Eigen::Vector3d::Zero();
  Eigen::Matrix3d P0_inv = Eigen::Matrix3d::Identity();
  std::vector<double> prior_mu;  ///< μ_k (rad); empty: θ uniform
  double prior_sigma = 0.1, prior_weight = 0.0;
  bool region = false;            ///< waypoint-region prior p(θ) = R(θ)² / (2A) from region_c
  Eigen::Vector2d region_c = Eigen::Vector2d::Zero(), region_lo = Eigen::Vector2d::Zero(), region_hi = Eigen::Vector2d::Zero();
  double region_log_scale = 0.0;  ///< log(π / A)
  double log_norm = 0.0;          ///< normalises the product of the two priors (0 when at most one is on)
  Eigen::Matrix2d A = Eigen::Matrix2d::Zero(), Bt = Eigen::Matrix2d::Zero(), Ctt = Eigen::Matrix2d::Zero();
  Eigen::Vector2d Bz = Eigen::Vector2d::Zero(), Ctz = Eigen::Vector2d::Zero();
  double zz = 0.0;

  void add(double t, const Eigen::Vector2d& z, const Eigen::Matrix2d& R) {
    const Eigen::Matrix2d Ri = R.inverse();
    const double tau = t - t_c;
    A += Ri;
    Bz += Ri * z;
    Bt += tau * Ri;
    Ctz += tau * (Ri * z);
    Ctt += tau * tau * Ri;
    zz += z.dot(Ri * z);
  }

  double logPrior(double th) const {
    double lp = log_norm;
    if (region) {
      // log(2π R² / (2A)); R floored at 0.1 mm so that a corner estimated on the boundary stays finite.
      const double R = std::max(boxReach(region_c, region_lo, region_hi, th), 1e-4);
      lp += region_log_scale + 2.0 * std::log(R);
    }
    if (prior_mu.empty() || prior_weight <= 0.0) return lp;
    double g = 0.0;
    for (double mu : prior_mu) {
      const double d = std::remainder(th - mu, 2.0 * core::kPi);  // wrapped to [−π, π]; σ ≪ π, one wrap suffices
      if (d * d < 100.0 * prior_sigma * prior_sigma) g += std::exp(-0.5 * d * d / (prior_sigma * prior_sigma));  // (e^-50 beyond)
    }
    g *= std::sqrt(2.0 * core::kPi) / prior_sigma / static_cast<double>(prior_mu.size());
    return lp + std::log((1.0 - prior_weight) + prior_weight * g);
  }

  /// log p(z | θ) (up to a constant), and the posterior mean and covariance of β = (c, s) given θ.
  double logLikelihood(double th, Eigen::Vector3d* m = nullptr, Eigen::Matrix3d* cov = nullptr) const {
    const Eigen::Vector2d u(std::cos(th), std::sin(th));
    Eigen::Matrix3d L = P0_inv;
    L.topLeftCorner<2, 2>() += A;
    const Eigen::Vector2d Btu = Bt * u;
    L.block<2, 1>(0, 2) += Btu;
    L.block<1, 2>(2, 0) += Btu.transpose();
    L(2, 2) += u.dot(Ctt * u);
    const Eigen::Vector3d P0_b0 = P0_inv * beta0;
    Eigen::Vector3d eta = P0_b0;
    eta.head<2>() += Bz;
    eta(2) += u.dot(Ctz);
    const Eigen::LLT<Eigen::Matrix3d> llt(L);
    const Eigen::Vector3d mean = llt.solve(eta);
    if (m != nullptr) *m = mean;
    if (cov != nullptr) *cov = llt.solve(Eigen::Matrix3d::Identity());
    const double logdet = 2.0 * Eigen::Matrix3d(llt.matrixL()).diagonal().array().log().sum();
    return -0.5 * (zz + beta0.dot(P0_b0) - eta.dot(mean)) - 0.5 * logdet;
  }

  /// log p(measurements | leg) up to the terms every candidate corner time shares (Σ log det 2πR_i, and
  /// −½ log det P₀ when P₀ is the same): log of the mean over θ of p(z | θ) p(θ) 2π, on a grid of
  /// `points` (the rectangle rule, exact to e^(−2π² σ²/h²) for a periodic integrand of width σ, step h).
  /// Every θ shares Λ's top-left block M = P₀⁻¹_cc + A, so log p(z | θ) is evaluated through the Schur
  /// complement of M (the same value as logLikelihood(θ), a few flops per θ instead of a 3x3 factorisation):
  ///   b = P₀⁻¹_cs + B_τ u, c = P₀⁻¹_ss + uᵀ C_ττ u, η = (η_c, η_s), g = M⁻¹ η_c,
  ///   ηᵀ Λ⁻¹ η = η_cᵀ g + (η_s − bᵀ g)² / σ,  log det Λ = log det M + log σ,  σ = c − bᵀ M⁻¹ b.
  double logEvidence(int points = 360) const {
    const Eigen::Matrix2d M = P0_inv.topLeftCorner<2, 2>() + A;
    const Eigen::LLT<Eigen::Matrix2d> llt_M(M);
    const Eigen::Matrix2d Mi = llt_M.solve(Eigen::Matrix2d::Identity());
    const double logdet_M = 2.0 * Eigen::Matrix2d(llt_M.matrixL()).diagonal().array().log().sum();
    const Eigen::Vector3d P0_b0 = P0_inv * beta0;
    const Eigen::Vector2d eta_c = P0_b0.head<2>() + Bz;
    const Eigen::Vector2d g = Mi * eta_c;
    const double base = zz + beta0.dot(P0_b0) - eta_c.dot(g);
    const Eigen::Vector2d P0_cs = P0_inv.block<2, 1>(0, 2);
    std::vector<double> ll(static_cast<std::size_t>(points));
    double top = -std::numeric_limits<double>::infinity();
    for (int k = 0; k < points; ++k) {
      const double th = -core::kPi + 2.0 * core::kPi * k / points;
      const Eigen::Vector2d u(std::cos(th), std::sin(th));
      const Eigen::Vector2d b = P0_cs + Bt * u;
      const double schur = P0_inv(2, 2) + u.dot(Ctt * u) - b.dot(Mi * b);
      const double r = P0_b0(2) + u.dot(Ctz) - b.dot(g);
      ll[static_cast<std::size_t>(k)] = -0.5 * (base - r * r / schur) - 0.5 * (logdet_M + std::log(schur)) + logPrior(th);
      top = std::max(top, ll[static_cast<std::size_t>(k)]);
    }
    double sum = 0.0;
    for (double v : ll) sum += std::exp(v - top);
    return top + std::log(sum / points);
  }

  /// The posterior moments of (p, v) at time t (p = c + s (t − t_c) u, v = s u).
  estimation::StateEstimate moments(double t) const {
    struct Point {
      double th = 0.0, ll = 0.0;
      Eigen::Vector3d m = Eigen::Vector3d::Zero();
      Eigen::Matrix3d cov = Eigen::Matrix3d::Zero();
    };
    const auto evaluate = [&](double th) {
      Point pt;
      pt.th = th;
      pt.ll = logLikelihood(th, &pt.m, &pt.cov) + logPrior(th);
      return pt;
    };
    // Grid over θ: 180 points on the circle, then refined (±2 steps of the previous grid, 81 points)
    // while one point holds more than 30 % of the mass, so a narrow posterior is still resolved.
    double lo = -core::kPi, step = 2.0 * core::kPi / 180.0;
    int count = 180;
    std::vector<Point> grid;
    for (int level = 0; level < 6; ++level) {
      grid.clear();
      for (int k = 0; k < count; ++k) grid.push_back(evaluate(lo + step * k));
      const auto best = std::max_element(grid.begin(), grid.end(), [](const Point& a, const Point& b) { return a.ll < b.ll; });
      double total = 0.0;
      for (const Point& pt : grid) total += std::exp(pt.ll - best->ll);
      if (1.0 / total < 0.3) break;
      lo = best->th - 2.0 * step;
      step = 4.0 * step / 80.0;
      count = 81;
    }
    double top = -1e300;
    for (const Point& pt : grid) top = std::max(top, pt.ll);
    const double tau = t - t_c;
    Eigen::Vector4d mean = Eigen::Vector4d::Zero();
    Eigen::Matrix4d second = Eigen::Matrix4d::Zero();
    double wsum = 0.0;
    for (const Point& pt : grid) {
      const double w = std::exp(pt.ll - top);
      if (w < 1e-12) continue;
      const Eigen::Vector2d u(std::cos(pt.th), std::sin(pt.th));
      Eigen::Matrix<double, 4, 3> J = Eigen::Matrix<double, 4, 3>::Zero();  // (p, v) = J β
      J.topLeftCorner<2, 2>() = Eigen::Matrix2d::Identity();
      J.block<2, 1>(0, 2) = tau * u;
      J.block<2, 1>(2, 2) = u;
      const Eigen::Vector4d x = J * pt.m;
      wsum += w;
      mean += w * x;
      second += w * (x * x.transpose() + J * pt.cov * J.transpose());
    }
    mean /= wsum;
    Eigen::Matrix4d P = second / wsum - mean * mean.transpose();
    P = 0.5 * (P + P.transpose()).eval();
    P.diagonal().array() += 1e-12;
    return estimation::StateEstimate(Eigen::VectorXd(mean), Eigen::MatrixXd(P), t);
  }
};

int PlanarTargetFilter::stateDim() const {
  switch (config_.model) {
    case TargetModel::ConstantVelocity:
    case TargetModel::WaypointParticles: return 4;
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

namespace {
WaypointParticleConfig particleConfig(const TargetFilterConfig& c, std::uint64_t stream) {
  WaypointParticleConfig w;
  w.particles = c.particles;
  w.region_center = c.region_center;
  w.region_size = c.region_size;
  w.min_leg = c.particle_min_leg;
  w.speed_min = c.particle_speed.x();
  w.speed_max = c.particle_speed.y();
  w.reinit_after = c.reinit_after;
  w.seed = core::deriveSeed(c.particle_seed, stream);
  return w;
}
}  // namespace

void PlanarTargetFilter::setParticleState() {
  const WaypointParticleFilter::Moments m = particles_->moments(particles_->t());
  Eigen::Vector4d x;
  x << m.p, m.v;
  Eigen::Matrix4d P = m.P;
  P.diagonal().array() += 1e-12;
  state_ = estimation::StateEstimate(Eigen::VectorXd(x), Eigen::MatrixXd(P), particles_->t());
}

void PlanarTargetFilter::reset(core::Timestamp t, const Eigen::Vector2d& z, const Eigen::Matrix2d& R) {
  core::requireFinite(z, "PlanarTargetFilter: z");
  if (config_.model == TargetModel::WaypointParticles) {
    particles_.emplace(particleConfig(config_, ++particle_resets_));
    particles_->update(t, z, R);
    setParticleState();
    initialized_ = true;
    rejected_in_a_row_ = 0;
    output_.reset();
    return;
  }
  noteMeasurement(t, R);
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
  output_.reset();
  leg_.reset();
  last_direction_ = std::numeric_limits<double>::quiet_NaN();  // (the learnt turns are kept)
  history_.clear();
  if (config_.jump_window > 0.0) history_.push_back(snapshot(t, z, R));
}

PlanarTargetFilter::Update PlanarTargetFilter::update(core::Timestamp t, const Eigen::Vector2d& z,
                                                      const Eigen::Matrix2d& R) {
  output_.reset();
  if (config_.model == TargetModel::WaypointParticles) {
    Update out;
    if (!initialized_) {
      reset(t, z, R);
      out.accepted = out.reinitialized = true;
      return out;
    }
    const WaypointParticleFilter::Moments prior = particles_->moments(std::max(t, particles_->t()));
    const Eigen::Vector2d e = z - prior.p;
    out.nis = e.dot((prior.P.topLeftCorner<2, 2>() + R).ldlt().solve(e));
    const std::size_t restarts = particles_->reinitialisations();
    particles_->update(t, z, R);
    setParticleState();
    out.accepted = true;
    out.reinitialized = particles_->reinitialisations() != restarts;
    return out;
  }
  noteMeasurement(t, R);
  Update out = step(t, z, R);
  if (out.accepted) checkRegion(z, R);
  // Gated-out measurements are kept for the jump test too: after a sharp corner the first
  // measurements of the new leg are the ones the gate rejects, and they are the evidence of the jump.
  if (config_.jump_window <= 0.0 || out.reinitialized) return out;
  history_.push_back(snapshot(t, z, R));
  while (history_.size() > 1 && history_.front().t < t - config_.jump_window) history_.erase(history_.begin());
  out.jump = detectJump();
  return out;
}

void PlanarTargetFilter::noteMeasurement(core::Timestamp t, const Eigen::Matrix2d& R) {
  last_R_ = R;
  if (std::isfinite(last_t_) && t > last_t_) {
    intervals_.push_back(t - last_t_);
    if (intervals_.size() > 16) intervals_.erase(intervals_.begin());
  }
  if (!std::isfinite(last_t_) || t > last_t_) last_t_ = t;
}

int PlanarTargetFilter::minSamples() const {
  if (config_.jump_min_samples) return *config_.jump_min_samples;
  // "auto": round(k ρ^(2/3)), ρ = σ / (ŝ Δt) (class comment, "Noise-scaled corner settings").
  const double sigma = noiseSigma();
  double dt = 0.0;
  if (!intervals_.empty()) {
    std::vector<double> sorted = intervals_;
    std::nth_element(sorted.begin(), sorted.begin() + static_cast<std::ptrdiff_t>(sorted.size() / 2), sorted.end());
    dt = sorted[sorted.size() / 2];
  }
  double speed = speedEstimate();
  if (!(speed_info_ > 0.0) && initialized_) {
    const Eigen::Vector2d v = state_.x().segment<2>(2);
    const double var_v = state_.P().block<2, 2>(2, 2).trace();
    if (v.squaredNorm() > var_v) speed = v.norm();
  }
  if (!(speed > 0.0) || !(dt > 0.0) || !(sigma > 0.0)) return kAutoJumpSamplesMax;
  const double m = std::round(kAutoJumpSamplesScale * std::cbrt(std::pow(sigma / (speed * dt), 2)));
  return static_cast<int>(std::clamp(m, 2.0, static_cast<double>(kAutoJumpSamplesMax)));
}

double PlanarTargetFilter::cornerSigma() const {
  if (config_.jump_corner_sigma) return *config_.jump_corner_sigma;
  return kAutoCornerSigmaPerNoise * noiseSigma();
}

double PlanarTargetFilter::noiseSigma() const { return std::sqrt(0.5 * std::max(last_R_.trace(), 0.0)); }

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
  const int m = minSamples();
  const bool soft = config_.jump_rate > 0.0;
  output_.reset();
  // Hard test: m <= j < n - m. Soft mixture: every j with m measurements before and 2 after.
  if (n < (soft ? m + 3 : 2 * m + 1)) return false;
  double best = config_.jump_threshold;
  int best_j = -1;
  std::vector<double> tau(static_cast<std::size_t>(n));
  std::vector<Eigen::Vector2d> r(static_cast<std::size_t>(n));
  std::vector<std::pair<double, int>> log_odds;  // soft: log(π_j BF_j), j
  const double prior_precision = soft ? 1.0 / (config_.jump_prior_sigma * config_.jump_prior_sigma) : 0.0;
  const bool leg_bf = soft && legEvidenceMixture();  // the soft mixture's Bayes factors from legs, not kinks
  const std::vector<double> region_odds = soft ? regionJumpOdds() : std::vector<double>{};
  for (int j = m; j + (soft ? 2 : m) < n; ++j) {
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
    double l = 0.0, log_bf = 0.0;
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
      const auto ldlt0 = M.topLeftCorner<3, 3>().ldlt();
      const double fit0 = g0.dot(ldlt0.solve(g0));
      const double fit1 = g.dot(M.ldlt().solve(g));
      l += fit1 - fit0;
      if (soft && !leg_bf) {
        // Bayes factor with Δv_a ~ N(0, jump_prior_sigma²) (α, β flat under both hypotheses):
        // log BF_a = ½ (fit1' − fit0) − ½ log(det M1' / det M0) − ½ log σ_Δ², M1' = M1 + diag(0, 0, 0, 1/σ_Δ²).
        Eigen::Matrix4d M1 = M;
        M1(3, 3) += prior_precision;
        const auto ldlt1 = M1.ldlt();
        const double fit1p = g.dot(ldlt1.solve(g));
        const double logdet1 = ldlt1.vectorD().array().log().sum(), logdet0 = ldlt0.vectorD().array().log().sum();
        log_bf += 0.5 * (fit1p - fit0) - 0.5 * (logdet1 - logdet0) + 0.5 * std::log(prior_precision);
      }
    }
    if (j + m < n && l > best) {
      best = l;
      best_j = j;
    }
    if (soft) {
      if (leg_bf) log_bf = legBayesFactor(j);
      // Prior probability of a jump at t_j (and nowhere else in the window): rate × the interval it stands for.
      const double dt_j = sj.t - history_[static_cast<std::size_t>(j - 1)].t;
      const double log_prior = region_odds.empty() ? std::log(std::max(config_.jump_rate * dt_j, 1e-300))
                                                   : region_odds[static_cast<std::size_t>(j)];
      log_odds.emplace_back(log_prior + log_bf, j);
    }
  }
  if (config_.jump_decision == "posterior" && soft) {
    // Decide by the mixture's posterior instead of the test: a jump once the hypotheses "a jump at t_j"
    // with jump_min_samples measurements after t_j hold more than jump_posterior of the posterior mass
    // (against no jump and the later t_j), at the most probable of them. The prior odds (jump_rate or
    // the waypoint region) thus count: a corner is declared sooner where one is likely, and a run of
    // noise mid-leg needs more evidence.
    double top = 0.0;
    for (const auto& entry : log_odds) top = std::max(top, entry.first);
    double total = std::exp(-top);
    for (const auto& entry : log_odds) total += std::exp(entry.first - top);
    double mass = 0.0, best_p = 0.0;
    int arg = -1;
    for (const auto& [lo, j] : log_odds) {
      if (j + m >= n) continue;
      const double p = std::exp(lo - top) / total;
      mass += p;
      if (p > best_p) {
        best_p = p;
        arg = j;
      }
    }
    best_j = mass > config_.jump_posterior ? arg : -1;
  }
  if (best_j < 0) {
    if (soft) softMixture(log_odds);
    return false;
  }
  if (config_.constant_speed) learnSpeed(static_cast<std::size_t>(best_j));
  if (config_.constant_speed && speed_info_ > 0.0) best_j = refineCornerTime(best_j);
  if (config_.constant_speed) learnTurn(direction(history_[static_cast<std::size_t>(best_j)].state));
  applyJump(best_j);
  ++jumps_;
  return true;
}

void PlanarTargetFilter::softMixture(std::vector<std::pair<double, int>>& log_odds) {
  // Posterior over "no jump in the window" (prior odds 1) and "a jump at t_j" (odds π_j BF_j): the
  // estimate is the mixture of the filter's own x(k|k) and of the filters restarted at the likely
  // jump times (the same restart as a detected jump, alternative()), moments matched. Hypotheses below
  // 1 % of the posterior are dropped (at most 4 are kept), so the cost stays a few re-runs per step.
  if (log_odds.empty()) return;
  std::sort(log_odds.begin(), log_odds.end(), [](const auto& a, const auto& b) { return a.first > b.first; });
  const double top = std::max(0.0, log_odds.front().first);
  double total = std::exp(-top);
  for (const auto& [lo, j] : log_odds) total += std::exp(lo - top);
  std::vector<std::pair<double, Eigen::VectorXd>> parts;
  std::vector<Eigen::MatrixXd> covs;
  const double w0 = std::exp(-top) / total;
  parts.emplace_back(w0, state_.x());
  covs.push_back(state_.P());
  for (std::size_t k = 0; k < log_odds.size() && k < 4; ++k) {
    const double w = std::exp(log_odds[k].first - top) / total;
    if (w < 0.01) break;
    const estimation::StateEstimate alt = alternative(log_odds[k].second);
    parts.emplace_back(w, alt.x());
    covs.push_back(alt.P());
  }
  if (parts.size() == 1) return;
  double wsum = 0.0;
  Eigen::VectorXd mean = Eigen::VectorXd::Zero(state_.x().size());
  for (const auto& [w, x] : parts) {
    wsum += w;
    mean += w * x;
  }
  mean /= wsum;
  Eigen::MatrixXd P = Eigen::MatrixXd::Zero(mean.size(), mean.size());
  for (std::size_t k = 0; k < parts.size(); ++k) {
    const Eigen::VectorXd d = parts[k].second - mean;
    P += parts[k].first / wsum * (covs[k] + d * d.transpose());
  }
  output_ = estimation::StateEstimate(mean, P, state_.t());
}

estimation::StateEstimate PlanarTargetFilter::reopened(const Snapshot& sj) const {
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
  return estimation::StateEstimate(x, P, sj.t);
}

estimation::StateEstimate PlanarTargetFilter::alternative(int j) const {
  // The state now if the jump had been at t_j: as applyJump, without the gate and without touching
  // the filter (a leg only accumulates its statistics; a linear model re-runs its Kalman steps).
  const Snapshot& sj = history_[static_cast<std::size_t>(j)];
  const std::size_t n = history_.size();
  if (config_.constant_speed && speed_info_ > 0.0) {
    Leg leg = makeLeg(sj.t, sj.state.x().head<2>(), sj.state.P().block(0, 0, 2, 2), direction(sj.state));
    for (std::size_t i = static_cast<std::size_t>(j) + 1; i < n; ++i) leg.add(history_[i].t, history_[i].z, history_[i].R);
    return leg.moments(history_.back().t);
  }
  estimation::StateEstimate s = reopened(sj);
  estimation::LinearMeasurement m;
  m.C = Eigen::MatrixXd::Zero(2, stateDim());
  m.C.block(0, 0, 2, 2) = Eigen::Matrix2d::Identity();
  for (std::size_t i = static_cast<std::size_t>(j) + 1; i < n; ++i) {
    const double dt = history_[i].t - s.t();
    if (dt > 1e-9) estimation::predict(s, estimation::discretize(model_, dt));
    m.y = history_[i].z;
    m.R = history_[i].R;
    estimation::update(s, m);
  }
  return s;
}

double PlanarTargetFilter::regionReach(const Eigen::Vector2d& c, double theta) const {
  const Eigen::Vector2d half = 0.5 * config_.region_size, inset = 1e-3 * config_.region_size;
  const Eigen::Vector2d lo = config_.region_center - half, hi = config_.region_center + half;
  return boxReach(c.cwiseMax(lo + inset).cwiseMin(hi - inset), lo, hi, theta);
}

std::vector<double> PlanarTargetFilter::regionJumpOdds() const {
  // The current leg started at t_c from c and runs at speed s along u (the estimate's velocity): the
  // target is s (t − t_c) along it at t, and the next waypoint lies on the ray within R = R(θ_u) with
  // density ∝ r (see the class comment). odds_j = (s_j² − s_{j−1}²) / (R² − s_n²), s_n now; the
  // denominator is floored at (1 mm)² once the straight leg would have left the region.
  if (!regionActive() || !leg_ || history_.size() < 2) return {};
  const Eigen::Vector2d p = state_.x().head<2>(), v = state_.x().segment<2>(2);
  const double speed = v.norm();
  if (!(speed > 1e-6)) return {};
  const double t_n = history_.back().t, t_c = leg_->t_c;
  const Eigen::Vector2d c = p - v * (t_n - t_c);
  const double R = regionReach(c, std::atan2(v.y(), v.x()));
  const auto along = [&](double t) { return speed * std::max(t - t_c, 0.0); };
  const double s_n = along(t_n);
  const double log_den = std::log(std::max(R * R - s_n * s_n, 1e-6));
  std::vector<double> odds(history_.size(), -1e300);
  for (std::size_t j = 1; j < history_.size(); ++j) {
    const double a = along(history_[j - 1].t), b = along(history_[j].t);
    odds[j] = std::log(std::max(b * b - a * a, 1e-300)) - log_den;
  }
  return odds;
}

void PlanarTargetFilter::checkRegion(const Eigen::Vector2d& p, const Eigen::Matrix2d& R) {
  if (!regionActive()) return;
  const Eigen::Vector2d sd = R.diagonal().cwiseMax(0.0).cwiseSqrt();
  const Eigen::Vector2d half = 0.5 * config_.region_size;
  const Eigen::Vector2d outside = ((p - config_.region_center).cwiseAbs() - half).cwiseMax(0.0);
  const bool out = (outside.array() > 2.0 * sd.array()).any();
  region_outside_run_ = out ? region_outside_run_ + 1 : 0;
  if (region_outside_run_ >= 5) region_dropped_ = true;
}

bool PlanarTargetFilter::legEvidenceMixture() const {
  return config_.jump_evidence == "legs" && speed_info_ > 0.0;
}

double PlanarTargetFilter::legBayesFactor(int j) const {
  // log p(z_{j+1..n} | a constant-speed leg from x(j|j) at t_j) − log p(z_{j+1..n} | straight on from x(j|j)).
  // Both are linear-Gaussian evidences; the Σ log det 2πR_i they share cancel.
  //   leg:  logEvidence() − ½ log det P₀ (see Leg);
  //   straight on: z_i = H_i x + e_i, H_i = [I  τ_i I], x ~ N(x̂_j, P_j): with Λ = P_j⁻¹ + Σ H_iᵀR_i⁻¹H_i,
  //         η = P_j⁻¹ x̂_j + Σ H_iᵀR_i⁻¹z_i: −½ (Σ z_iᵀR_i⁻¹z_i + x̂ᵀP_j⁻¹x̂ − ηᵀΛ⁻¹η) − ½ log det Λ − ½ log det P_j.
  const std::size_t n = history_.size();
  const Snapshot& sj = history_[static_cast<std::size_t>(j)];
  const Eigen::Vector4d x = sj.state.x().head<4>();
  Eigen::Matrix4d P = sj.state.P().topLeftCorner<4, 4>();
  P.diagonal().array() += 1e-10;
  const auto llt_P = P.llt();
  const Eigen::Matrix4d P_inv = llt_P.solve(Eigen::Matrix4d::Identity());
  Eigen::Matrix4d L = P_inv;
  Eigen::Vector4d eta = P_inv * x;
  double zz = 0.0;
  Leg leg = makeLeg(sj.t, x.head<2>(), P.topLeftCorner<2, 2>(), direction(sj.state));
  for (std::size_t i = static_cast<std::size_t>(j) + 1; i < n; ++i) {
    const Snapshot& si = history_[i];
    const Eigen::Matrix2d Ri = si.R.inverse();
    Eigen::Matrix<double, 2, 4> H;
    H << Eigen::Matrix2d::Identity(), (si.t - sj.t) * Eigen::Matrix2d::Identity();
    L += H.transpose() * Ri * H;
    eta += H.transpose() * (Ri * si.z);
    zz += si.z.dot(Ri * si.z);
    leg.add(si.t, si.z, si.R);
  }
  const auto llt_L = L.llt();
  const double logdet_L = 2.0 * Eigen::Matrix4d(llt_L.matrixL()).diagonal().array().log().sum();
  const double logdet_P = 2.0 * Eigen::Matrix4d(llt_P.matrixL()).diagonal().array().log().sum();
  const double straight = -0.5 * (zz + x.dot(P_inv * x) - eta.dot(llt_L.solve(eta))) - 0.5 * logdet_L - 0.5 * logdet_P;
  const double logdet_P0 = -std::log(leg.P0_inv.determinant());
  // Steps of 3° or the turn prior's σ if smaller: θ's likelihood is wider than ~2° over a few seconds of
  // leg, so the rectangle rule's relative error stays below ~1e-4 (see logEvidence).
  const int points = std::max(120, static_cast<int>(std::ceil(360.0 / config_.turn_prior_sigma_deg)));
  return leg.logEvidence(points) - 0.5 * logdet_P0 - straight;
}

int PlanarTargetFilter::refineCornerTime(int j) const {
  // The test's t_j is only the best kink of a free velocity step; a leg that starts a few samples
  // early or late bends towards the old direction. Among the candidates t_j' within ±6 measurements,
  // take the one of highest evidence for "straight on from x(i0|i0) until t_j', then a constant-speed
  // leg from there": the same measurements i0+1 .. n−1 are explained by both parts for every j'.
  const int n = static_cast<int>(history_.size());
  const int i0 = std::max(0, j - 6);
  const Snapshot& s0 = history_[static_cast<std::size_t>(i0)];
  const Eigen::Matrix2d P_pos = s0.state.P().block(0, 0, 2, 2);
  int best = j;
  double best_e = -1e300;
  for (int jj = std::max(i0 + 1, j - 6); jj <= std::min(n - 3, j + 6); ++jj) {
    double e = 0.0;
    for (int i = i0 + 1; i <= jj; ++i) {
      const Snapshot& si = history_[static_cast<std::size_t>(i)];
      const Eigen::Vector2d r = si.z - extrapolatePosition(s0.state.x(), si.t - s0.t);
      e -= 0.5 * r.dot(si.R.ldlt().solve(r));
    }
    const Snapshot& sj = history_[static_cast<std::size_t>(jj)];
    Leg leg = makeLeg(sj.t, extrapolatePosition(s0.state.x(), sj.t - s0.t), P_pos, direction(s0.state));
    for (int i = jj + 1; i < n; ++i) {
      const Snapshot& si = history_[static_cast<std::size_t>(i)];
      leg.add(si.t, si.z, si.R);
    }
    e += leg.logEvidence();
    if (e > best_e) {
      best_e = e;
      best = jj;
    }
  }
  return best;
}

void PlanarTargetFilter::applyJump(int best_j) {
  // Back to x(j|j) with the motion prior re-opened, then the later measurements again.
  std::vector<Snapshot> later(history_.begin() + best_j + 1, history_.end());
  history_.erase(history_.begin(), history_.begin() + best_j);
  history_.resize(1);
  Snapshot& sj = history_.front();
  state_ = reopened(sj);
  leg_.reset();
  if (config_.constant_speed && speed_info_ > 0.0)
    leg_ = std::make_shared<const Leg>(makeLeg(sj.t, state_.x().head<2>(), state_.P().block(0, 0, 2, 2), direction(state_)));
  if (imm_) {
    imm_ = *sj.imm;
    imm_->reset(state_.x(), state_.P(), sj.t, sj.imm->probabilities());
  }
  sj = snapshot(sj.t, sj.z, sj.R);
  rejected_in_a_row_ = 0;
  for (const Snapshot& s : later) {
    const Update u = step(s.t, s.z, s.R);
    if (u.reinitialized) history_.clear();
    history_.push_back(snapshot(s.t, s.z, s.R));
  }
}

double PlanarTargetFilter::direction(const estimation::StateEstimate& s) {
  const Eigen::Vector2d v = s.x().segment<2>(2);
  return v.norm() > 1e-9 ? std::atan2(v.y(), v.x()) : std::numeric_limits<double>::quiet_NaN();
}

void PlanarTargetFilter::learnTurn(double dir) {
  // The leg that just ended had direction dir; the one before it last_direction_: that corner's turn.
  if (config_.turn_prior_weight <= 0.0) return;
  if (std::isfinite(dir) && std::isfinite(last_direction_)) {
    turns_.push_back(std::remainder(dir - last_direction_, 2.0 * core::kPi));
    if (turns_.size() > 8) turns_.erase(turns_.begin());
  }
  last_direction_ = dir;
}

PlanarTargetFilter::Leg PlanarTargetFilter::makeLeg(core::Timestamp t_c, const Eigen::Vector2d& c,
                                                    const Eigen::Matrix2d& P_c, double from_direction) const {
  Leg leg;
  leg.t_c = t_c;
  if (config_.turn_prior_weight > 0.0 && std::isfinite(from_direction) && !turns_.empty()) {
    for (double turn : turns_) leg.prior_mu.push_back(from_direction + turn);
    leg.prior_weight = config_.turn_prior_weight;
    leg.prior_sigma = config_.turn_prior_sigma_deg * core::kPi / 180.0;
  }
  if (regionActive()) {
    // The corner clamped into the region (an estimate can fall just outside it).
    const Eigen::Vector2d half = 0.5 * config_.region_size;
    leg.region = true;
    leg.region_lo = config_.region_center - half;
    leg.region_hi = config_.region_center + half;
    const Eigen::Vector2d inset = 1e-3 * config_.region_size;
    leg.region_c = c.cwiseMax(leg.region_lo + inset).cwiseMin(leg.region_hi - inset);
    leg.region_log_scale = std::log(core::kPi / (config_.region_size.x() * config_.region_size.y()));
    if (!leg.prior_mu.empty()) {
      // Both priors: normalise their product on a fine grid (each alone already has mean 1 in 2π p(θ)).
      constexpr int kPoints = 720;
      double sum = 0.0;
      for (int k = 0; k < kPoints; ++k) sum += std::exp(leg.logPrior(-core::kPi + 2.0 * core::kPi * k / kPoints));
      leg.log_norm = -std::log(sum / kPoints);
    }
  }
  leg.beta0 << c, speedEstimate();
  Eigen::Matrix3d P0 = Eigen::Matrix3d::Zero();
  P0.topLeftCorner<2, 2>() = P_c + std::pow(cornerSigma(), 2) * Eigen::Matrix2d::Identity();
  P0(2, 2) = speedVariance() + config_.constant_speed_sigma * config_.constant_speed_sigma;
  leg.P0_inv = P0.inverse();
  return leg;
}

void PlanarTargetFilter::startLeg(core::Timestamp t_c) {
  if (!initialized_) throw core::Error("PlanarTargetFilter::startLeg: filter not initialised");
  if (particles_) throw core::Error("PlanarTargetFilter::startLeg: not for waypoint_particles");
  if (!config_.constant_speed || !(speed_info_ > 0.0))
    throw core::Error("PlanarTargetFilter::startLeg: needs constant_speed and a known speed (setSpeed or a finished leg)");
  if (t_c < state_.t()) throw core::InvalidInput("PlanarTargetFilter::startLeg: t_c is before the last measurement");
  const Kinematics k = at(t_c);
  const double from = direction(state_);
  learnTurn(from);
  leg_ = std::make_shared<const Leg>(makeLeg(t_c, k.p, k.P_pos, from));
  Eigen::VectorXd x = Eigen::VectorXd::Zero(4);
  x.head<2>() = k.p;
  Eigen::MatrixXd P = Eigen::MatrixXd::Zero(4, 4);
  P.block(0, 0, 2, 2) = k.P_pos;
  P.block(2, 2, 2, 2) = std::pow(config_.init_velocity_sigma, 2) * Eigen::Matrix2d::Identity();
  state_ = estimation::StateEstimate(x, P, t_c);
  output_.reset();
  history_.clear();
}

void PlanarTargetFilter::setSpeed(double speed, double variance) {
  core::requirePositive(speed, "PlanarTargetFilter::setSpeed: speed");
  core::requirePositive(variance, "PlanarTargetFilter::setSpeed: variance");
  speed_sum_ = speed / variance;
  speed_info_ = 1.0 / variance;
}

void PlanarTargetFilter::learnSpeed(std::size_t end) {
  // Weighted least-squares line z = a + b t per axis through history_[0..end] (the segment that
  // ended at the detected jump, or its last jump_window s): var b = 1 / Σ w (t − t̄)², t̄ the weighted
  // mean time. s_k = |b|, var s_k = b̂ᵀ diag(var b) b̂ (b̂ = b / |b|). Segments under 0.5 s or with
  // fewer than 2 jump_min_samples measurements are skipped (their slope is mostly noise).
  if (end + 1 < static_cast<std::size_t>(2 * minSamples())) return;
  if (history_[end].t - history_.front().t < 0.5) return;
  Eigen::Vector2d b, var_b;
  for (int a = 0; a < 2; ++a) {
    double sw = 0.0, swt = 0.0, swz = 0.0;
    for (std::size_t i = 0; i <= end; ++i) {
      const double w = 1.0 / history_[i].R(a, a);
      sw += w;
      swt += w * history_[i].t;
      swz += w * history_[i].z(a);
    }
    const double tm = swt / sw, zm = swz / sw;
    double stt = 0.0, stz = 0.0;
    for (std::size_t i = 0; i <= end; ++i) {
      const double w = 1.0 / history_[i].R(a, a);
      stt += w * (history_[i].t - tm) * (history_[i].t - tm);
      stz += w * (history_[i].t - tm) * (history_[i].z(a) - zm);
    }
    b(a) = stz / stt;
    var_b(a) = 1.0 / stt;
  }
  const double s = b.norm();
  if (!(s > 0.0)) return;
  const Eigen::Vector2d u = b / s;
  const double var_s = u.cwiseProduct(u).dot(var_b);
  if (!(var_s > 0.0) || var_s > 0.25 * s * s) return;  // a segment whose speed is not resolved
  speed_sum_ += s / var_s;
  speed_info_ += 1.0 / var_s;
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
  if (leg_) {
    // Constant-speed leg: gate on the leg's predicted moments, then add the measurement to the leg. Every
    // component of the posterior moves on a straight line, so the moments at t are exactly those at the
    // last measurement carried by p += τ v (no process noise).
    Eigen::MatrixXd Phi = Eigen::MatrixXd::Identity(4, 4);
    Phi(0, 2) = Phi(1, 3) = dt;
    const estimation::StateEstimate pred(Phi * state_.x(), Phi * state_.P() * Phi.transpose(), t);
    const Eigen::Matrix2d S = pred.P().block(0, 0, 2, 2) + R;
    const Eigen::Vector2d d = z - pred.x().head<2>();
    out.nis = d.dot(S.ldlt().solve(d));
    if (out.nis > gate_) {
      state_ = pred;
      if (++rejected_in_a_row_ >= config_.reinit_after) {
        reset(t, z, R);
        out.accepted = out.reinitialized = true;
      }
      return out;
    }
    rejected_in_a_row_ = 0;
    auto leg = std::make_shared<Leg>(*leg_);
    leg->add(t, z, R);
    leg_ = leg;
    state_ = leg_->moments(t);
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

namespace {
// The waypoint region's model says every leg joins two points of the box B (convex), so the target
// never leaves B. An extrapolation from p0 (inside B) that ends outside stops where the chord p0 -> k.p
// meets B's boundary, with v = a = 0 there: the target turns somewhere before it, towards a waypoint
// the measurements have not shown yet. Without this, coasting through an occlusion at a corner near the
// edge runs the camera straight out of B (at 0.3 m/s, a 1 s occlusion then cost a 1.9 s search).
// An estimate already outside B (noise near the edge) is left as extrapolated.
void stopAtRegionBoundary(const Eigen::Vector2d& p0, const Eigen::Vector2d& center, const Eigen::Vector2d& size,
                          PlanarTargetFilter::Kinematics& k) {
  const Eigen::Vector2d lo = center - 0.5 * size, hi = center + 0.5 * size;
  const auto inside = [&](const Eigen::Vector2d& p) { return (p.array() >= lo.array()).all() && (p.array() <= hi.array()).all(); };
  if (!inside(p0) || inside(k.p)) return;
  const Eigen::Vector2d d = k.p - p0;
  double f = 1.0;  // the largest f with p0 + f d in B
  for (int i = 0; i < 2; ++i) {
    if (k.p(i) > hi(i)) f = std::min(f, (hi(i) - p0(i)) / d(i));
    if (k.p(i) < lo(i)) f = std::min(f, (lo(i) - p0(i)) / d(i));
  }
  k.p = p0 + std::clamp(f, 0.0, 1.0) * d;
  k.v.setZero();
  k.a.setZero();
}
}  // namespace

PlanarTargetFilter::Kinematics PlanarTargetFilter::at(core::Timestamp t) const {
  if (!initialized_) throw core::Error("PlanarTargetFilter::at: filter not initialised");
  Kinematics k;
  if (particles_) {
    const WaypointParticleFilter::Moments m = particles_->moments(std::max(t, particles_->t()));
    k.p = m.p;
    k.v = m.v;
    k.P_pos = m.P.topLeftCorner<2, 2>();
    return k;
  }
  const estimation::StateEstimate& est = estimate();
  const double dt = t - est.t();
  Eigen::VectorXd x = est.x();
  Eigen::MatrixXd P = est.P();
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
  if (regionActive() && dt > 1e-9)
    stopAtRegionBoundary(est.x().head<2>(), config_.region_center, config_.region_size, k);
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
