// The planar target filter: models, gate and state in the header; corners in filter_jumps.cpp.
#include "viewline/tracking/planar_target/filter.h"

#include <Eigen/Cholesky>
#include <Eigen/LU>
#include <algorithm>
#include <array>
#include <cmath>
#include <limits>

#include "viewline/core/checks.h"
#include "viewline/core/error.h"
#include "viewline/estimation/kalman_filter.h"
#include "viewline/estimation/models/coordinated_turn.h"

namespace viewline::tracking {

namespace {
bool sameMatrix(const Eigen::MatrixXd& a, const Eigen::MatrixXd& b) {
  return a.rows() == b.rows() && a.cols() == b.cols() && a == b;
}
}  // namespace

const estimation::LinearTransition& discretized(const estimation::ContinuousLinearModel& model, double dt) {
  // The measurement intervals repeat (a camera's frame period) and so does the law's look-ahead: the last
  // few results are kept per thread, keyed by the model's matrices and the exact dt. discretize() is a
  // function of those alone (no input here), so a hit is the same transition to the last bit, without
  // its matrix exponential.
  struct Entry {
    Eigen::MatrixXd A, B, G, Qc;
    estimation::LinearTransition tr;
  };
  thread_local std::array<Entry, 8> cache;
  thread_local std::size_t next = 0;
  for (const Entry& e : cache)
    if (e.tr.dt == dt && e.tr.Phi.size() > 0 && sameMatrix(e.A, model.A) && sameMatrix(e.B, model.B) &&
        sameMatrix(e.G, model.G) && sameMatrix(e.Qc, model.Qc))
      return e.tr;
  Entry& e = cache[next];
  next = (next + 1) % cache.size();
  e.tr = estimation::discretize(model, dt);
  e.A = model.A;
  e.B = model.B;
  e.G = model.G;
  e.Qc = model.Qc;
  return e.tr;
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
    case TargetModel::ConstantVelocity:
    case TargetModel::WaypointParticles:
    case TargetModel::Mixture: return 4;
    case TargetModel::CoordinatedTurn:
    case TargetModel::Imm: return 5;
    default: return 6;
  }
}

Eigen::VectorXd PlanarTargetFilter::modeProbabilities() const {
  if (imm_ && imm_->initialized()) return imm_->probabilities();
  if (!parts_.empty()) return part_probability_;
  return {};
}

namespace {
const TargetFilterConfig& validated(const TargetFilterConfig& c) {
  c.validate();
  return c;
}
}  // namespace

PlanarTargetFilter::PlanarTargetFilter(const TargetFilterConfig& config)
    : config_(validated(config)),
      gate_(2, {config_.gate_probability, config_.reinit_after}),
      corners_(config_.jump_min_samples, config_.jump_corner_sigma),
      turns_(config_.turn_prior_weight > 0.0),
      region_(config_.region_center, config_.region_size) {
  if (config_.model == TargetModel::Mixture) {
    TargetFilterConfig legs = config_;  // every corner key applies to the cv part
    legs.model = TargetModel::ConstantVelocity;
    TargetFilterConfig turn = config_;  // the ct part: none of the corner keys (they are cv's)
    turn.model = TargetModel::CoordinatedTurn;
    turn.jump_window = turn.jump_rate = turn.turn_prior_weight = 0.0;
    turn.constant_speed = false;
    turn.jump_evidence = "kink";
    turn.jump_decision = "test";
    turn.region_size.setZero();
    parts_.emplace_back(legs);
    parts_.emplace_back(turn);
    return;
  }
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
  if (!parts_.empty()) {  // the model probabilities are kept: a lost target has not changed its motion
    for (PlanarTargetFilter& f : parts_) f.reset(t, z, R);
    gate_.drop();  // the mixture's gate, the one that decides for every part, starts at t
    gate_.decide(t, 0.0);
    initialized_ = true;
    setMixtureState(t);
  } else {
    start(t, z, R);
  }
  Update u;
  u.decision = GateDecision::Start;
  count(u);
}

void PlanarTargetFilter::start(core::Timestamp t, const Eigen::Vector2d& z, const Eigen::Matrix2d& R) {
  core::requireFinite(z, "PlanarTargetFilter: z");
  gate_.drop();
  gate_.decide(t, 0.0);  // Start: the track begins at this measurement
  if (config_.model == TargetModel::WaypointParticles) {
    particles_.emplace(particleConfig(config_, ++particle_resets_));
    particles_->update(t, z, R);
    setParticleState();
    initialized_ = true;
    output_.reset();
    return;
  }
  corners_.note(t, R);
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
  output_.reset();
  leg_.reset();
  turns_.forgetDirection();  // (the learnt turns are kept)
  history_.clear();
  if (config_.jump_window > 0.0) history_.push_back(snapshot(t, z, R));
}

