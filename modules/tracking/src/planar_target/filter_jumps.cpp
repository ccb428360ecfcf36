// The planar target filter's corners: a detected jump restarts the filter at the corner, the soft
// mixture blends the likely corners into the estimate, and constant-speed legs start there (the
// models are in corner_detector.h and speed_legs.h).
#include "viewline/tracking/planar_target/filter.h"

#include <Eigen/Cholesky>
#include <Eigen/LU>
#include <algorithm>
#include <cmath>
#include <functional>
#include <limits>

#include "viewline/core/error.h"
#include "viewline/core/frames.h"
#include "viewline/estimation/kalman_filter.h"

namespace viewline::tracking {

// filter.cpp: estimation::discretize, memoised.
const estimation::LinearTransition& discretized(const estimation::ContinuousLinearModel& model, double dt);

bool PlanarTargetFilter::detectJump() {
  // The test and the soft mixture's odds: corner_detector.h. On a jump at t_j the filter goes back to
  // x(j|j), its velocity (and turn rate or acceleration) prior is re-opened as at initialisation, the
  // position kept, and the measurements after t_j are processed again (applyJump): x(k|k) stays a
  // filtered estimate (it uses measurements up to t_k only).
  const int n = static_cast<int>(history_.size());
  const int m = minSamples();
  const bool soft = config_.jump_rate > 0.0;
  output_.reset();
  if (n < (soft ? m + 3 : 2 * m + 1)) return false;  // (as scanForJump: the region odds are not needed)
  JumpScanSettings settings;
  settings.min_samples = m;
  settings.threshold = config_.jump_threshold;
  settings.soft = soft;
  settings.jump_rate = config_.jump_rate;
  settings.prior_sigma = config_.jump_prior_sigma;
  settings.posterior_decision = config_.jump_decision == "posterior";
  settings.posterior_mass = config_.jump_posterior;
  const auto scanHistory = [&]() {
    std::function<double(int)> leg_bf;
    if (soft && legEvidenceMixture()) {
      const LegFactory make = legFactory();
      // legBayesFactor from the sums kept since the last scan (LegBayesFactors: the same values).
      leg_bayes_factors_.sync(history_);
      leg_bf = [this, make](int j) { return leg_bayes_factors_(history_, j, make, config_.turn_prior_sigma_deg); };
    }
    return scanForJump(history_, settings, leg_bf, soft ? regionJumpOdds() : std::vector<double>{});
  };
  JumpScan scan = scanHistory();
  int best_j = scan.jump;
  if (best_j < 0) {
    if (soft) softMixture(scan.log_odds);
    return false;
  }
  if (config_.constant_speed) speed_.learn(history_, static_cast<std::size_t>(best_j), minSamples());
  if (config_.constant_speed && speed_.known()) best_j = refineCornerTime(history_, best_j, legFactory());
  if (config_.constant_speed) turns_.legEnded(velocityDirection(history_[static_cast<std::size_t>(best_j)].state));
  applyJump(best_j);
  ++jumps_;
  // The measurement that declares a corner gets the soft mixture too, over the new leg's history: without
  // it the output there was the one new leg alone, sure of the corner time just chosen (a false corner
  // declared by noise one sample after a true one left a NEES of 23579 at that frame, the random path's
  // seed 12 mean 22 instead of 7). The scan's own declaration is left to the next measurement.
  if (soft) {
    settings.min_samples = minSamples();  // (the speed may have been learnt at this corner)
    JumpScan after = scanHistory();
    softMixture(after.log_odds);
  }
  return true;
}

int PlanarTargetFilter::minSamples() const {
  if (!parts_.empty()) return parts_.front().minSamples();
  // The speed the "auto" setting scales by: ŝ, or before the first leg has ended |v̂| once it exceeds its std.
  double speed = speed_.estimate();
  if (!speed_.known() && initialized_) {
    const Eigen::Vector2d v = state_.x().segment<2>(2);
    const double var_v = state_.P().block<2, 2>(2, 2).trace();
    if (v.squaredNorm() > var_v) speed = v.norm();
  }
  return corners_.minSamples(speed);
}

double PlanarTargetFilter::cornerSigma() const {
  return parts_.empty() ? corners_.cornerSigma() : parts_.front().cornerSigma();
}

LegFactory PlanarTargetFilter::legFactory() const {
  return [this](core::Timestamp t_c, const Eigen::Vector2d& c, const Eigen::Matrix2d& P_c, double from_direction) {
    return makeLeg(t_c, c, P_c, from_direction, false);  // (the scan's legs: logEvidence only)
  };
}

std::vector<double> PlanarTargetFilter::regionJumpOdds() const {
  if (!region_.active() || !leg_ || history_.size() < 2) return {};
  return region_.jumpOdds(state_.x().head<2>(), state_.x().segment<2>(2), leg_->t_c, history_);
}

bool PlanarTargetFilter::legEvidenceMixture() const {
  return config_.jump_evidence == "legs" && speed_.known();
}

namespace {
// Smallest posterior weight of a jump hypothesis the soft mixture keeps (below: dropped, the rest
// renormalised). 1e-3 against 1e-5 moved the NEES of the three paths by < 0.4 at a third to a half of the time.
constexpr double kSoftMixtureMinWeight = 1e-3;
}  // namespace

void PlanarTargetFilter::softMixture(std::vector<std::pair<double, int>>& log_odds) {
  // Posterior over "no jump in the window" (prior odds 1) and "a jump at t_j" (odds π_j BF_j) for every
  // measurement time of the window, the last ones included (a jump at the last measurement has no evidence
  // yet: its weight is its prior odds, its leg the direction prior alone): the jump time is a discrete
  // variable marginalised out (Rao-Blackwellised: given t_j the rest is the leg's closed-form posterior), and
  // the estimate is the mixture's mean and covariance (spread of the means included) over the filter's own
  // x(k|k) and the filters restarted at each t_j (the same restart as a detected jump, alternative()).
  // Its covariance is then E[(x − x̂)(x − x̂)ᵀ | z] of the model, whatever the mixture's shape, so the NEES
  // of a target that follows the model has mean dim x. Every hypothesis down to kSoftMixtureMinWeight of the
  // posterior is kept: a new corner's mass is spread over the last few t_j, each small but far off in
  // velocity, and keeping only the few largest (1 %, at most 4) left the random path's NEES at 80-100
  // instead of 4 (seeds 1-5; 54 at 1 % without the cap).
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
  for (std::size_t k = 0; k < log_odds.size(); ++k) {
    const double w = std::exp(log_odds[k].first - top) / total;
    if (w < kSoftMixtureMinWeight) break;
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
  if (config_.constant_speed && speed_.known()) {
    ConstantSpeedLeg leg = makeLeg(sj.t, sj.state.x().head<2>(), sj.state.P().block(0, 0, 2, 2), velocityDirection(sj.state));
    // The scan has just summed the measurements after t_j for this candidate (the same sums as adding them here).
    if (const ConstantSpeedLeg* sums = leg_bayes_factors_.legSums(history_, j)) {
      leg.copySums(*sums);
    } else {
      for (std::size_t i = static_cast<std::size_t>(j) + 1; i < n; ++i) leg.add(history_[i].t, history_[i].z, history_[i].R);
    }
    return leg.moments(history_.back().t);
  }
  estimation::StateEstimate s = reopened(sj);
  estimation::LinearMeasurement m;
  m.C = Eigen::MatrixXd::Zero(2, stateDim());
  m.C.block(0, 0, 2, 2) = Eigen::Matrix2d::Identity();
  for (std::size_t i = static_cast<std::size_t>(j) + 1; i < n; ++i) {
    const double dt = history_[i].t - s.t();
    if (dt > 1e-9) estimation::predict(s, discretized(model_, dt));
    m.y = history_[i].z;
    m.R = history_[i].R;
    estimation::update(s, m);
  }
  return s;
}

void PlanarTargetFilter::applyJump(int best_j) {
  // Back to x(j|j) with the motion prior re-opened, then the later measurements again.
  std::vector<Snapshot> later(history_.begin() + best_j + 1, history_.end());
  history_.erase(history_.begin(), history_.begin() + best_j);
  history_.resize(1);
  Snapshot& sj = history_.front();
  state_ = reopened(sj);
  leg_.reset();
  if (config_.constant_speed && speed_.known())
    leg_ = std::make_shared<const ConstantSpeedLeg>(
        makeLeg(sj.t, state_.x().head<2>(), state_.P().block(0, 0, 2, 2), velocityDirection(state_)));
  if (imm_) {
    imm_ = *sj.imm;
    imm_->reset(state_.x(), state_.P(), sj.t, sj.imm->probabilities());
  }
  sj = snapshot(sj.t, sj.z, sj.R);
  gate_.drop();  // the rejections so far were of the old leg: the gate starts again at t_j
  gate_.decide(sj.t, 0.0);
  for (const Snapshot& s : later) {
    const Update u = step(s.t, s.z, s.R);
    if (u.reinitialized) history_.clear();
    history_.push_back(snapshot(s.t, s.z, s.R));
  }
}

const PlanarTargetFilter::LegPriorMemo& PlanarTargetFilter::legPriorMemo(const ConstantSpeedLeg& leg,
                                                                         bool moments_table) const {
  const auto same = [&leg](const LegPriorMemo& e) {
    return e.region == leg.region && e.region_c == leg.region_c && e.prior_mu == leg.prior_mu &&
           e.prior_weight == leg.prior_weight && e.prior_sigma == leg.prior_sigma && e.region_lo == leg.region_lo &&
           e.region_hi == leg.region_hi && e.region_log_scale == leg.region_log_scale;
  };
  // moments()' table only when asked for (the scan's legs only need the evidence's); made from the same fields.
  const auto addMoments = [&leg](LegPriorMemo& e) {
    ConstantSpeedLeg prior = leg;
    prior.log_norm = e.log_norm;
    e.moments = std::make_shared<const std::vector<double>>(prior.logPriorOnGrid(180, false));
  };
  ++memo_clock_;
  // From the entry after the last one found (a scan asks for its candidates in the order their entries were
  // made), round the whole memo: keys are unique (an entry is made only after a full miss), so the entry
  // found is the same in any order.
  const std::size_t size = leg_prior_memo_.size();
  for (std::size_t i = 0; i < size; ++i) {
    const std::size_t at = (memo_hint_ + i) % size;
    LegPriorMemo& e = leg_prior_memo_[at];
    if (same(e)) {
      e.used = memo_clock_;
      if (moments_table && !e.moments) addMoments(e);
      memo_hint_ = at + 1;
      return e;
    }
  }
  if (leg_prior_memo_.size() >= kLegPriorMemoSize) {  // drop the least recently used
    leg_prior_memo_.erase(std::min_element(leg_prior_memo_.begin(), leg_prior_memo_.end(),
                                           [](const LegPriorMemo& a, const LegPriorMemo& b) { return a.used < b.used; }));
  }
  LegPriorMemo e;
  e.region = leg.region;
  e.region_c = leg.region_c;
  e.region_lo = leg.region_lo;
  e.region_hi = leg.region_hi;
  e.region_log_scale = leg.region_log_scale;
  e.prior_mu = leg.prior_mu;
  e.prior_weight = leg.prior_weight;
  e.prior_sigma = leg.prior_sigma;
  ConstantSpeedLeg prior = leg;
  prior.log_norm = 0.0;
  if (leg.region && !leg.prior_mu.empty()) {
    // Both priors: normalise their product on a fine grid (each alone already has mean 1 in 2π p(θ)).
    prior.log_norm = prior.logPriorNormalisation(720);
  }
  e.log_norm = prior.log_norm;
  e.evidence = std::make_shared<const std::vector<double>>(
      prior.logPriorOnGrid(legEvidencePoints(config_.turn_prior_sigma_deg), true));
  if (moments_table) addMoments(e);
  e.used = memo_clock_;
  leg_prior_memo_.push_back(std::move(e));
  memo_hint_ = 0;
  return leg_prior_memo_.back();
}

ConstantSpeedLeg PlanarTargetFilter::makeLeg(core::Timestamp t_c, const Eigen::Vector2d& c, const Eigen::Matrix2d& P_c,
                                             double from_direction, bool moments_table) const {
  ConstantSpeedLeg leg;
  leg.t_c = t_c;
  if (config_.turn_prior_weight > 0.0 && std::isfinite(from_direction) && !turns_.turns().empty()) {
    leg.prior_mu.reserve(turns_.turns().size());
    for (double turn : turns_.turns()) leg.prior_mu.push_back(from_direction + turn);
    leg.prior_weight = config_.turn_prior_weight;
    leg.prior_sigma = config_.turn_prior_sigma_deg * core::kPi / 180.0;
  }
  if (region_.active()) {
    // The corner clamped into the region (an estimate can fall just outside it).
    leg.region = true;
    leg.region_lo = region_.lo();
    leg.region_hi = region_.hi();
    leg.region_c = region_.clampInside(c);
    leg.region_log_scale = std::log(core::kPi / (config_.region_size.x() * config_.region_size.y()));
  }
  // The prior of θ is a function of the fields set above alone, and the scan asks for the same ones at
  // every measurement (one per candidate corner): the normalisation and the θ grids' logPrior tables are
  // memoised, keyed by those fields compared exactly, so a hit gives the values a fresh evaluation would.
  const LegPriorMemo& memo = legPriorMemo(leg, moments_table);
  leg.log_norm = memo.log_norm;
  leg.log_prior_evidence = memo.evidence;
  leg.log_prior_moments = memo.moments;
  leg.beta0 << c, speed_.estimate();
  Eigen::Matrix3d P0 = Eigen::Matrix3d::Zero();
  P0.topLeftCorner<2, 2>() = P_c + std::pow(cornerSigma(), 2) * Eigen::Matrix2d::Identity();
  P0(2, 2) = speed_.variance() + config_.constant_speed_sigma * config_.constant_speed_sigma;
  leg.P0_inv = P0.inverse();
  return leg;
}

void PlanarTargetFilter::startLeg(core::Timestamp t_c) {
  if (!initialized_) throw core::Error("PlanarTargetFilter::startLeg: filter not initialised");
  if (particles_) throw core::Error("PlanarTargetFilter::startLeg: not for waypoint_particles");
  if (!config_.constant_speed || !speed_.known())
    throw core::Error("PlanarTargetFilter::startLeg: needs constant_speed and a known speed (setSpeed or a finished leg)");
  if (t_c < state_.t()) throw core::InvalidInput("PlanarTargetFilter::startLeg: t_c is before the last measurement");
  const Kinematics k = at(t_c);
  const double from = velocityDirection(state_);
  turns_.legEnded(from);
  leg_ = std::make_shared<const ConstantSpeedLeg>(makeLeg(t_c, k.p, k.P_pos, from));
  Eigen::VectorXd x = Eigen::VectorXd::Zero(4);
  x.head<2>() = k.p;
  Eigen::MatrixXd P = Eigen::MatrixXd::Zero(4, 4);
  P.block(0, 0, 2, 2) = k.P_pos;
  P.block(2, 2, 2, 2) = std::pow(config_.init_velocity_sigma, 2) * Eigen::Matrix2d::Identity();
  state_ = estimation::StateEstimate(x, P, t_c);
  output_.reset();
  history_.clear();
}

void PlanarTargetFilter::setSpeed(double speed, double variance) { speed_.set(speed, variance); }

}  // namespace viewline::tracking
