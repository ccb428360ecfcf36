// Waypoint particle filter: model and equations in the header.
#include "viewline/tracking/planar_target/waypoint_particles.h"

#include <Eigen/Cholesky>

#include <algorithm>
#include <cmath>
#include <limits>
#include <random>
#include <string>

#include "viewline/core/error.h"
#include "viewline/core/frames.h"

namespace viewline::tracking {

using Eigen::Matrix2d;
using Eigen::Vector2d;

void WaypointParticleConfig::validate() const {
  if (particles < 10) throw core::InvalidInput("waypoint particle filter: particles must be >= 10");
  if (!region_center.allFinite() || !(region_size.x() > 0.0) || !(region_size.y() > 0.0) || !region_size.allFinite())
    throw core::InvalidInput("waypoint particle filter: the waypoint region (filter.region) needs a finite centre and "
                             "a positive size");
  if (!(min_leg >= 0.0) || min_leg >= 0.5 * std::min(region_size.x(), region_size.y()))
    throw core::InvalidInput("waypoint particle filter: min_leg must be in [0, half the region's smaller side)");
  if (!(speed_min > 0.0) || !(speed_max >= speed_min) || !std::isfinite(speed_max))
    throw core::InvalidInput("waypoint particle filter: need 0 < speed_min <= speed_max (equal: a known speed)");
  if (!(jitter_position >= 0.0) || !(jitter_waypoint >= 0.0) || !(jitter_speed >= 0.0))
    throw core::InvalidInput("waypoint particle filter: jitters must be >= 0");
  if (!(outlier_probability >= 0.0 && outlier_probability < 1.0))
    throw core::InvalidInput("waypoint particle filter: outlier_probability must be in [0, 1)");
  if (reinit_after < 1) throw core::InvalidInput("waypoint particle filter: reinit_after must be >= 1");
}

namespace {
const WaypointParticleConfig& validated(const WaypointParticleConfig& c) {
  c.validate();
  return c;
}
}  // namespace

// The gate's NIS is a pass/fail here (0: some particle explains the measurement better than an outlier,
// infinity: none does), so only its restart count matters; its probability is not used.
WaypointParticleFilter::WaypointParticleFilter(const WaypointParticleConfig& config)
    : cfg_(validated(config)), rng_(core::makeRng(config.seed)), gate_(2, {0.999, config.reinit_after}) {}

Vector2d WaypointParticleFilter::drawWaypoint(const Vector2d& from, core::Rng& rng) const {
  const Vector2d h = 0.5 * cfg_.region_size;
  for (;;) {  // min_leg < half the smaller side: the rejection ends
    const Vector2d w = cfg_.region_center + Vector2d(core::uniform(rng, -h.x(), h.x()), core::uniform(rng, -h.y(), h.y()));
    if ((w - from).norm() >= cfg_.min_leg) return w;
  }
}

void WaypointParticleFilter::advance(Particle& q, double dt, core::Rng& rng) const {
  double d = q.s * dt;
  for (int legs = 0; d > 0.0 && legs < 1000; ++legs) {
    const Vector2d to = q.w - q.p;
    const double L = to.norm();
    if (L >= d) {
      q.p += (d / L) * to;
      return;
    }
    d -= L;
    q.p = q.w;
    q.w = drawWaypoint(q.p, rng);
  }
}

void WaypointParticleFilter::propagateTo(double t) {
  if (!initialized_) return;
  if (!(t >= t_)) throw core::InvalidInput("waypoint particle filter: time went back (" + std::to_string(t) + " < " +
                                           std::to_string(t_) + ")");
  const double dt = t - t_;
  if (dt > 0.0)
    for (auto& q : particles_) advance(q, dt, rng_);
  t_ = t;
}

void WaypointParticleFilter::update(double t, const Vector2d& z, const Matrix2d& R) {
  if (!z.allFinite() || !R.allFinite() || !(R.determinant() > 0.0))
    throw core::InvalidInput("waypoint particle filter: non-finite measurement or covariance not positive definite");
  const std::size_t n = cfg_.particles;
  if (!initialized_) {
    gate_.decide(t, 0.0);  // Start
    drawPrior(t, z, R);
    return;
  }
  propagateTo(t);
  const Matrix2d Ri = R.inverse();
  const double log_norm = -std::log(2.0 * core::kPi) - 0.5 * std::log(R.determinant());
  const Vector2d grown = cfg_.region_size + 6.0 * R.diagonal().cwiseSqrt();
  const double log_out = std::log(cfg_.outlier_probability) - std::log(grown.x() * grown.y());
  const double log_in = std::log1p(-cfg_.outlier_probability) + log_norm;
  double best = -std::numeric_limits<double>::infinity(), best_in = best;
  for (std::size_t i = 0; i < n; ++i) {
    const Vector2d e = z - particles_[i].p;
    const double a = log_in - 0.5 * e.dot(Ri * e);
    best_in = std::max(best_in, a);
    // log((1 − ε) N + ε / |B₊|); the outlier term is below 1e-8 of it when a > log_out + 20
    const double ll = cfg_.outlier_probability > 0.0 && a < log_out + 20.0
                          ? std::max(a, log_out) + std::log1p(std::exp(-std::abs(a - log_out)))
                          : a;
    log_w_[i] += ll;
    best = std::max(best, log_w_[i]);
  }
  // No particle explains the measurement better than an outlier does: after reinit_after of these in a
  // row the cloud has lost the target (e.g. it turned during an occlusion), and starts again from the
  // measurement.
  const bool explained = !(best_in < log_out);
  if (gate_.decide(t, explained ? 0.0 : std::numeric_limits<double>::infinity()) == GateDecision::Restart) {
    drawPrior(t, z, R);
    ++reinitialisations_;
    return;
  }
  w_.resize(n);
  w_sum_ = 0.0;
  double w2 = 0.0;
  for (std::size_t i = 0; i < n; ++i) {
    log_w_[i] -= best;  // max 0: no overflow
    w_[i] = std::exp(log_w_[i]);
    w_sum_ += w_[i];
    w2 += w_[i] * w_[i];
  }
  ess_ = w_sum_ * w_sum_ / w2;
  ++updates_;
  if (effectiveSampleSize() < 0.5 * static_cast<double>(n)) resample();
}

void WaypointParticleFilter::resample() {
  const std::size_t n = particles_.size();
  std::vector<double> c(n);
  double acc = 0.0;
  for (std::size_t i = 0; i < n; ++i) c[i] = (acc += w_[i]);
  std::vector<Particle> next;
  next.reserve(n);
  const double step = acc / static_cast<double>(n);
  double u = core::uniform(rng_, 0.0, step);
  std::size_t j = 0;
  const Vector2d lo = cfg_.region_center - 0.5 * cfg_.region_size, hi = cfg_.region_center + 0.5 * cfg_.region_size;
  std::normal_distribution<double> g;  // one for the whole pass: it keeps the second of each pair it draws
  const bool known_speed = cfg_.speed_max == cfg_.speed_min;
  for (std::size_t i = 0; i < n; ++i, u += step) {
    while (j + 1 < n && c[j] < u) ++j;
    Particle q = particles_[j];
    q.p += cfg_.jitter_position * Vector2d(g(rng_), g(rng_));
    q.w += cfg_.jitter_waypoint * Vector2d(g(rng_), g(rng_));
    q.w = q.w.cwiseMax(lo).cwiseMin(hi);
    if (!known_speed) q.s = std::clamp(q.s + cfg_.jitter_speed * g(rng_), cfg_.speed_min, cfg_.speed_max);
    next.push_back(q);
  }
  particles_.swap(next);
  std::fill(log_w_.begin(), log_w_.end(), 0.0);
  resetWeights();
  ++resamplings_;
}

void WaypointParticleFilter::drawPrior(double t, const Vector2d& z, const Matrix2d& R) {
  particles_.resize(cfg_.particles);
  log_w_.assign(cfg_.particles, 0.0);
  const Eigen::LLT<Matrix2d> llt(R);
  const Matrix2d Lr = llt.matrixL();
  for (auto& q : particles_) {
    q.p = z + Lr * Vector2d(core::gaussian(rng_), core::gaussian(rng_));
    q.w = drawWaypoint(q.p, rng_);
    q.s = core::uniform(rng_, cfg_.speed_min, cfg_.speed_max);
  }
  resetWeights();
  initialized_ = true;
  t_ = t;
  ++updates_;
}

void WaypointParticleFilter::resetWeights() {
  w_.assign(particles_.size(), 1.0);
  w_sum_ = ess_ = static_cast<double>(particles_.size());
}

Vector2d WaypointParticleFilter::predict(double t) const { return moments(t).p; }

WaypointParticleFilter::Moments WaypointParticleFilter::moments(double t) const {
  if (!initialized_) throw core::InvalidInput("waypoint particle filter: predict before the first measurement");
  if (!(t >= t_)) throw core::InvalidInput("waypoint particle filter: predict into the past");
  // Fresh waypoints from a stream of the update count: the same cloud gives the same run-ahead.
  core::Rng rng = core::makeRng(core::deriveSeed(cfg_.seed, 1000003 + updates_));
  const double dt = t - t_;
  Eigen::Vector4d sum = Eigen::Vector4d::Zero();
  Eigen::Matrix4d second = Eigen::Matrix4d::Zero();
  for (std::size_t i = 0; i < particles_.size(); ++i) {
    Particle q = particles_[i];
    if (dt > 0.0) advance(q, dt, rng);
    const Vector2d to = q.w - q.p;
    const double L = to.norm();
    Eigen::Vector4d x;
    x << q.p, (L > 1e-12 ? Vector2d(q.s / L * to) : Vector2d::Zero());
    sum += w_[i] * x;
    second.noalias() += w_[i] * x * x.transpose();
  }
  Moments m;
  const Eigen::Vector4d mean = sum / w_sum_;
  m.p = mean.head<2>();
  m.v = mean.tail<2>();
  m.P = second / w_sum_ - mean * mean.transpose();
  m.P = 0.5 * (m.P + m.P.transpose()).eval();
  return m;
}

double WaypointParticleFilter::speedMean() const {
  if (!initialized_) return std::nan("");
  double sum = 0.0;
  for (std::size_t i = 0; i < particles_.size(); ++i) sum += w_[i] * particles_[i].s;
  return sum / w_sum_;
}

}  // namespace viewline::tracking