PlanarTargetFilter::Update PlanarTargetFilter::update(core::Timestamp t, const Eigen::Vector2d& z,
                                                      const Eigen::Matrix2d& R) {
  return updateUnder(t, z, R, std::nullopt);
}

PlanarTargetFilter::Update PlanarTargetFilter::updateUnder(core::Timestamp t, const Eigen::Vector2d& z,
                                                           const Eigen::Matrix2d& R,
                                                           std::optional<GateDecision> decided) {
  output_.reset();
  if (!parts_.empty()) return updateMixture(t, z, R);
  if (config_.model == TargetModel::WaypointParticles) {
    Update out;
    if (!initialized_) {
      start(t, z, R);
      out.accepted = out.reinitialized = true;
      out.decision = GateDecision::Start;
      count(out);
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
    out.decision = out.reinitialized ? GateDecision::Restart : GateDecision::Accept;
    count(out);
    return out;
  }
  corners_.note(t, R);
  Update out = step(t, z, R, decided);
  count(out);
  if (out.accepted) region_.check(z, R);
  // Gated-out measurements are kept for the jump test too: after a sharp corner the first
  // measurements of the new leg are the ones the gate rejects, and they are the evidence of the jump.
  if (config_.jump_window <= 0.0 || out.reinitialized) return out;
  history_.push_back(snapshot(t, z, R));
  while (history_.size() > 1 && history_.front().t < t - config_.jump_window) history_.erase(history_.begin());
  out.jump = detectJump();
  // A mixture part under a rejection (the mixture's gate took the measurement for an outlier): the soft
  // jump mixture would re-run its corner hypotheses through it and move the estimate, so the estimate
  // stays the coasted prediction. The measurement stays in the history: if later measurements confirm
  // a corner, it is part of that evidence; a declared jump (above) re-processes it under this filter's
  // own gate, as for a cv filter alone.
  if (decided && *decided == GateDecision::Reject && !out.jump) output_.reset();
  return out;
}

PlanarTargetFilter::Snapshot PlanarTargetFilter::snapshot(core::Timestamp t, const Eigen::Vector2d& z,
                                                          const Eigen::Matrix2d& R) {
  Snapshot s;
  s.serial = ++serial_;
  s.t = t;
  s.z = z;
  s.R = R;
  s.state = state_;
  if (imm_) s.imm = *imm_;
  return s;
}

void PlanarTargetFilter::count(const Update& u) {
  if (!u.decision) return;
  switch (*u.decision) {
    case GateDecision::Start: ++counts_.starts; break;
    case GateDecision::Accept: ++counts_.accepted; break;
    case GateDecision::Reject: ++counts_.rejected; break;
    case GateDecision::Restart: ++counts_.restarts; break;
  }
}

bool PlanarTargetFilter::admit(Update& out, core::Timestamp t, const Eigen::Vector2d& z, const Eigen::Matrix2d& R,
                               const estimation::StateEstimate* coast, std::optional<GateDecision> decided) {
  out.decision = decided ? *decided : gate_.decide(t, out.nis);
  if (*out.decision == GateDecision::Accept) return true;
  if (coast != nullptr) state_ = *coast;
  if (*out.decision != GateDecision::Reject) {  // Restart (Start cannot happen: the track is live)
    start(t, z, R);
    out.accepted = out.reinitialized = true;
  }
  return false;
}

PlanarTargetFilter::Update PlanarTargetFilter::step(core::Timestamp t, const Eigen::Vector2d& z,
                                                    const Eigen::Matrix2d& R, std::optional<GateDecision> decided) {
  Update out;
  if (!initialized_) {
    start(t, z, R);
    out.accepted = out.reinitialized = true;
    out.decision = GateDecision::Start;
    return out;
  }
  const double dt = t - state_.t();
  estimation::LinearMeasurement m;
  m.C = Eigen::MatrixXd::Zero(2, stateDim());
  m.C.block(0, 0, 2, 2) = Eigen::Matrix2d::Identity();
  m.y = z;
  m.R = R;
  if (imm_) {
    // The IMM's own innovation test of the mixture's prediction (the NIS its update reports).
    if (dt > 1e-9) imm_->predict(t);
    state_ = imm_->combined();
    out.nis = imm_->combinedNis(m);
    if (!admit(out, t, z, R, nullptr, decided)) return out;
    imm_->update(m);
    state_ = imm_->combined();
    out.accepted = true;
    return out;
  }
  if (leg_) {
    // Constant-speed leg: gate on the leg's predicted moments, then add the measurement to the leg. Every
    // component of the posterior moves on a straight line, so the moments at t are exactly those at the
    // last measurement carried by p += τ v (no process noise). (No Kalman update: the NIS is the leg's.)
    Eigen::MatrixXd Phi = Eigen::MatrixXd::Identity(4, 4);
    Phi(0, 2) = Phi(1, 3) = dt;
    const estimation::StateEstimate pred(Phi * state_.x(), Phi * state_.P() * Phi.transpose(), t);
    const Eigen::Matrix2d S = pred.P().block(0, 0, 2, 2) + R;
    const Eigen::Vector2d d = z - pred.x().head<2>();
    out.nis = d.dot(S.ldlt().solve(d));
    if (!admit(out, t, z, R, &pred, decided)) return out;
    auto leg = std::make_shared<ConstantSpeedLeg>(*leg_);
    leg->add(t, z, R);
    leg_ = leg;
    state_ = leg_->moments(t);
    out.accepted = true;
    return out;
  }
  if (dt > 1e-9) estimation::predict(state_, discretized(model_, dt));
  // The gate decides before the update, so the NIS is that of the predicted state, S = R + C P Cᵀ
  // factored by LDLT. estimation::update's UpdateReport has the same NIS but from its square-root array
  // (a triangular solve with S^½), equal only to the last bits: taking it would mean updating a copy
  // first and could flip a decision at the threshold, so the seeded results would not stay identical.
  const Eigen::MatrixXd S = estimation::innovationCovariance(state_, m.C, m.R);
  const Eigen::Vector2d d = z - state_.x().head<2>();
  out.nis = d.dot(S.ldlt().solve(d));
  if (!admit(out, t, z, R, nullptr, decided)) return out;
  estimation::update(state_, m);
  out.accepted = true;
  return out;
}

PlanarTargetFilter::Kinematics PlanarTargetFilter::at(core::Timestamp t) const {
  if (!initialized_) throw core::Error("PlanarTargetFilter::at: filter not initialised");
  if (!parts_.empty()) return mixtureAt(t);
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
    const estimation::LinearTransition& tr = discretized(model_, dt);
    x = tr.Phi * x;
    P = tr.Phi * P * tr.Phi.transpose() + tr.Q;
  }
  k.p = x.head<2>();
  k.v = x.segment<2>(2);
  if (stateDim() == 6) k.a = x.segment<2>(4);
  k.P_pos = P.block(0, 0, 2, 2);
  if (region_.active() && dt > 1e-9) region_.stopAtBoundary(est.x().head<2>(), k.p, k.v, k.a);
  return k;
}

