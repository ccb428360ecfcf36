// Robust track start of the viewline tracker (TrackStartConfig in tracker.h).
//
// Why: a track seeded by its first image, untested, is wrong whenever that image (or one of the
// next few, which are gated against a still-huge covariance and so always pass) is a gross
// outlier; the state then fits the outlier exactly and nothing can tell until later images
// disagree. With 6 states and 2 rows per image, three images fit anything: an outlier among the
// first n images is only DETECTABLE once the subset without it has redundancy (n − 1 >= 4,
// 2 dof) and IDENTIFIABLE once exactly one subset of that size is consistent.
//
// Method: a tentative track keeps its newest `window` images. After each image it fits every
// subset that sets aside k = 0, 1, ..., max_outliers images (smallest k first), each fit a
// linear batch estimate from the prior (the viewline rows are linear in the state; sequential
// Kalman updates over the subset equal the batch fit), and tests it:
//   - consistency: the sum of the fit's normalised innovations, Σ dᵢᵀ Sᵢ⁻¹ dᵢ, equals the batch
//     least-squares cost (prior term included) and is chi-square with 2|S| − 6 dof for a diffuse
//     prior (Bar-Shalom, Li, Kirubarajan 2001, §5.4 / §3.4: the residual of a linear LS fit of
//     n_s states from m rows is χ²(m − n_s)); accepted when <= χ²(2|S| − 6, probability);
//   - geometry: the fitted point lies in front of every camera at its capture times (depth >
//     min_depth): a subset "fitted" behind a camera is not a flight that camera saw.
// The first k with a consistent subset is the maximum-consensus level (the RANSAC criterion of
// Fischler & Bolles 1981, here exhaustive since the window is small). The track is confirmed when
// that level's consistent subset is unique and has at least confirm_images images; the set-aside
// images are then rejected (Fate::Gated) and the track goes on with the usual gate and restart.
// While tentative, state() holds the best subset's fit but confirmed() is false: callers report
// no estimate. A confirmed track that the restart rule condemns becomes tentative again over
// its newest images, so a restart cannot be seeded by one outlier either.
//
// Each subset fit uses the rows' noise from the depth of the subset's own forward fit (the
// young-track refit's idea, tracker.h): the first pass's depth is the prior's and would keep the
// first rows' variance huge. Causal and deterministic over the track history, so the late-data
// replay stays exact.

#include <algorithm>
#include <cmath>
#include <limits>

#include "viewline/core/statistics.h"
#include "viewline/tracking/tracker.h"
#include "track_filter.h"

