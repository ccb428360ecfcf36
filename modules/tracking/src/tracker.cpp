#include "viewline/tracking/tracker.h"

#include <algorithm>
#include <cmath>
#include <limits>
#include <string>
#include <tuple>
#include <unordered_map>

#include "viewline/core/checks.h"
#include "viewline/estimation/kalman_filter.h"
#include "track_filter.h"

namespace viewline::tracking {

const char* toString(Refusal r) {
  switch (r) {
    case Refusal::None: return "none";
    case Refusal::NonFinite: return "non_finite";
    case Refusal::UnknownCamera: return "unknown_camera";
    case Refusal::OutsideImage: return "outside_image";
    case Refusal::BadNoise: return "bad_noise";
    case Refusal::Duplicate: return "duplicate";
    case Refusal::TooOld: return "too_old";
    case Refusal::FarFuture: return "far_future";
    case Refusal::kCount: break;
  }
  return "?";
}

const char* toString(TimeMode m) { return m == TimeMode::Exact ? "exact" : "dt_offset"; }

const char* toString(Fate f) {
  switch (f) {
    case Fate::Fused: return "fused";
    case Fate::Gated: return "gated";
    case Fate::DroppedOnRestart: return "dropped_on_restart";
  }
  return "?";
}

void TrackerConfig::validate() const {
  core::requireFinite(prior_mean, "tracker.prior_mean");
  core::requireSymmetricPositiveDefinite(prior_cov, "tracker.prior_cov");
  core::requireFinite(model.gravity_w, "tracker.model.gravity_w");
  if (!(model.accel_psd >= 0.0) || !std::isfinite(model.accel_psd))
    throw core::InvalidInput("tracker.model.accel_psd: expected a finite number >= 0");
  if (time_mode == TimeMode::DtOffset) core::requirePositive(sample_period, "tracker.sample_period");
  if (!(late_horizon >= 0.0) || !std::isfinite(late_horizon))
    throw core::InvalidInput("tracker.late_horizon: expected a finite number >= 0");
  core::requirePositive(max_forward_gap, "tracker.max_forward_gap");
  if (restart_after_rejections < 1) throw core::InvalidInput("tracker.restart_after_rejections: expected >= 1");
  core::requirePositive(max_coast, "tracker.max_coast");
  if (history_capacity < 1) throw core::InvalidInput("tracker.history_capacity: expected >= 1");
  core::requirePositive(min_depth, "tracker.min_depth");
  if (!(image_margin_px >= 0.0)) throw core::InvalidInput("tracker.image_margin_px: expected >= 0");
  if (start.confirm_images < 0) throw core::InvalidInput("tracker.start.confirm_images: expected >= 0");
  if (start.confirm_images > 0) {
    if (start.max_outliers < 0) throw core::InvalidInput("tracker.start.max_outliers: expected >= 0");
    if (start.window < static_cast<std::size_t>(start.confirm_images) + static_cast<std::size_t>(start.max_outliers))
      throw core::InvalidInput("tracker.start.window: expected >= confirm_images + max_outliers");
    if (!(start.probability > 0.0 && start.probability < 1.0))
      throw core::InvalidInput("tracker.start.probability: expected in (0, 1)");
  }
  if (!(pixel_bias.sigma_px >= 0.0) || !std::isfinite(pixel_bias.sigma_px))
    throw core::InvalidInput("tracker.pixel_bias.sigma_px: expected a finite number >= 0");
  if (pixel_bias.enabled() && !(pixel_bias.time_constant_s > 0.0))
    throw core::InvalidInput("tracker.pixel_bias.time_constant_s: expected > 0 (+infinity: a constant bias)");
  if (!(gate.directional_p > 0.0)) throw core::InvalidInput("tracker.gate.directional_p: expected > 0");
  if (!(gate.mahalanobis_alpha > 0.0 && gate.mahalanobis_alpha < 1.0))
    throw core::InvalidInput("tracker.gate.mahalanobis_alpha: expected in (0, 1)");
}

namespace detail {

estimation::StateEstimate biasedPrior(const TrackerConfig& cfg, std::size_t cameras, core::Timestamp t) {
  const Eigen::Index n = biasIndex(cameras);
  Eigen::VectorXd x(n);
  x << cfg.prior_mean, Eigen::VectorXd::Zero(n - 6);
  Eigen::MatrixXd P = Eigen::MatrixXd::Zero(n, n);
  P.topLeftCorner<6, 6>() = cfg.prior_cov;
  for (std::size_t c = 0; c < cameras; ++c) {
    const double sigma = cfg.pixel_bias.sigmaOf(c);
    P.block<2, 2>(biasIndex(c), biasIndex(c)) = sigma * sigma * Eigen::Matrix2d::Identity();
  }
  return estimation::StateEstimate(x, P, t);
}

void predictBiased(const TrackerConfig& cfg, estimation::StateEstimate& s, double dt) {
  const estimation::LinearTransition pv = cfg.model.transition(dt);
  const Eigen::Index n = s.dim();
  const double tau = cfg.pixel_bias.time_constant_s;
  const double a = std::isinf(tau) ? 1.0 : std::exp(-dt / tau);
  const double share = std::isinf(tau) ? 0.0 : -std::expm1(-2.0 * dt / tau);  // 1 − a²
  estimation::LinearTransition tr;
  tr.Phi = Eigen::MatrixXd::Identity(n, n);
  tr.Phi.topLeftCorner<6, 6>() = pv.Phi;
  tr.Q = Eigen::MatrixXd::Zero(n, n);
  tr.Q.topLeftCorner<6, 6>() = pv.Q;
  for (Eigen::Index i = 6; i < n; ++i) {
    const double sigma = cfg.pixel_bias.sigmaOf(static_cast<std::size_t>((i - 6) / 2));
    tr.Phi(i, i) = a;
    tr.Q(i, i) = share * sigma * sigma;
  }
  tr.Gamma = Eigen::MatrixXd::Zero(n, pv.Gamma.cols());
  tr.Gamma.topRows<6>() = pv.Gamma;
  tr.u = pv.u;
  tr.dt = pv.dt;
  estimation::predict(s, tr);
}

Matrix6 covPV(const estimation::StateEstimate& s) {
  const auto L = s.sqrtP().topLeftCorner<6, 6>();
  return L * L.transpose();
}

estimation::StateEstimate marginalPV(const estimation::StateEstimate& s) {
  estimation::StateEstimate out;
  out.assign(s.x().head<6>(), s.sqrtP().topLeftCorner<6, 6>(), s.t());
  return out;
}

estimation::LinearMeasurement biasedMeasurement(const estimation::StateEstimate& s, const core::Camera& camera,
                                                const ImageMeasurement& m, const ViewlineRows& rows,
                                                double depth_sq) {
  estimation::LinearMeasurement meas;
  meas.C = Eigen::MatrixXd::Zero(2, s.dim());
  meas.C.leftCols<6>() = rows.C;
  meas.C.block<2, 2>(0, biasIndex(m.camera)) = viewlinePixelJacobian(camera, m.uv, depth_sq);
  meas.y = rows.y;
  meas.R = rows.R;
  return meas;
}

}  // namespace detail

namespace {

// The image gate and, when it accepts (or `force`), the update: shared by the (p, v) and the
// bias-augmented paths. `d` = y − C x̂, `R2` the rows' own noise (reported in `update`).
void gateAndFuse(estimation::StateEstimate& s, const estimation::LinearMeasurement& meas, const Eigen::VectorXd& d,
                 const Eigen::Matrix2d& R2, const GateConfig& gate, bool force, ImageUpdate* update,
                 MeasurementOutcome& out) {
  const Eigen::MatrixXd S = estimation::innovationCovariance(s, meas.C, meas.R);
  out.gate = evaluateGate(d, S, gate);
  if (update != nullptr) {
    update->m = out.m;
    update->innovation = d;
    update->S = S;
    update->R = R2;
    update->nis = out.gate.mahalanobis;
  }
  if (force) out.gate.rejected = false;
  if (out.gate.rejected) {
    out.fate = Fate::Gated;
  } else {
    estimation::update(s, meas);
    out.fate = Fate::Fused;
  }
}

// fuse() on the augmented state (pixel bias on): the same gate and update with the bias columns.
MeasurementOutcome fuseBiased(estimation::StateEstimate& s, const core::Camera& camera, const ImageMeasurement& m,
                              const BallisticModel& model, const GateConfig& gate, double dt_offset,
                              double min_depth, bool force, bool depth_variance_in_noise, ImageUpdate* update) {
  MeasurementOutcome out;
  out.m = m;
  if (!std::isfinite(dt_offset)) core::requireFinite(dt_offset, "viewline: capture-time offset dt");
  const double depth_sq = expectedSquaredDepth(camera, detail::meanPV(s), detail::covPV(s), dt_offset, model,
                                               min_depth, depth_variance_in_noise);
  const ViewlineRows rows = viewlineRowsWithDepth(camera, m.uv, m.sigma_px, dt_offset, model, depth_sq);
  const estimation::LinearMeasurement meas = detail::biasedMeasurement(s, camera, m, rows, depth_sq);
  const Eigen::VectorXd d = meas.y - meas.C * s.x();
  gateAndFuse(s, meas, d, rows.R, gate, force, update, out);
  return out;
}

// fuseImage, also handing out the innovation, S and R2 it formed (when `update` is not null).
MeasurementOutcome fuse(estimation::StateEstimate& s, const core::Camera& camera, const ImageMeasurement& m,
                        const BallisticModel& model, const GateConfig& gate, double dt_offset, double min_depth,
                        bool force, bool depth_variance_in_noise, ImageUpdate* update) {
  if (s.dim() > 6)
    return fuseBiased(s, camera, m, model, gate, dt_offset, min_depth, force, depth_variance_in_noise, update);
  MeasurementOutcome out;
  out.m = m;
  const Vector6 x = s.x();
  const Matrix6 P = s.P();
  const ViewlineRows rows = viewlineRows(camera, m.uv, m.sigma_px, x, P, dt_offset, model, min_depth,
                                          depth_variance_in_noise);
  estimation::LinearMeasurement meas{rows.C, rows.y, rows.R};
  const Eigen::VectorXd d = rows.y - rows.C * x;
  gateAndFuse(s, meas, d, rows.R, gate, force, update, out);
  return out;
}

}  // namespace

MeasurementOutcome fuseImage(estimation::StateEstimate& s, const core::Camera& camera,
                             const ImageMeasurement& m, const BallisticModel& model,
                             const GateConfig& gate, double dt_offset, double min_depth, bool force,
                             bool depth_variance_in_noise) {
  return fuse(s, camera, m, model, gate, dt_offset, min_depth, force, depth_variance_in_noise, nullptr);
}

TrackState ViewlineTracker::initialState(const TrackerConfig& cfg, std::size_t cameras) {
  cfg.validate();
  if (cameras == 0) throw core::InvalidInput("tracker: at least one camera is needed");
  const auto& per_camera = cfg.pixel_bias.camera_sigma_px;
  if (cfg.pixel_bias.enabled() && !per_camera.empty()) {
    if (per_camera.size() != cameras)
      throw core::InvalidInput("tracker.pixel_bias.camera_sigma_px: " + std::to_string(per_camera.size()) +
                               " entries for " + std::to_string(cameras) + " cameras");
    for (const double sigma : per_camera)
      if (!(sigma > 0.0) || !std::isfinite(sigma))
        throw core::InvalidInput("tracker.pixel_bias.camera_sigma_px: expected finite numbers > 0");
  }
  // The image gate (gates.h) decides accept / reject; the track gate keeps the life cycle, with
  // one rejection count per camera. Its own chi-square threshold is that of the Mahalanobis gate.
  TrackGateConfig life;
  life.probability = 1.0 - cfg.gate.mahalanobis_alpha;
  life.restart_after = cfg.restart_after_rejections;
  life.max_coast_s = cfg.max_coast;
  return TrackState(TrackGate(2, life, cameras));
}

ViewlineTracker::ViewlineTracker(std::vector<core::Camera> cameras, TrackerConfig cfg)
    : cameras_(std::move(cameras)),
      cfg_(std::move(cfg)),
      fresh_(initialState(cfg_, cameras_.size())),
      state_(fresh_) {}

void ViewlineTracker::reset() {
  state_ = fresh_;
  last_update_.reset();
  head_ = count_ = 0;  // the ring keeps its slots
  final_.clear();
  refusals_.fill(0);
  any_ = false;
  newest_ = 0.0;
  late_inserted_ = 0;
}

core::Timestamp ViewlineTracker::sampleTime(core::Timestamp t) const {
  if (cfg_.time_mode == TimeMode::Exact) return t;
  // Grid instant at or before t (a tiny tolerance so that stamps on the grid map to themselves).
  return std::floor(t / cfg_.sample_period + 1e-9) * cfg_.sample_period;
}

Refusal ViewlineTracker::check(const ImageMeasurement& m) const {
  if (!std::isfinite(m.t) || !m.uv.allFinite()) return Refusal::NonFinite;
  if (m.camera >= cameras_.size()) return Refusal::UnknownCamera;
  if (!(m.sigma_px > 0.0) || !std::isfinite(m.sigma_px)) return Refusal::BadNoise;
  const core::Camera& cam = cameras_[m.camera];
  const double g = cfg_.image_margin_px;
  if (m.uv.x() < -g || m.uv.y() < -g || m.uv.x() > cam.width - 1.0 + g || m.uv.y() > cam.height - 1.0 + g)
    return Refusal::OutsideImage;
  if (any_) {
    if (m.t < newest_ - cfg_.late_horizon) return Refusal::TooOld;
    if (m.t > newest_ + cfg_.max_forward_gap) return Refusal::FarFuture;
    for (std::size_t i = 0; i < count_; ++i) {
      const Entry& e = entry(i);
      if (e.m.id == m.id) return Refusal::Duplicate;
      if (e.m.camera == m.camera && std::abs(e.m.t - m.t) <= 1e-9) return Refusal::Duplicate;
    }
  }
  return Refusal::None;
}

void ViewlineTracker::startTrack(TrackState& ts, core::Timestamp t) {
  for (const MeasurementOutcome& o : ts.history) evict(o);
  ts.history.clear();
  ts.est = estimation::StateEstimate(cfg_.prior_mean, cfg_.prior_cov, sampleTime(t));
  if (cfg_.pixel_bias.enabled()) ts.full = detail::biasedPrior(cfg_, cameras_.size(), ts.est.t());
  ts.fused_in_track = 0;
  ts.track_start_t = ts.est.t();
  ++ts.tracks_started;
}

void ViewlineTracker::step(TrackState& ts, const ImageMeasurement& m, ImageUpdate* update) {
  stepFilter(ts, m, update);
  if (cfg_.pixel_bias.enabled() && ts.full.dim() > 0) ts.est = detail::marginalPV(ts.full);
}

estimation::StateEstimate& ViewlineTracker::work(TrackState& ts) const {
  return cfg_.pixel_bias.enabled() ? ts.full : ts.est;
}

void ViewlineTracker::predictTo(estimation::StateEstimate& s, core::Timestamp t) const {
  if (cfg_.pixel_bias.enabled())
    detail::predictBiased(cfg_, s, t - s.t());
  else
    estimation::predict(s, cfg_.model.transition(t - s.t()));
  s.setTime(t);
}

void ViewlineTracker::stepFilter(TrackState& ts, const ImageMeasurement& m, ImageUpdate* update) {
  // No live track, or none fused for longer than max_coast: the image seeds a new one from the
  // prior (the test TrackGate::decide makes below, where it answers Start).
  const TrackGate& life = ts.gate;
  const bool seed = !life.active() || m.t - life.lastUsedTime() > life.config().max_coast_s;
  if (cfg_.start.confirm_images > 0 && (seed || !ts.confirmed)) {
    stepTentative(ts, m, update, seed);  // robust start (track_start.cpp)
    return;
  }
  if (seed) startTrack(ts, m.t);
  const int fused_before = ts.fused_in_track;
  const core::Timestamp ts_time = sampleTime(m.t);
  estimation::StateEstimate& est = work(ts);
  if (ts_time > est.t()) predictTo(est, ts_time);
  const double dt_offset = (cfg_.time_mode == TimeMode::Exact) ? 0.0 : m.t - est.t();
  MeasurementOutcome o = fuse(est, cameras_[m.camera], m, cfg_.model, cfg_.gate, dt_offset, cfg_.min_depth, seed,
                              cfg_.depth_variance_in_noise, update);
  o.seed = seed;
  const bool fused = o.fate == Fate::Fused;
  // The image gate has judged the image; the track gate counts it (an accepted image resets its
  // camera's run of rejections, a rejected one extends it) and says when the track restarts.
  o.decision = ts.gate.decide(m.t, fused ? 0.0 : std::numeric_limits<double>::infinity(), m.camera);
  if (update != nullptr) {
    update->decision = o.decision;
    update->fused_before = fused_before;
  }
  if (fused) ++ts.fused_in_track;
  const GateDecision decision = o.decision;
  ts.history.push_back(std::move(o));
  if (fused && ts.fused_in_track >= 2 && ts.fused_in_track <= cfg_.refit_young_tracks) {
    if (cfg_.start.confirm_images > 0)
      refitConfirmed(ts);
    else
      refit(ts);
  }
  if (ts.history.size() > cfg_.history_capacity) {
    evict(ts.history.front());
    ts.history.erase(ts.history.begin());
  }
  if (decision == GateDecision::Restart) {
    if (cfg_.start.confirm_images > 0)
      restartTentative(ts);
    else
      restart(ts);
  }
}

void ViewlineTracker::refit(TrackState& ts) const {
  // Only when the whole track is in the history (not capped), else nothing to refit from.
  // (A robust start's sliding window moves the track's prior to its oldest image: also whole.)
  if (ts.history.empty()) return;
  const bool whole = ts.history.front().seed ||
                     (cfg_.start.confirm_images > 0 && sampleTime(ts.history.front().m.t) == ts.track_start_t);
  if (!whole) return;
  const bool biased = cfg_.pixel_bias.enabled();
  const estimation::StateEstimate& current = biased ? ts.full : ts.est;
  const Vector6 xk = biased ? detail::meanPV(current) : Vector6(current.x());
  const Matrix6 Pk = biased ? detail::covPV(current) : Matrix6(current.P());
  const core::Timestamp tk = current.t();
  estimation::StateEstimate s = biased ? detail::biasedPrior(cfg_, cameras_.size(), ts.track_start_t)
                                       : estimation::StateEstimate(cfg_.prior_mean, cfg_.prior_cov, ts.track_start_t);
  for (const MeasurementOutcome& o : ts.history) {
    if (o.fate != Fate::Fused) continue;
    const core::Timestamp st = sampleTime(o.m.t);
    if (st > s.t()) predictTo(s, st);
    const double dt_offset = (cfg_.time_mode == TimeMode::Exact) ? 0.0 : o.m.t - s.t();
    // Current estimate moved (noise-free) to the capture time: x(t) = Φ(t − tk) xk + Γ g,
    // its covariance Φ Pk Φᵀ (backwards in time there is no process noise to add).
    const double tau = o.m.t - tk;
    const Vector6 xi = cfg_.model.propagate(xk, tau);
    Matrix6 Phi = Matrix6::Identity();
    Phi.topRightCorner<3, 3>() = tau * Eigen::Matrix3d::Identity();
    const Matrix6 Pi = Phi * Pk * Phi.transpose();
    const double depth_sq = expectedSquaredDepth(cameras_[o.m.camera], xi, Pi, 0.0, cfg_.model, cfg_.min_depth,
                                                 cfg_.depth_variance_in_noise);
    const ViewlineRows rows =
        viewlineRowsWithDepth(cameras_[o.m.camera], o.m.uv, o.m.sigma_px, dt_offset, cfg_.model, depth_sq);
    if (biased)
      estimation::update(s, detail::biasedMeasurement(s, cameras_[o.m.camera], o.m, rows, depth_sq));
    else
      estimation::update(s, estimation::LinearMeasurement{rows.C, rows.y, rows.R});
  }
  if (tk > s.t()) {
    if (biased)
      detail::predictBiased(cfg_, s, tk - s.t());
    else
      estimation::predict(s, cfg_.model.transition(tk - s.t()));
  }
  s.setTime(tk);
  (biased ? ts.full : ts.est) = std::move(s);
}

void ViewlineTracker::restart(TrackState& ts) {
  std::vector<MeasurementOutcome> items = std::move(ts.history);
  ts.history.clear();
  MeasurementOutcome dropped = items.front();
  dropped.fate = Fate::DroppedOnRestart;
  evict(dropped);
  ts.gate.drop();
  ++ts.restarts;
  for (std::size_t i = 1; i < items.size(); ++i) step(ts, items[i].m, nullptr);
}

Refusal ViewlineTracker::submit(const ImageMeasurement& m) {
  const Refusal r = check(m);
  last_update_.reset();
  if (r != Refusal::None) {
    ++refusals_[static_cast<std::size_t>(r)];
    return r;
  }
  ImageUpdate update;
  auto key = [](const ImageMeasurement& a) { return std::make_tuple(a.t, a.camera, a.id); };
  // Upper bound of m in the buffer (the first entry after it in processing order).
  std::size_t idx = 0;
  for (std::size_t hi = count_; idx < hi;) {
    const std::size_t mid = idx + (hi - idx) / 2;
    if (key(m) < key(entry(mid).m)) hi = mid;
    else idx = mid + 1;
  }
  if (idx == count_) {
    pushEntry(m, state_);
    step(state_, m, &update);
  } else {
    // Late: insert in order and re-process everything after it from the snapshot.
    TrackState ts = entry(idx).before;
    pushEntry(m, ts);
    for (std::size_t j = count_ - 1; j > idx; --j) std::swap(entry(j), entry(j - 1));
    for (std::size_t j = idx; j < count_; ++j) {
      entry(j).before = ts;
      step(ts, entry(j).m, j == idx ? &update : nullptr);
    }
    state_ = std::move(ts);
    ++late_inserted_;
  }
  newest_ = any_ ? std::max(newest_, m.t) : m.t;
  any_ = true;
  last_update_ = std::move(update);
  while (count_ > 0 && entry(0).m.t < newest_ - cfg_.late_horizon) {
    head_ = (head_ + 1) % ring_.size();
    --count_;
  }
  return Refusal::None;
}

void ViewlineTracker::pushEntry(const ImageMeasurement& m, const TrackState& s) {
  if (count_ == ring_.size()) {
    // Full: unroll the ring (entries from slot 0) and grow it by one slot.
    std::rotate(ring_.begin(), ring_.begin() + static_cast<std::ptrdiff_t>(head_), ring_.end());
    head_ = 0;
    ring_.push_back(Entry{m, s});
  } else {
    Entry& e = ring_[(head_ + count_) % ring_.size()];
    e.m = m;
    e.before = s;  // copy-assignment: the slot's vectors and matrices keep their storage
  }
  ++count_;
}

void ViewlineTracker::evict(const MeasurementOutcome& o) {
  // Ids mostly arrive in increasing order: the outcome is appended (amortised: no allocation
  // once the vector has grown to a run's size), or replaces the one it was before a restart.
  const auto it = std::lower_bound(final_.begin(), final_.end(), o.m.id,
                                   [](const MeasurementOutcome& a, std::uint64_t id) { return a.m.id < id; });
  if (it != final_.end() && it->m.id == o.m.id) *it = o;
  else final_.insert(it, o);
}

estimation::StateEstimate ViewlineTracker::predictAt(core::Timestamp t) const {
  if (!initialised()) throw core::InvalidInput("tracker: predictAt before any measurement");
  if (!std::isfinite(t)) core::requireFinite(t, "tracker: predictAt time");
  if (t < state_.est.t()) throw core::InvalidInput("tracker: predictAt time is before the estimate's time");
  estimation::StateEstimate s = state_.est;
  if (t > s.t()) {
    estimation::predict(s, cfg_.model.transition(t - s.t()));
    s.setTime(t);
  }
  return s;
}

std::optional<MeasurementOutcome> ViewlineTracker::outcome(std::uint64_t id) const {
  for (const MeasurementOutcome& o : state_.history)
    if (o.m.id == id) return o;
  const auto it = std::lower_bound(final_.begin(), final_.end(), id,
                                   [](const MeasurementOutcome& a, std::uint64_t i) { return a.m.id < i; });
  if (it != final_.end() && it->m.id == id) return *it;
  return std::nullopt;
}

std::vector<MeasurementOutcome> ViewlineTracker::outcomes() const {
  std::vector<MeasurementOutcome> out;
  out.reserve(final_.size() + state_.history.size());
  std::unordered_map<std::uint64_t, bool> in_history;
  for (const MeasurementOutcome& o : state_.history) in_history[o.m.id] = true;
  for (const MeasurementOutcome& o : final_)
    if (in_history.find(o.m.id) == in_history.end()) out.push_back(o);
  for (const MeasurementOutcome& o : state_.history) out.push_back(o);
  std::sort(out.begin(), out.end(), [](const MeasurementOutcome& a, const MeasurementOutcome& b) {
    return std::make_tuple(a.m.t, a.m.camera, a.m.id) < std::make_tuple(b.m.t, b.m.camera, b.m.id);
  });
  return out;
}

}  // namespace viewline::tracking