PlanarTargetFilter::Kinematics PlanarTargetFilter::mixtureAt(core::Timestamp t) const {
  std::array<Kinematics, 2> ks;
  for (std::size_t i = 0; i < ks.size(); ++i) ks[i] = parts_[i].at(t);
  return mixtureOf(ks);
}

PlanarTargetFilter::Kinematics PlanarTargetFilter::mixtureOf(const std::array<Kinematics, 2>& ks) const {
  Kinematics k;
  for (std::size_t i = 0; i < ks.size(); ++i) {
    const double w = part_probability_(static_cast<int>(i));
    k.p += w * ks[i].p;
    k.v += w * ks[i].v;
    k.a += w * ks[i].a;
  }
  for (std::size_t i = 0; i < ks.size(); ++i) {
    const Eigen::Vector2d d = ks[i].p - k.p;
    k.P_pos += part_probability_(static_cast<int>(i)) * (ks[i].P_pos + d * d.transpose());
  }
  return k;
}

void PlanarTargetFilter::setMixtureState(core::Timestamp t) {
  // Each part's (p, v) block (the ct part carries ω after them), moment-matched.
  Eigen::Vector4d x = Eigen::Vector4d::Zero();
  Eigen::Matrix4d P = Eigen::Matrix4d::Zero();
  for (std::size_t i = 0; i < parts_.size(); ++i)
    x += part_probability_(static_cast<int>(i)) * parts_[i].estimate().x().head<4>();
  for (std::size_t i = 0; i < parts_.size(); ++i) {
    const estimation::StateEstimate& e = parts_[i].estimate();
    const Eigen::Vector4d d = e.x().head<4>() - x;
    P += part_probability_(static_cast<int>(i)) * (e.P().topLeftCorner<4, 4>() + d * d.transpose());
  }
  state_ = estimation::StateEstimate(Eigen::VectorXd(x), Eigen::MatrixXd(P), t);
}