namespace viewline::tracking {

namespace {

/// The fit of one subset of a tentative track's images.
struct SubsetFit {
  estimation::StateEstimate est;  ///< at the newest image's sample time
  double cost = 0.0;              ///< Σ NIS of the last pass (the batch LS cost)
  bool feasible = true;           ///< in front of every camera at every used capture time
};

double sampleOf(const TrackerConfig& cfg, double t) {
  if (cfg.time_mode == TimeMode::Exact) return t;
  return std::floor(t / cfg.sample_period + 1e-9) * cfg.sample_period;
}

// One filter pass from the prior over the images with use[i]. Row noise: E[Z²] from `depth_from`
// moved (noise-free, as the young-track refit does) to each capture time, or, without it, from
// the pass's own prediction. With `out`, sums the NIS and checks the depth of `depth_from`.
estimation::StateEstimate fitPass(const std::vector<core::Camera>& cams, const TrackerConfig& cfg,
                                  const std::vector<MeasurementOutcome>& items, const std::vector<char>& use,
                                  core::Timestamp t0, core::Timestamp t_end,
                                  const estimation::StateEstimate* depth_from, SubsetFit* out) {
  // With the pixel bias (tracker.h) the same pass on the augmented state (p, v, b_0, ...).
  const bool biased = cfg.pixel_bias.enabled();
  estimation::StateEstimate s = biased ? detail::biasedPrior(cfg, cams.size(), t0)
                                       : estimation::StateEstimate(cfg.prior_mean, cfg.prior_cov, t0);
  const auto predictTo = [&](core::Timestamp t) {
    if (biased)
      detail::predictBiased(cfg, s, t - s.t());
    else
      estimation::predict(s, cfg.model.transition(t - s.t()));
    s.setTime(t);
  };
  for (std::size_t i = 0; i < items.size(); ++i) {
    if (!use[i]) continue;
    const ImageMeasurement& m = items[i].m;
    const core::Timestamp st = sampleOf(cfg, m.t);
    if (st > s.t()) predictTo(st);
    const double dt_offset = (cfg.time_mode == TimeMode::Exact) ? 0.0 : m.t - s.t();
    const core::Camera& cam = cams[m.camera];
    ViewlineRows rows;
    double depth_sq = 0.0;  // E[Z²] of the rows (used for the bias columns)
    if (depth_from == nullptr) {
      if (biased) {
        depth_sq = expectedSquaredDepth(cam, detail::meanPV(s), detail::covPV(s), dt_offset, cfg.model, cfg.min_depth,
                                        cfg.depth_variance_in_noise);
        rows = viewlineRowsWithDepth(cam, m.uv, m.sigma_px, dt_offset, cfg.model, depth_sq);
      } else {
        rows = viewlineRows(cam, m.uv, m.sigma_px, s.x(), s.P(), dt_offset, cfg.model, cfg.min_depth,
                            cfg.depth_variance_in_noise);
      }
    } else {
      const double tau = m.t - depth_from->t();
      const Vector6 xi = cfg.model.propagate(biased ? detail::meanPV(*depth_from) : Vector6(depth_from->x()), tau);
      Matrix6 Phi = Matrix6::Identity();
      Phi.topRightCorner<3, 3>() = tau * Eigen::Matrix3d::Identity();
      const Matrix6 Pi = Phi * (biased ? detail::covPV(*depth_from) : Matrix6(depth_from->P())) * Phi.transpose();
      depth_sq = expectedSquaredDepth(cam, xi, Pi, 0.0, cfg.model, cfg.min_depth, cfg.depth_variance_in_noise);
      rows = viewlineRowsWithDepth(cam, m.uv, m.sigma_px, dt_offset, cfg.model, depth_sq);
      if (out != nullptr && cam.toCamera(xi.head<3>()).z() <= cfg.min_depth) out->feasible = false;
    }
    if (biased) {
      const estimation::LinearMeasurement meas = detail::biasedMeasurement(s, cam, m, rows, depth_sq);
      const estimation::UpdateReport rep = estimation::update(s, meas);
      if (out != nullptr) out->cost += rep.nis;
      continue;
    }
    if (out != nullptr) {
      const Eigen::Vector2d d = rows.y - rows.C * s.x();
      const Eigen::Matrix2d S = rows.C * s.P() * rows.C.transpose() + rows.R;
      out->cost += d.dot(S.ldlt().solve(d));
    }
    estimation::update(s, estimation::LinearMeasurement{rows.C, rows.y, rows.R});
  }
  if (t_end > s.t()) predictTo(t_end);
  return s;
}

// The subset's fit: a first pass with the depths of `guess` (the tentative estimate before this
// image, when there is one: it already holds what the earlier images said) or of the pass's own
// predictions, then passes with the depths of the previous pass (a fixed-point iteration on the
// depth-dependent row noise); the last one is tested.
SubsetFit fitSubset(const std::vector<core::Camera>& cams, const TrackerConfig& cfg,
                    const std::vector<MeasurementOutcome>& items, const std::vector<char>& use,
                    core::Timestamp t0, core::Timestamp t_end, const estimation::StateEstimate* guess,
                    int passes) {
  estimation::StateEstimate prev = fitPass(cams, cfg, items, use, t0, t_end, guess, nullptr);
  for (int p = 1; p < passes; ++p) prev = fitPass(cams, cfg, items, use, t0, t_end, &prev, nullptr);
  SubsetFit out{prev};
  out.est = fitPass(cams, cfg, items, use, t0, t_end, &prev, &out);
  return out;
}

// Passes before the tested one (see fitSubset): one from the guess, one from its own depths.
constexpr int kDepthPasses = 2;

// Calls f(use) for every mask over n items that sets aside exactly k of them (lexicographic).
template <class F>
void forEachExclusion(std::size_t n, std::size_t k, F&& f) {
  std::vector<std::size_t> idx(k);
  for (std::size_t i = 0; i < k; ++i) idx[i] = i;
  std::vector<char> use(n);
  while (true) {
    std::fill(use.begin(), use.end(), 1);
    for (std::size_t i : idx) use[i] = 0;
    f(use);
    // Next combination of k out of n.
    std::size_t i = k;
    while (i > 0 && idx[i - 1] == n - k + (i - 1)) --i;
    if (i == 0) return;
    ++idx[i - 1];
    for (std::size_t j = i; j < k; ++j) idx[j] = idx[j - 1] + 1;
  }
}

}  // namespace

void ViewlineTracker::stepTentative(TrackState& ts, const ImageMeasurement& m, ImageUpdate* update, bool seed) {
  if (seed) {
    // The images of a track never confirmed were never part of a reported estimate.
    if (!ts.confirmed)
      for (MeasurementOutcome& o : ts.history) o.fate = Fate::DroppedOnRestart;
    startTrack(ts, m.t);
    ts.confirmed = false;
  }
  const int fused_before = ts.fused_in_track;
  // The image's innovation against the tentative estimate (diagnostics only: the estimate is
  // re-fitted below from the prior over the chosen subset).
  estimation::StateEstimate probe = work(ts);
  const core::Timestamp st = sampleTime(m.t);
  if (st > probe.t()) predictTo(probe, st);
  const double dt_offset = (cfg_.time_mode == TimeMode::Exact) ? 0.0 : m.t - probe.t();
  ViewlineRows rows;
  Eigen::Vector2d d;
  Eigen::Matrix2d S;
  if (cfg_.pixel_bias.enabled()) {
    const double depth_sq = expectedSquaredDepth(cameras_[m.camera], detail::meanPV(probe), detail::covPV(probe),
                                                 dt_offset, cfg_.model, cfg_.min_depth, cfg_.depth_variance_in_noise);
    rows = viewlineRowsWithDepth(cameras_[m.camera], m.uv, m.sigma_px, dt_offset, cfg_.model, depth_sq);
    const estimation::LinearMeasurement meas = detail::biasedMeasurement(probe, cameras_[m.camera], m, rows, depth_sq);
    d = meas.y - meas.C * probe.x();
    S = estimation::innovationCovariance(probe, meas.C, meas.R);
  } else {
    rows = viewlineRows(cameras_[m.camera], m.uv, m.sigma_px, probe.x(), probe.P(), dt_offset, cfg_.model,
                        cfg_.min_depth, cfg_.depth_variance_in_noise);
    d = rows.y - rows.C * probe.x();
    S = rows.C * probe.P() * rows.C.transpose() + rows.R;
  }
  MeasurementOutcome o;
  o.m = m;
  o.fate = Fate::Fused;
  o.gate = evaluateGate(d, S, cfg_.gate);
  o.gate.rejected = false;  // a tentative image is kept in the window whatever it looks like
  if (update != nullptr) {
    update->m = m;
    update->innovation = d;
    update->S = S;
    update->R = rows.R;
    update->nis = o.gate.mahalanobis;
  }
  o.seed = seed;
  o.decision = ts.gate.decide(m.t, 0.0, m.camera);  // Start for a seed, else Accept (keeps it live)
  if (update != nullptr) {
    update->decision = o.decision;
    update->fused_before = fused_before;
  }
  ts.history.push_back(std::move(o));
  // Slide the window: the oldest image leaves the tentative track unused.
  while (ts.history.size() > cfg_.start.window) {
    MeasurementOutcome gone = ts.history.front();
    gone.fate = Fate::DroppedOnRestart;
    evict(gone);
    ts.history.erase(ts.history.begin());
    ts.track_start_t = sampleTime(ts.history.front().m.t);
  }

  // Maximum-consensus search, fewest set-aside images first.
  const estimation::StateEstimate before = work(ts);  // the tentative estimate before this image
  const estimation::StateEstimate* guess = ts.history.size() > 1 ? &before : nullptr;
  const std::size_t n = ts.history.size();
  const core::Timestamp t_end = sampleTime(ts.history.back().m.t);
  const auto max_k = static_cast<std::size_t>(std::max(0, cfg_.start.max_outliers));
  std::optional<SubsetFit> best;
  std::vector<char> best_use(n, 1);
  std::size_t consistent_at_level = 0;
  std::optional<SubsetFit> fallback;  // lowest cost over everything tried (when nothing passes)
  std::vector<char> fallback_use(n, 1);
  for (std::size_t k = 0; k <= max_k && k < n; ++k) {
    const std::size_t size = n - k;
    const double dof = 2.0 * static_cast<double>(size) - 6.0;
    const double threshold =
        dof > 0.0 ? core::chiSquareQuantile(dof, cfg_.start.probability) : std::numeric_limits<double>::infinity();
    forEachExclusion(n, k, [&](const std::vector<char>& use) {
      SubsetFit f = fitSubset(cameras_, cfg_, ts.history, use, ts.track_start_t, t_end, guess, kDepthPasses);
      const bool ok = f.feasible && f.cost <= threshold;
      if (ok) {
        ++consistent_at_level;
        if (!best || f.cost < best->cost) {
          best = f;
          best_use = use;
        }
      } else if (!best && (!fallback || f.cost < fallback->cost)) {
        fallback = f;
        fallback_use = use;
      }
    });
    if (best) break;
  }
  const std::vector<char>& use = best ? best_use : fallback_use;
  const SubsetFit& fit = best ? *best : *fallback;
  work(ts) = fit.est;
  int used = 0;
  for (std::size_t i = 0; i < n; ++i) {
    ts.history[i].fate = use[i] ? Fate::Fused : Fate::Gated;
    if (i > 0) ts.history[i].decision = use[i] ? GateDecision::Accept : GateDecision::Reject;
    used += use[i] ? 1 : 0;
  }
  ts.fused_in_track = used;
  if (best && consistent_at_level == 1 && used >= cfg_.start.confirm_images) {
    ts.confirmed = true;
    ++ts.confirmations;
  }
}

void ViewlineTracker::refitConfirmed(TrackState& ts) const {
  // The young-track refit of a confirmed track (tracker.h) with the start's fixed-point passes:
  // the fused images of the window, depths first from the current estimate.
  if (ts.history.empty() || sampleTime(ts.history.front().m.t) != ts.track_start_t) return;
  std::vector<char> use(ts.history.size());
  for (std::size_t i = 0; i < use.size(); ++i) use[i] = ts.history[i].fate == Fate::Fused ? 1 : 0;
  const estimation::StateEstimate current = work(ts);
  work(ts) = fitSubset(cameras_, cfg_, ts.history, use, ts.track_start_t, current.t(), &current, kDepthPasses).est;
}

void ViewlineTracker::restartTentative(TrackState& ts) {
  std::vector<MeasurementOutcome> items = std::move(ts.history);
  ts.history.clear();
  // The oldest image always leaves (as the plain restart drops the seed): each nested restart
  // re-feeds fewer images, so the re-feeding ends.
  const std::size_t keep = std::min(items.size() - 1, cfg_.start.window);
  for (std::size_t i = 0; i + keep < items.size(); ++i) {
    MeasurementOutcome dropped = items[i];
    dropped.fate = Fate::DroppedOnRestart;
    evict(dropped);
  }
  ts.gate.drop();
  ++ts.restarts;
  for (std::size_t i = items.size() - keep; i < items.size(); ++i) step(ts, items[i].m, nullptr);
}

}  // namespace viewline::tracking