PlanarTargetFilter::Update PlanarTargetFilter::updateMixture(core::Timestamp t, const Eigen::Vector2d& z,
                                                             const Eigen::Matrix2d& R) {
  core::requireFinite(z, "PlanarTargetFilter: z");
  Update out;
  if (!initialized_) {
    for (PlanarTargetFilter& f : parts_) f.update(t, z, R);
    gate_.drop();
    gate_.decide(t, 0.0);  // Start
    initialized_ = true;
    setMixtureState(t);
    out.accepted = out.reinitialized = true;
    out.decision = GateDecision::Start;
    count(out);
    return out;
  }
  // Markov prediction of the model probabilities over dt: each switches to the other at
  // mixture_switch_rate (the chain's transition probability 1 − exp(−r dt)).
  const double dt = std::max(0.0, t - state_.t());
  const double e = 0.5 * (1.0 - std::exp(-2.0 * config_.mixture_switch_rate * dt));
  Eigen::Vector2d prior(part_probability_(0) * (1.0 - e) + part_probability_(1) * e,
                        part_probability_(1) * (1.0 - e) + part_probability_(0) * e);
  // The predictive likelihood of each part, N(z; p̂ᵢ(t), Pᵢ + R).
  Eigen::Vector2d log_like;
  std::array<Kinematics, 2> ks;
  for (std::size_t i = 0; i < ks.size(); ++i) ks[i] = parts_[i].at(t);
  for (int i = 0; i < 2; ++i) {
    const Eigen::Matrix2d S = ks[static_cast<std::size_t>(i)].P_pos + R;
    const Eigen::Vector2d d = z - ks[static_cast<std::size_t>(i)].p;
    log_like(i) = -0.5 * d.dot(S.ldlt().solve(d)) - 0.5 * std::log(S.determinant());
  }
  // ONE gate for the mixture: the NIS of the measurement against the mixture's prediction at(t) (the
  // prediction a consumer, e.g. the telemetry's innovation record, sees before the update), and every
  // part takes that decision. Gating each part on its own prediction would let the wider part (ct)
  // fuse an outlier the leading part rejects, and the mixture's estimate would move by that part's
  // share although the mixture reports the measurement as rejected (a 1 m outlier moved it 0.28 m).
  const Kinematics mix = mixtureOf(ks);  // = mixtureAt(t): the parts' predictions above, not computed twice
  const Eigen::Vector2d innovation = z - mix.p;
  const double nis = innovation.dot((mix.P_pos + R).ldlt().solve(innovation));
  const GateDecision decision = gate_.decide(t, nis);
  // A rejected measurement still goes to each part, without being fused: the cv part keeps it in its
  // corner history, as a cv filter does with its gated-out measurements (after a sharp corner the first
  // measurements of the new leg are the ones the gate rejects, and they are the evidence of the corner);
  // a detected corner then re-processes them under the cv part's own gate. A restart re-initialises
  // every part at the measurement.
  std::array<Update, 2> ups;
  for (std::size_t i = 0; i < ups.size(); ++i) ups[i] = parts_[i].updateUnder(t, z, R, decision);
  // Only a fused measurement is evidence about the motion: a rejected one (an outlier) or a restart
  // leaves the probabilities at the chain's prediction (otherwise the wider part would win it).
  Eigen::Vector2d post = prior;
  if (decision == GateDecision::Accept)
    post = Eigen::Vector2d(prior.array() * (log_like.array() - log_like.maxCoeff()).exp());
  // Floor: neither model is ever ruled out beyond recovery by one measurement (a corner's first ones).
  post = (post / post.sum()).cwiseMax(1e-6);
  part_probability_ = post / post.sum();
  setMixtureState(t);
  out.decision = decision;
  out.accepted = uses(decision);
  out.reinitialized = decision == GateDecision::Restart;
  out.jump = ups.front().jump;  // the corner report is the cv part's
  out.nis = nis;
  count(out);
  return out;
}

}  // namespace viewline::tracking
